"""The gallery (`pendulum gallery`, and `pendulum batch`'s page) reads, writes and deletes only inside OUT, and one
bad render costs its own card, never the page (issue 22).

An output root is built with every hostile input found so far: outputs naming `../../x.mp4` or an absolute path,
a render folder that is a symlink out of OUT, a metadata.json that is a FIFO, a symlink to /dev/zero or to a
file outside, nested 100000 deep, of the wrong shape, with 10**400 in it, over the size cap, and a file name of
300 characters. Beside every target outside OUT lie files named exactly like the sweeper's temporaries of a dead
writer. The directory outside is snapshotted (listing, contents, mtimes, and atimes set older than mtimes, so
that relatime records any read or listing) before and after the command.
"""
import contextlib
import errno
import hashlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import immutable, run_cli
from render.video import atomic
from render.commands import confined, gallery
from render.config.scene import load
from render.video.version import __version__

TIMEOUT_S = 30  # about 3 s here; the FIFO hung for ever and /dev/zero read until memory ran out
SKIPPED = {  # folder -> what its card says after "skipped: "
    "traversal": "'../../outside/x.mp4', which is not a file in its own folder",
    "absolute": "which is not a file in its own folder",
    "linked": "linked is a symlink (to ",
    "fifo": "metadata.json is a FIFO, not a regular file",
    "zero": "metadata.json is a symlink (to /dev/zero), not a file",
    "meta_outside": "metadata.json is a symlink (to ",
    "meta_dir": "metadata.json is a folder, not a regular file",
    "deep": "metadata.json is nested too deeply to parse",
    "deep_inside": "metadata.json is nested too deeply to parse",
    "a_list": "metadata.json holds a list, not an object",
    "outputs_str": "metadata.json: outputs is a string, not an object",
    "outputs_list": "metadata.json: outputs is a list, not an object",
    "preset_list": "metadata.json: preset is a list, not an object",
    "size_str": "outputs 'size_str.mp4' has a string where its size in bytes belongs",
    "huge": "an integer of 401 digits",
    "huge_size": "an integer of 401 digits",
    "big": f"is 2097152 bytes, over the {confined.META_MAX_BYTES}-byte limit",
    "not_utf8": "metadata.json does not parse",
    "long_output": "File name too long",
    "output_link": "outputs 'output_link.mp4' is a symlink, not a regular file",
    "output_fifo": "outputs 'output_fifo.mp4' is a FIFO, not a regular file",
    "compare/evil": "evil is a symlink (to ",
}
LONG_NAME = "n" * 300
# Overrides and a comparison's variants as metadata may hold them: markup, a quote, a non-string, none at all.
HOSTILE_SETS = ['description="</code><script>alert(1)</script>"', "name='x' onload=\"y\"", 7, None]
HOSTILE_VARIANTS = [{"label": "<img src=x onerror=alert(2)>", "divergence_s": 0.25,
                     "faithfulness": {"faithful_until_s": 0.5}},
                    {"label": "f64 & co", "divergence_s": None, "faithfulness": {"faithful_until_s": 9}},
                    {"label": ["not", "text"], "divergence_s": "soon", "faithfulness": "always"}, "a string"]


def mp4(path: Path):
    import imageio_ffmpeg
    subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "testsrc=size=64x36:rate=10",
                    "-t", "1", "-pix_fmt", "yuv420p", "-c:v", "libx264", str(path)], check=True, timeout=60)


def dead_pid() -> int:
    return int(subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                              text=True).stdout)


def stale_temporaries(folder: Path, *targets: str) -> list[Path]:
    """Files named like a dead writer's temporaries of `targets` in `folder`: what the sweeper removes."""
    pid, made = dead_pid(), []
    for target, suffix in [(t, ".jpg" if t.endswith(".poster.jpg") else ".part") for t in targets]:
        made.append(folder / f".{target}.{atomic.HOST}-{pid}.abcdefgh{suffix}")
        made[-1].write_bytes(b"a file that only looks like a temporary")
    return made


def meta_of(name: str, files: dict) -> dict:
    return {"preset": {"name": name, "system": "rigid", "pendulums": {"count": 3}, "description": f"{name} <&>"},
            "frames": 10, "fps": 10, "width": 64, "height": 36, "duration": 1.0,
            "integrator": {"method": "rk4", "dt": 1e-3, "substeps": 100, "precision": "f64"},
            "faithfulness": {"faithful_until_s": 0.5, "median_until_s": 1.0, "tolerance": 1e-3, "unit": "rad"},
            "energy": {"max_rel_drift": 1e-9}, "timings_s": {"total": 1.5}, "versions": {"package": "x"},
            "overrides": HOSTILE_SETS, "compare": {"finest": 1, "variants": HOSTILE_VARIANTS},
            "outputs": {f: p.stat().st_size for f, p in files.items()},
            "outputs_sha256": {f: atomic.digest(p) for f, p in files.items()}}


def build(tmp: Path):
    """(out, outside): an output root with good and hostile renders, and the directory outside it they aim at."""
    out, outside = tmp / "out", tmp / "outside"
    (outside / "renderdir").mkdir(parents=True)
    mp4(outside / "x.mp4")
    (outside / "x.gif").write_bytes(b"GIF89a")
    (outside / "metadata.json").write_text(json.dumps(meta_of("outside", {"x.mp4": outside / "x.mp4"})))
    mp4(outside / "renderdir" / "renderdir.mp4")
    (outside / "renderdir" / "metadata.json").write_text(
        json.dumps(meta_of("renderdir", {"renderdir.mp4": outside / "renderdir" / "renderdir.mp4"})))
    stale_temporaries(outside, "x.poster.jpg", "x.mp4", "index.html", "metadata.json")
    stale_temporaries(outside / "renderdir", "renderdir.poster.jpg", "renderdir.mp4", "index.html")

    def folder(name, meta=None, text=None):
        (out / name).mkdir(parents=True)
        if meta is not None or text is not None:
            (out / name / "metadata.json").write_text(text if text is not None else json.dumps(meta))
        return out / name

    good = folder("good")
    mp4(good / "good.mp4")
    (good / "good.gif").write_bytes(b"GIF89a")
    (good / "metadata.json").write_text(json.dumps(meta_of("good", {f: good / f for f in ("good.mp4", "good.gif")})))
    inside = stale_temporaries(good, "good.poster.jpg")  # the sweeper still works inside OUT
    g = folder("good_gif")
    (g / "good_gif.gif").write_bytes(b"GIF89a")
    (g / "metadata.json").write_text(json.dumps(meta_of("good_gif", {"good_gif.gif": g / "good_gif.gif"})))
    folder("long_name", {**meta_of(LONG_NAME, {}), "outputs": {}})
    folder("infinite", text='{"frames": 1e400, "duration": Infinity, "fps": NaN, "outputs": {}}')

    size = (outside / "x.mp4").stat().st_size
    folder("traversal", {"outputs": {"../../outside/x.mp4": size, "x.gif": 6}})
    folder("absolute", {"outputs": {str(outside / "x.mp4"): size}})
    (out / "linked").symlink_to(outside / "renderdir")
    os.mkfifo(folder("fifo") / "metadata.json")
    (folder("zero") / "metadata.json").symlink_to("/dev/zero")
    (folder("meta_outside") / "metadata.json").symlink_to(outside / "metadata.json")
    (folder("meta_dir") / "metadata.json").mkdir()
    folder("deep", text="[" * 100_000 + "]" * 100_000)
    folder("deep_inside", text='{"preset": {"description": ' + "[" * 100_000 + "]" * 100_000 + "}}")
    folder("a_list", [1, 2, 3])
    folder("outputs_str", {"outputs": "x.mp4"})
    folder("outputs_list", {"outputs": ["x.mp4"]})
    folder("preset_list", {"preset": [], "outputs": {}})
    folder("size_str", {"outputs": {"size_str.mp4": "big"}})
    folder("huge", text='{"frames": 1' + "0" * 400 + ', "outputs": {}}')
    folder("huge_size", text='{"outputs": {"huge_size.mp4": 1' + "0" * 400 + "}}")
    folder("big", text='{"outputs": {}}' + " " * ((2 << 20) - 15))
    (folder("not_utf8") / "metadata.json").write_bytes(b'{"outputs": "\xff\xfe"}')
    folder("long_output", {"outputs": {"a" * 300 + ".mp4": 1}})
    (folder("output_link", {"outputs": {"output_link.mp4": size}}) / "output_link.mp4").symlink_to(outside / "x.mp4")
    os.mkfifo(folder("output_fifo", {"outputs": {"output_fifo.mp4": 0}}) / "output_fifo.mp4")
    (out / "compare").mkdir()
    (out / "compare" / "evil").symlink_to(outside / "renderdir")
    return out, outside, inside


def snapshot(top: Path) -> dict:
    """Every path under top, not following symlinks: its kind, size, mtime, and bytes (or link target)."""
    found = {}
    for dirpath, dirs, files in os.walk(top):
        for p in [Path(dirpath) / n for n in dirs + files]:
            st = p.lstat()
            body = (os.readlink(p) if p.is_symlink() else
                    hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "")
            found[p] = (st.st_mode, st.st_size, st.st_mtime_ns, body)
    return found


def age_atimes(paths) -> dict:
    """Set each path's atime 10 s before its mtime, so that relatime updates it on any read or listing."""
    ages = {}
    for p in [*paths, *{p.parent for p in paths}]:
        st = p.lstat()
        os.utime(p, ns=(st.st_mtime_ns - 10**10, st.st_mtime_ns), follow_symlinks=False)
        ages[p] = p.lstat().st_atime_ns
    probe = next(p for p in paths if p.is_file() and not p.is_symlink())
    probe.read_bytes()
    if probe.lstat().st_atime_ns == ages[probe]:
        pytest.skip("this file system records no atime (noatime): reads outside OUT cannot be seen")
    os.utime(probe, ns=(ages[probe], probe.lstat().st_mtime_ns))
    return ages


def atimes_of(paths) -> dict:
    return {p: p.lstat().st_atime_ns if os.path.lexists(p) else None for p in paths}


def cards(page: str) -> dict[str, str]:
    """Each card's heading -> the card's HTML."""
    found = {}
    for chunk in page.split('<div class="card">')[1:]:
        heading = chunk.split("<h2>", 1)[1].split("</h2>", 1)[0]
        found[heading] = chunk
    return found


@pytest.mark.parametrize("command", ["gallery", "batch"])
def test_hostile_renders_get_a_card_each_and_nothing_outside_out_is_touched(tmp_path, command):
    out, outside, inside = build(tmp_path)
    before = snapshot(outside)
    ages = age_atimes(list(before))
    if command == "gallery":
        argv = ["gallery", "--out", out]
    else:  # a preset that fails validation beside a tiny one: batch renders one and goes on to its page (a batch
        # of bad presets only is bad input, refused with nothing written)
        (tmp_path / "bad.toml").write_text('name = "bad"\nsystem = "rigid"\n[pendulums]\ncount = -1\n')
        (tmp_path / "tiny.toml").write_text('system = "rigid"\n[pendulums]\ncount = 1\n[video]\nwidth = 32\n'
                                            'height = 32\nduration = 0.1\nformats = ["gif"]\n')
        argv = ["batch", tmp_path / "bad.toml", tmp_path / "tiny.toml", "--out", out, "--no-progress", "--jobs", "1"]
    t0 = time.monotonic()
    r = run_cli(*argv, timeout=TIMEOUT_S)
    wall = time.monotonic() - t0
    assert r.returncode == (0 if command == "gallery" else 1), r.stderr  # batch: its one preset failed
    assert "Traceback" not in r.stderr, r.stderr
    if command == "gallery":
        assert r.stdout.strip() == f"4 render(s), {len(SKIPPED)} skipped -> {out / 'index.html'}", (r.stdout, wall)

    atimes = atimes_of(ages)  # before the snapshot, which reads every file
    assert snapshot(outside) == before  # nothing outside OUT was written, deleted or modified
    assert atimes == ages  # nor read, nor listed
    assert not any(p.exists() for p in inside)  # while inside OUT the dead writer's temporaries were swept

    page = (out / "index.html").read_text()
    found = cards(page)
    for name, why in SKIPPED.items():
        assert name in found, (name, sorted(found))
        assert f'<div class="skip">skipped: ' in found[name] and why in found[name].replace("&#x27;", "'"), found[name]
    good = found["good"]
    assert 'src="good/good.mp4" poster="good/good.poster.jpg"' in good and (out / "good/good.poster.jpg").is_file()
    assert "good &lt;&amp;&gt;" in good and "until 0.50 s (median the end) at 0.001 rad" in good
    assert "rigid, N=3" in good and "10 frames, 64x36 @ 10 fps" in good and "rk4, dt=0.001 s x100, f64" in good
    assert 'src="good_gif/good_gif.gif"' in found["good_gif"]
    assert "<script" not in page.replace(f"<script>{gallery.SCRIPT}</script>", "") and "<img src=x" not in page
    assert ('<dd><code class="set">description=&quot;&lt;/code&gt;&lt;script&gt;alert(1)&lt;/script&gt;&quot;</code>'
            '<br><code class="set">name=&#x27;x&#x27; onload=&quot;y&quot;</code></dd>') in good  # not 7, not null
    assert ('<dd><span class="variant">&lt;img src=x onerror=alert(2)&gt;: parts from the finest at 0.25 s, faithful '
            'until 0.50 s</span><br><span class="variant">f64 &amp; co: the one the others part from, faithful until '
            'the end</span><br><span class="variant">variant 3: parts from the finest at ?, faithful until ?</span>'
            '<br><span class="variant">variant 4: never parts from the finest, faithful until ?</span></dd>') in good
    assert LONG_NAME in page and "skip" not in found[LONG_NAME]
    assert "skip" not in found["infinite"] and "inf frames" in found["infinite"]
    assert len(found) == 4 + len(SKIPPED) + (command == "batch")
    if command == "batch":
        assert "Failed in the last batch" in page and "<b>bad</b>" in page and "tiny" in found


def test_up_to_date_reads_nothing_outside_out(tmp_path):
    """`batch` skips a render its metadata says is intact; outputs naming a file outside made it hash that file.
    The same metadata without that entry is up to date, so only the entry outside makes the difference."""
    out, outside = tmp_path / "out", tmp_path / "outside"
    outside.mkdir()
    mp4(outside / "x.mp4")
    scene = load("classic", ['name="uptodate"', 'video.formats=["mp4", "gif"]'])
    d = scene.out_dir(out)
    d.mkdir(parents=True)
    mp4(d / "uptodate.mp4")
    (d / "uptodate.gif").write_bytes(b"GIF89a")
    files = {"uptodate.mp4": d / "uptodate.mp4", "uptodate.gif": d / "uptodate.gif"}
    meta = {**meta_of("uptodate", files), "preset_hash": scene.hash(), "versions": {"package": __version__}}
    (d / "metadata.json").write_text(json.dumps(meta))
    assert gallery.up_to_date(scene, out) == meta

    before = snapshot(outside)
    ages = age_atimes(list(before))
    for name in ("../../outside/x.mp4", str(outside / "x.mp4")):
        hostile = json.loads(json.dumps(meta))
        hostile["outputs"][name] = (outside / "x.mp4").stat().st_size
        hostile["outputs_sha256"][name] = before[outside / "x.mp4"][3]
        (d / "metadata.json").write_text(json.dumps(hostile))
        assert gallery.up_to_date(scene, out) is None
    (d / "metadata.json").unlink()
    os.mkfifo(d / "metadata.json")
    assert gallery.up_to_date(scene, out) is None  # at once: the FIFO is never waited on
    atimes = atimes_of(ages)
    assert snapshot(outside) == before and atimes == ages


def test_the_sweeper_never_enters_a_symlinked_folder(tmp_path):
    (tmp_path / "real").mkdir()
    stale = stale_temporaries(tmp_path / "real", "x.mp4")
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert atomic.sweep_stale(tmp_path / "link") == [] and all(p.exists() for p in stale)
    assert atomic.sweep_stale(tmp_path / "real") == stale and not any(p.exists() for p in stale)


def test_the_sweeper_takes_only_what_temp_beside_makes(tmp_path):
    """A user's files that look like a dead writer's temporaries, but for mkstemp's 8 characters or a suffix
    this package never uses, stay; a real one of a dead writer goes."""
    pid = dead_pid()
    mine = [tmp_path / f".{name}.{atomic.HOST}-{pid}.{tail}"
            for name, tail in (("db", "snap.gz"), ("backup", "v1.tar"), ("x.mp4", "abcdefgh.tar"),
                               ("x.mp4", "abcdefghi.part"))]
    for f in mine:
        f.write_text("mine")
    old = time.time() - 2 * atomic.FOREIGN_STALE_S
    foreign = tmp_path / f".db.deadbeef-{pid}.snapshot.gz"
    foreign.write_text("mine")
    os.utime(foreign, (old, old))
    real = stale_temporaries(tmp_path, "x.mp4")
    assert atomic.sweep_stale(tmp_path) == real
    assert all(f.exists() for f in [*mine, foreign])
    with pytest.raises(ValueError, match="suffix"):
        atomic.temp_beside(tmp_path / "x.tar", suffix=".tar")


@pytest.mark.parametrize("folder", ["/sys/kernel", "readonly"])
def test_an_unwritable_gallery_folder_is_bad_input(tmp_path, folder):
    """A folder no one may write: as root (CI), one made immutable (chattr +i), which stops root too."""
    reason, pinned = os.strerror(errno.EACCES), contextlib.nullcontext()
    if folder == "readonly":
        folder = tmp_path / "readonly"
        folder.mkdir()
        if os.geteuid() == 0:
            reason, pinned = os.strerror(errno.EPERM), immutable(folder)
        else:
            folder.chmod(0o555)
    elif not os.path.isdir(folder):
        pytest.skip(f"no {folder} here")
    with pinned:
        r = run_cli("gallery", "--out", folder, timeout=TIMEOUT_S)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert lines[0] == f"pendulum: error: --out {folder}: cannot write the gallery there: {reason}"


scalars = st.none() | st.booleans() | st.integers(-10**18, 10**18) | st.floats() | st.text(max_size=20)
json_values = st.recursive(scalars, lambda kids: st.lists(kids, max_size=4) | st.dictionaries(
    st.text(max_size=12), kids, max_size=4), max_leaves=20)
variant = st.fixed_dictionaries({}, optional={"label": json_values, "divergence_s": json_values, "faithfulness":
                                              st.fixed_dictionaries({}, optional={"faithful_until_s": json_values})
                                              | json_values})
comparisons = st.fixed_dictionaries({}, optional={"finest": json_values, "variants": st.lists(variant | json_values,
                                                                                               max_size=4)})
sections = st.fixed_dictionaries({}, optional={**{k: json_values
                                                  for k in (*confined.SECTIONS, "frames", "duration", "fps")},
                                               "overrides": st.lists(json_values, max_size=4) | json_values,
                                               "compare": comparisons | json_values})


@settings(max_examples=300, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(meta=st.one_of(json_values, sections))
def test_any_json_gives_a_card_or_says_why_not(tmp_path, meta):
    """Whatever JSON a metadata.json holds, its card is made or the render is skipped with a reason; no crash."""
    d = tmp_path / "r"
    d.mkdir(exist_ok=True)
    (d / "metadata.json").write_text(json.dumps(meta))
    [found] = gallery.find_renders(tmp_path)
    html = gallery.card(found, Path("r"))
    assert ("skipped: " in html) == bool(found.skipped) and (found.meta is None) == bool(found.skipped)


def test_a_folder_where_a_poster_goes_leaves_that_card_without_a_poster_not_the_page_unwritten(tmp_path):
    out = tmp_path / "out"
    r = run_cli("render", "classic", "--set", "video.width=64", "--set", "video.height=36", "--set",
                "video.duration=0.5", "--set", 'video.formats=["mp4"]', "--out", out, "--no-progress")
    assert r.returncode == 0, r.stderr
    [folder] = out.iterdir()
    blocker = folder / f"{folder.name}.poster.jpg"
    blocker.mkdir()
    os.utime(blocker, (0, 0))  # older than the video: a poster "to make again"
    r = run_cli("gallery", "--out", out)
    assert r.returncode == 0 and r.stdout.startswith("1 render(s) ->"), r.stderr
    page = (out / "index.html").read_text()
    assert f'src="{folder.name}/{folder.name}.mp4"' in page and "poster=" not in page and blocker.is_dir()
