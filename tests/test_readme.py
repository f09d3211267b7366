"""The README and docs/ say what the code does: the README's API example runs as written (the first ```python
block under "## Python API", in a fresh interpreter and an empty folder), every relative link and #anchor in
README.md and docs/*.md resolves, every file a page names exists, the recipes in docs/architecture.md name
what the code defines, and `make figures` fills the generated blocks wherever they now live."""
import ast
import importlib.util
import re
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT

DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
README_LIMIT = 15_000  # bytes: the README is the front page; the rest lives in docs/
# What `make figures` splices in (benchmarks/readme_figures.py): out/<source> as the last run wrote it.
GENERATED = {"seed/faithful.md", "accuracy/quality.md", "accuracy/summary.md", "bench/targets.md",
             "bench/effects.md"}


def api_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## Python API\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_api_example_runs_as_written(tmp_path):
    code = api_example()
    assert "render.render(" in code and "render.simulate(" in code and "render.load(" in code
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "classic 120 2.0"
    assert lines[1].startswith("classic: 120 frames 640x360@60 | ")
    assert lines[2].startswith("out/classic/classic.mp4 2.0 ")  # faithful to the end of the 2 s
    assert lines[3] == "(120,) (120, 1, 2) (120, 1)"
    assert "classic.toml: video.fps" in lines[4]
    assert all((tmp_path / "out/classic" / f).is_file() for f in ("classic.mp4", "classic.gif", "metadata.json"))


# ---------------------------------------------------------------- links and anchors
def prose(text: str) -> str:
    """The text outside fenced code blocks, with inline code spans blanked (links inside them are not links)."""
    out, fence = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fence = not fence
            continue
        if not fence:
            out.append(re.sub(r"`[^`]*`", "code", line))
    return "\n".join(out)


def headings(text: str) -> list[str]:
    out, fence = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fence = not fence
        elif not fence and (m := re.match(r"#{1,6} +(.+?) *#*$", line)):
            out.append(m.group(1))
    return out


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation (backticks included) dropped, spaces to '-'."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def anchors(page) -> set[str]:
    seen: dict[str, int] = {}
    out = set()
    for h in headings(page.read_text()):
        s = slug(h)
        out.add(f"{s}-{seen[s]}" if s in seen else s)  # a repeated heading gets -1, -2, ...
        seen[s] = seen.get(s, 0) + 1
    return out


def links(page) -> list[str]:
    return re.findall(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", prose(page.read_text()))


def test_the_link_checker_sees_links_and_anchors():
    assert slug("The `.npz` of `pendulum simulate`") == "the-npz-of-pendulum-simulate"
    assert slug("metadata.json") == "metadatajson" and slug("--quality") == "--quality"
    readme = links(ROOT / "README.md")
    assert "docs/index.md" in readme and "benchmarks/figures/hud_rigid_chaos.png" in readme
    assert "docs/output-format.md#override-folders" in readme
    assert "python-api" in anchors(ROOT / "README.md")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    broken = []
    for target in links(page):
        if re.match(r"[a-z]+:", target):  # https:, mailto:: not ours to check
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            broken.append(f"{target}: no such file")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            broken.append(f"{target}: no heading #{anchor} in {dest.relative_to(ROOT)}")
    assert not broken, broken


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_file_a_page_names_exists(page):
    named = set(re.findall(r"\b((?:render|tests|benchmarks|presets)/[\w/.\-]+\.(?:py|toml|md|ipynb|png))",
                           page.read_text()))
    assert not {n for n in named if not (ROOT / n).exists()}


def test_the_readme_and_the_index_link_every_docs_page():
    pages = {p.name for p in DOCS.glob("*.md")}
    assert {"index.md", "architecture.md", "presets.md", "failure-modes.md", "performance.md",
            "accuracy.md"} <= pages
    readme = {t.partition("#")[0] for t in links(ROOT / "README.md")}
    assert {f"docs/{p}" for p in pages} <= readme
    index = {t.partition("#")[0] for t in links(DOCS / "index.md")}
    assert pages - {"index.md"} <= index


# ---------------------------------------------------------------- what the README must keep
def test_the_readme_is_a_front_page():
    text = (ROOT / "README.md").read_text()
    assert len(text.encode()) <= README_LIMIT, f"README.md is {len(text.encode())} bytes"
    quickstart = text.split("\n## Quickstart\n", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```sh\n(.*?)```", quickstart, re.S).group(1)
    assert [ln.split()[:2] for ln in block.splitlines()] == [["make", "demo"], ["make", "test"]]
    assert "apt-get install" in text  # the system packages the skipped tests need


def test_the_readme_preset_is_the_file_it_names():
    """"## A preset" shows presets/NAME.toml, the file it names, as it is."""
    section = (ROOT / "README.md").read_text().split("\n## A preset\n", 1)[1].split("\n## ", 1)[0]
    name = re.search(r"this is `(presets/\w+\.toml)`", section).group(1)
    block = re.search(r"```toml\n(.*?)```", section, re.S).group(1)
    assert block == (ROOT / name).read_text()


def test_the_readme_commands_table_names_every_subcommand():
    from render.commands.cli import build_parser
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    table = (ROOT / "README.md").read_text().split("\n## Commands\n", 1)[1].split("\n## ", 1)[0]
    assert set(sub.choices) == set(re.findall(r"^\| `pendulum (\w+)", table, re.M))


# ---------------------------------------------------------------- the architecture page names real code
def defined_names(path) -> set[str]:
    """Every name a module defines at any depth: functions, classes, assigned names."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            out.add(node.id)
    return out


def test_adding_a_system_lists_only_what_a_system_has():
    from render.physics.system import System
    section = (DOCS / "architecture.md").read_text().split("\n## Adding a system\n", 1)[1].split("\n## ", 1)[0]
    declared, implemented = section.split("class attributes:", 1)[1].split("and implements the physics once:", 1)
    attrs = set(re.findall(r"`([A-Z][A-Z0-9_]*)`", declared))
    assert {"SYSTEM", "LINKS", "METHODS", "REFERENCE"} <= attrs
    assert not {a for a in attrs if not hasattr(System, a)}  # no QUALITY: --quality needs nothing of a system
    hooks = set(re.findall(r"`([a-z_]\w*)(?:\([^`]*\))?`", implemented.split("The integrators", 1)[0]))
    assert {"omega_max", "accel", "points", "momentum_rate"} <= hooks
    assert not {h for h in hooks if not callable(getattr(System, h, None))}


def test_the_recipes_name_what_their_files_define():
    """In each recipe bullet `- `render/X.py`: ...`, the constants, classes and functions() it names are X's."""
    text = (DOCS / "architecture.md").read_text()
    checked = 0
    for m in re.finditer(r"^- `((?:render|tests)/[\w/]+\.py)`(.*?)(?=^- |^$|\Z)", text, re.M | re.S):
        path = ROOT / m.group(1)
        assert path.is_file(), m.group(1)
        body = m.group(2)
        names = set(re.findall(r"`(\w+)\(\)`", body)) | set(re.findall(r"`([A-Z_][A-Za-z0-9_]*)`", body))
        missing = names - defined_names(path)
        assert not missing, f"{m.group(1)}: {missing}"
        checked += len(names)
    assert checked >= 15


# ---------------------------------------------------------------- generated blocks (make figures)
def load_readme_figures():
    spec = importlib.util.spec_from_file_location("readme_figures", ROOT / "benchmarks" / "readme_figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def blocks(text: str) -> list[str]:
    return re.findall(r"<!-- generated: (\S+) -->\n", text)


def test_every_generated_block_is_on_some_page_once_and_closed():
    found = []
    for page in PAGES:
        text = page.read_text()
        found += blocks(text)
        assert len(re.findall("^<!-- generated: ", text, re.M)) == len(re.findall("^<!-- end generated -->", text, re.M)), page
    assert sorted(found) == sorted(GENERATED)


def test_make_figures_fills_the_blocks_wherever_they_live(tmp_path):
    figures = load_readme_figures()
    root = tmp_path / "repo"
    shutil.copytree(DOCS, root / "docs")
    shutil.copy(ROOT / "README.md", root / "README.md")
    out = tmp_path / "out"
    for src in GENERATED:
        (out / src).parent.mkdir(parents=True, exist_ok=True)
        (out / src).write_text(f"| fresh | {src} |\n")
    for src in figures.IMAGES:
        (out / src).parent.mkdir(parents=True, exist_ok=True)
        (out / src).write_bytes(b"png " + src.encode())
    assert figures.main(["--out", str(out)], root=root) == 0
    filled = {}
    for page in figures.pages(root):
        for src, body in re.findall(r"<!-- generated: (\S+) -->\n(.*?)<!-- end generated -->", page.read_text(), re.S):
            filled[src] = (page.relative_to(root), body)
    assert {src: body for src, (_, body) in filled.items()} == {src: f"| fresh | {src} |\n" for src in GENERATED}
    assert {str(p) for p, _ in filled.values()} >= {"docs/performance.md", "docs/accuracy.md"}
    for src, name in figures.IMAGES.items():  # copied where the pages link them
        assert (root / "benchmarks" / "figures" / name).read_bytes() == b"png " + src.encode()
    # the prose around the blocks is untouched
    for page in figures.pages(root):
        original = (ROOT / page.relative_to(root)).read_text()
        strip = lambda t: re.sub(r"(<!-- generated: \S+ -->\n).*?(<!-- end generated -->)", r"\1\2", t, flags=re.S)
        assert strip(page.read_text()) == strip(original)


def test_make_figures_says_what_it_could_not_find(tmp_path, capsys):
    figures = load_readme_figures()
    root = tmp_path / "repo"
    shutil.copytree(DOCS, root / "docs")
    shutil.copy(ROOT / "README.md", root / "README.md")
    assert figures.main(["--out", str(tmp_path / "empty")], root=root) == 1
    assert "bench/targets.md" in capsys.readouterr().err
    assert (root / "docs" / "performance.md").read_text() == (DOCS / "performance.md").read_text()


def test_every_figure_make_figures_writes_is_shown_on_a_page():
    figures = load_readme_figures()
    shown = {t.rsplit("/", 1)[-1] for page in PAGES for t in links(page) if "benchmarks/figures/" in t}
    assert set(figures.IMAGES.values()) <= shown
