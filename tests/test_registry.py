"""The package's structure: layers that import only downwards, systems from the registry (nothing else names one),
their declarations apart from their Taichi side, and imports that form no cycle."""
import ast
from pathlib import Path

import pytest

from render.commands import cli
from render.physics import integrators, reference, registry
from render.physics.plan import Plan
from render.physics.system import System
from render.config.limits import EFFECTS, LINK_EFFECTS
from render.config.scene import load

PKG = Path(__file__).resolve().parent.parent / "render"
SYSTEM_DIR = PKG / "physics" / "systems"
KERNEL_DIR = PKG / "physics" / "kernels"

# render/'s layers, lowest first (docs/architecture.md): a module may import its own layer and those before it.
# The faces (render/__init__.py, __main__.py) stand above them all; errors.py below them all.
LAYERS = ("errors", "physics", "trust", "draw", "maps", "video", "config", "commands")


def module_name(path: Path) -> str:
    rel = path.relative_to(PKG.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def imported_modules(path: Path, known: set[str]) -> set[str]:
    """render.* modules a file imports anywhere in it (lazy imports inside functions included)."""
    here = module_name(path)
    package = here if path.name == "__init__.py" else here.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(anchor + ([node.module] if node.module else []))
            names = {f"{base}.{a.name}" for a in node.names}  # `from . import x` imports module x
            out |= names
            if not names <= known:  # a name read from base itself (a function, __version__): base is needed;
                out.add(base)       # `from . import x` of submodules only reads nothing the package defines
    return {m for m in out if m in known}


def import_graph() -> dict[str, set[str]]:
    files = sorted(PKG.rglob("*.py"))
    known = {module_name(f) for f in files}
    graph = {module_name(f): imported_modules(f, known) - {module_name(f)} for f in files}
    # The registry imports every system module by discovery and its Taichi side by name (importlib), which ast
    # cannot see.
    graph["render.physics.registry"] |= {module_name(f) for folder in (SYSTEM_DIR, KERNEL_DIR)
                                         for f in folder.glob("*.py") if f.name != "__init__.py"}
    # The command line imports the module of the command given (importlib, so `--help` stays light).
    graph["render.commands.cli"] |= {f"render.commands.{module}" for module, _ in cli.COMMANDS.values()}
    return graph


def find_cycle(graph):
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_the_import_graph_of_render_has_no_cycle():
    graph = import_graph()
    assert {"render.commands.api", "render.config.options", "render.errors"} <= graph["render.commands.cli"]  # the graph is read
    assert "render.commands.api" in graph["render"]  # lazy imports too (the package re-exports the API on first use)
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


def layer(module: str) -> int:
    """The rank of a render.* module's layer; the package's faces above every layer."""
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else len(LAYERS)


def test_every_module_lives_in_a_layer_and_imports_only_downwards():
    graph = import_graph()
    faces = {"render", "render.__main__"}
    assert not {m for m in graph if layer(m) == len(LAYERS)} - faces, "a module outside the layers"
    upward = sorted(f"{m} -> {d}" for m, deps in graph.items() for d in deps
                    if m not in faces and layer(d) > layer(m))
    assert not upward, upward


def test_the_layer_check_sees_an_upward_import():
    assert layer("render.physics.system") < layer("render.draw.canvas") < layer("render.commands.cli")
    assert layer("render.errors") == 0 and layer("render") == len(LAYERS)


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_module_outside_the_systems_and_the_registry_names_a_system():
    names = set(registry.names())
    offenders = []
    for path in sorted(PKG.rglob("*.py")):
        if path.parent in (SYSTEM_DIR, KERNEL_DIR) or path.name == "registry.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and node.value in names:
                offenders.append(f"{path.relative_to(PKG.parent)}:{node.lineno}: {node.value!r}")
    assert not offenders, offenders


@pytest.mark.parametrize("module", ["draw/canvas.py", "draw/hud.py"])
def test_the_canvas_reads_only_the_drawing_contract(module):
    """The canvas (and the HUD it draws) never reaches into a system's private fields (sim.m1, sim.l1, ...)."""
    contract = {"points", "q", "n", "LINKS", "reach", "bob_sizes", "lengths"}
    used = set()
    for node in ast.walk(ast.parse((PKG / module).read_text())):
        if isinstance(node, ast.Attribute):
            owner = node.value
            if (isinstance(owner, ast.Name) and owner.id == "sim") or (
                    isinstance(owner, ast.Attribute) and owner.attr == "sim"):
                used.add(node.attr)
    assert used and used <= contract, used - contract


@pytest.mark.parametrize("name", registry.names())
def test_every_system_declares_its_contract(name):
    cls = registry.get(name)
    assert cls.SYSTEM == name and cls.NAME and cls.DOC
    assert cls.LINKS and set(cls.LINKS) <= set(LINK_EFFECTS.values())
    assert cls.D > 0 and cls.METHODS and set(cls.METHODS) <= set(integrators.METHOD)
    assert set(cls.DEFAULT_EFFECTS) <= set(EFFECTS)
    per_pendulum = {src: 1 for src in ("q", "v")}
    for src, shape in cls.STATE.values():
        size = 1
        for s in shape:
            size *= s
        per_pendulum[src] = size
    assert per_pendulum == {"q": cls.D, "v": cls.D}, cls.STATE
    assert cls.REFERENCE in reference.MODEL_ACCEL
    preset, horizon = cls.ACCURACY_CASE
    assert load(preset).system == name and horizon > 0 and 1e-3 in cls.ACCURACY_LADDER
    assert {f"theta{k}" for k in range(1, len(cls.LINKS) + 1)} <= set(cls.preset_keys())


@pytest.mark.parametrize("name", registry.names())
def test_every_system_has_its_taichi_side_apart_from_its_declaration(name):
    """The registry's class is the declaration and plan (no Taichi); the Taichi class, in the module of the same
    name in physics/kernels/, is that plan with the shared kernels and the system's own Taichi functions."""
    plan, kernels = registry.get(name), registry.kernels(name)
    assert issubclass(plan, Plan) and not issubclass(plan, System)
    assert issubclass(kernels, plan) and issubclass(kernels, System) and kernels.SYSTEM == name
    assert kernels.__module__ == plan.__module__.replace(".systems.", ".kernels.")
    own = {k for k, v in vars(kernels).items() if callable(v)}
    assert {"accel", "energy", "points"} <= own, own  # its physics in Taichi, not the base's placeholders


def starts_taichi_or_builds_a_system(path: Path) -> list[str]:
    """runtime.init(...) or ti.init(...) calls, and systems built with fields: registry.kernels(...)(...) without
    allocate=False (registry.get(...)(...) only plans)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Attribute) and f.attr == "init" and isinstance(f.value, ast.Name) and \
                f.value.id in ("runtime", "ti"):
            found.append(f"{node.lineno}: {f.value.id}.init")
        planned = any(k.arg == "allocate" and isinstance(k.value, ast.Constant) and k.value.value is False
                      for k in node.keywords)
        if isinstance(f, ast.Call) and isinstance(f.func, ast.Attribute) and f.func.attr == "kernels" and \
                isinstance(f.func.value, ast.Name) and f.func.value.id == "registry" and not planned:
            found.append(f"{node.lineno}: a system built")
    return found


def test_only_the_frame_loop_starts_taichi_and_builds_systems():
    """render/physics/stepper.py starts Taichi for the system it builds, so no caller has an order of calls to
    keep (runtime.py's own ti.init aside)."""
    offenders = {}
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).as_posix()
        if rel not in ("physics/stepper.py", "physics/runtime.py"):
            if found := starts_taichi_or_builds_a_system(path):
                offenders[rel] = found
    assert not offenders, offenders
    kinds = {f.split(": ")[1] for f in starts_taichi_or_builds_a_system(PKG / "physics" / "stepper.py")}
    assert kinds == {"runtime.init", "a system built"}  # the check sees both
    assert any("ti.init" in f for f in starts_taichi_or_builds_a_system(PKG / "physics" / "runtime.py"))
