"""Shared fixtures. Taichi has one runtime per process; a Run (render/physics/stepper.py) starts the one it needs."""
import os
import shutil
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pytest

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")
# Taichi's offline cache (on: render/physics/runtime.py): a kernel compiled once loads in a fraction of that
# time in every later process, this run's and the next run's. The suite keeps its kernels in a folder of its
# own, big enough for all of them: Taichi's default folder is shared with every Taichi program on the machine
# and holds 100 MB, least recently used out first, so there the suite's kernels pushed each other out.
# Inherited by every process the tests start. A compiled kernel is the same code either way: a cache hit
# cannot change a frame.
os.environ.setdefault("TI_OFFLINE_CACHE_FILE_PATH", str(Path.home() / ".cache" / "taichi-pendulum-tests"))
os.environ.setdefault("TI_OFFLINE_CACHE_MAX_SIZE_OF_FILES", str(1 << 30))  # 1 GiB

ROOT = Path(__file__).resolve().parent.parent


def start_afresh():
    """Each test module starts with a fresh Taichi runtime and empty in-process memos, as its own process would.
    Taichi's offline cache keys a compiled kernel by every field allocated before it in the process (their
    ids count up), so with the history of whatever other modules a worker happened to run first (xdist
    hands out modules as workers come free, and a change to one module shifts the history of every module
    after it), most kernels were compiled anew: a clean-clone run after a change to one kernel and one test
    module wrote about 3,850 new cache entries, close to one per kernel the suite compiles. Started afresh, a
    module allocates the same fields in the same order on every run, and finds its kernels in the cache (the
    next run of the same tree wrote none)."""
    from render.physics import runtime, stability
    from render.trust import certify

    runtime.forget()
    certify._MEMO.clear()  # a hit skips the certificate's runs, and with them their fields
    stability._memo.clear()


@pytest.fixture(autouse=True, scope="module")
def fresh_runtime():
    start_afresh()


# CI installs every tool the tests use (.ci/run), so a skip there is a test that did not run: only the
# bench-only numba peer may skip. Elsewhere a skip is a missing tool, listed with its reason by `-ra`.
CI_MAY_SKIP = ("numba",)


def pytest_sessionfinish(session, exitstatus):
    if hasattr(session.config, "workerinput") or os.environ.get("CI") != "true":
        return  # an xdist worker (the controller holds every report), or not CI
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = reporter.stats.get("skipped", []) if reporter else []
    reasons = [str(r.longrepr[2] if isinstance(r.longrepr, tuple) else r.longrepr) for r in skipped]
    banned = [f"{r.nodeid}: {why}" for r, why in zip(skipped, reasons) if not any(k in why for k in CI_MAY_SKIP)]
    if banned and reporter:
        reporter.write_line(f"CI: {len(banned)} test(s) skipped that CI must run:", red=True)
        for line in banned:
            reporter.write_line(f"  {line}")
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


# `make test` runs two pytest-xdist workers with `--dist loadfile`, which this scheduler refines. Each test
# module goes to one worker whole, so a module-scoped fixture is built once, not once per worker; the modules
# in SHARE_A_WORKER go together, because they share a session fixture; and the costliest modules (HEAVY_FIRST,
# measured) go out first, so that the two workers finish together rather than one waiting on a late long
# module. (xdist's own `loadgroup` no longer groups anything under pytest 9: it marks a test's group by
# rewriting item._nodeid, which pytest 9 no longer reads, so both workers rendered every preset.)
SHARE_A_WORKER = {"test_golden.py": "preset_renders", "test_render.py": "preset_renders"}
HEAVY_FIRST = ("test_accuracy_cmd.py", "test_golden.py", "test_render.py", "test_bench.py", "test_certify.py",
               "test_compare.py", "test_fractal.py", "test_map_data.py", "test_explore.py", "test_map_axes.py",
               "test_integrators.py", "test_step_limit.py", "test_batch.py",
               "test_hard_cases.py", "test_api.py", "test_hardening.py", "test_fuzz.py", "test_lyapunov.py",
               "test_ftle.py", "test_poincare.py", "test_glow.py", "test_refusals.py", "test_bad_input.py")


@pytest.hookimpl(optionalhook=True)  # an xdist hook: no error where xdist is not loaded
def pytest_xdist_make_scheduler(config, log):
    if config.getvalue("dist") != "loadfile":
        return None  # xdist's own scheduler
    from xdist.scheduler import LoadFileScheduling

    class ModulesHeavyFirst(LoadFileScheduling):
        def _split_scope(self, nodeid):
            path = nodeid.split("::", 1)[0]
            return SHARE_A_WORKER.get(Path(path).name, path)

    config.option.loadscopereorder = False  # keep the order the workers collected in (heaviest first)
    return ModulesHeavyFirst(config, log)


def pytest_collection_modifyitems(config, items):
    if not hasattr(config, "workerinput"):
        return  # not an xdist worker: pytest's own order
    rank = {name: i for i, name in enumerate(HEAVY_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: each module stays in order


def pytest_addoption(parser):
    parser.addoption("--update-goldens", action="store_true",
                     help="rewrite tests/golden/<preset>/*.png from the current renderer instead of comparing")


@pytest.fixture
def update_goldens(request):
    return request.config.getoption("--update-goldens")


def make_scene(system="rigid", count=1, **sections):
    """A Scene from keyword sections, e.g. make_scene(pendulums={"theta1": 1.0}, video={"fps": 50})."""
    from render.config.scene import from_dict
    raw = {"system": system, "pendulums": {"count": count}}
    for key, val in sections.items():
        if isinstance(val, dict):
            raw.setdefault(key, {}).update(val)
        else:
            raw[key] = val
    return from_dict(raw, "<test>")


def out_folder(out, name: str) -> Path:
    """Where a render of preset `name` went: OUT/NAME/, or with --set or --quality its OUT/NAME__<hash>/."""
    found = [p for p in Path(out).iterdir() if p.name == name or p.name.startswith(f"{name}__")]
    assert len(found) == 1, found
    return found[0]


def run_cli(*args, cwd=None, timeout=300, **kw):
    """`python -m render ARGS` in a subprocess: the real exit code, stdout and stderr."""
    return subprocess.run([sys.executable, "-m", "render", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=timeout, **kw)


# Every preset rendered once, small and short, for both the goldens (tests/test_golden.py: raw frames) and the
# decode-back checks (tests/test_render.py: the MP4, the GIF and metadata.json): compiling each preset's
# kernels is most of a render's cost here, so one render serves both (on one worker: SHARE_A_WORKER).
SMALL_W, SMALL_H, SMALL_FPS, SMALL_SECONDS = 256, 144, 10, 3.0
PICKS = {"first": 0, "early": 5, "later": 29}  # t = 0, 0.5 s, 2.9 s: well before f64 round-off matters


@contextmanager
def immutable(path: Path):
    """`path` made immutable with chattr +i (root cannot write it either); skips where that is not possible."""
    if shutil.which("chattr") is None:
        pytest.skip("chattr is not installed (Debian: e2fsprogs)")
    made = subprocess.run(["chattr", "+i", str(path)], capture_output=True, text=True)
    if made.returncode:
        pytest.skip(f"chattr +i does not work here: {made.stderr.strip()}")
    try:
        yield path
    finally:
        subprocess.run(["chattr", "-i", str(path)], check=True)


def small_scene(name):
    from render.config.scene import load
    return load(name, [f"video.width={SMALL_W}", f"video.height={SMALL_H}", f"video.fps={SMALL_FPS}",
                       f"video.duration={SMALL_SECONDS}", 'video.formats=["mp4", "gif"]'])


def render_small(name, out, threads=None):
    """(folder, metadata, raw frames at PICKS) of the small render of preset `name` into OUT."""
    from render.video import pipeline
    scene, frames, want = small_scene(name), {}, {v: k for k, v in PICKS.items()}
    meta = pipeline.render(scene, out, threads=threads,
                           frame_hook=lambda f, fr: frames.__setitem__(want[f], fr.copy()) if f in want else None)
    return scene.out_dir(out), meta, frames  # a comparison goes to OUT/compare/NAME/


@pytest.fixture(scope="session")
def preset_renders(tmp_path_factory):
    from render.config.scene import list_presets
    start_afresh()  # a session fixture is built before the module's own fixtures: the same history on any worker
    out = tmp_path_factory.mktemp("presets")
    return {p.stem: render_small(p.stem, out) for p in list_presets()}


def ocr_line(img, whitelist: str, pattern: str) -> float | None:
    """The number `pattern` (a regex, group 1) finds in one line of bitmap text that tesseract reads from the crop
    `img`, or None. A bitmap font's square pixels read poorly as they are: upscaled 4x and softened, dark on
    light, they read; how soft suits tesseract varies by glyph, so a few blurs are tried in turn."""
    import re
    import subprocess

    import imageio.v3 as iio
    import numpy as np
    from PIL import Image, ImageFilter

    grey = Image.fromarray(255 - np.asarray(img)[..., :3].max(axis=2))
    big = grey.resize((4 * grey.width, 4 * grey.height), Image.NEAREST)
    for blur in (1.5, 1.7, 2.0, 1.2, 2.5):
        soft = np.pad(np.asarray(big.filter(ImageFilter.GaussianBlur(blur))), 20, constant_values=255)
        cmd = ["tesseract", "stdin", "stdout", "--psm", "7", "-c", f"tessedit_char_whitelist={whitelist}"]
        out = subprocess.run(cmd, input=iio.imwrite("<bytes>", soft, extension=".png"), capture_output=True,
                             check=True).stdout.decode()
        found = re.fullmatch(pattern, out)
        if found:
            return float(found[1])
    return None
