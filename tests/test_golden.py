"""Golden frames for every preset, compared on raw frames before encoding.

Metric: per-channel absolute difference; a frame matches when at most MAX_BAD_FRACTION of its pixel
channels differ by more than ATOL (as Manim does). Goldens are 256x144 PNGs in tests/golden/<preset>/.
Regenerate after a deliberate visual change with `make goldens` (pytest tests/test_golden.py --update-goldens).
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from conftest import PICKS, render_small
from render.config.scene import list_presets


GOLDEN = Path(__file__).parent / "golden"
DIFFS = Path(__file__).resolve().parent.parent / "out" / "golden-diffs"
ATOL = 2
MAX_BAD_FRACTION = 1e-3
PRESETS = [p.stem for p in list_presets()]


def raw_frames(name, out, threads=None):
    """The raw frames PICKS names, as rendered (encoding too, since that is the code path users run)."""
    return render_small(name, out, threads)[2]


def compare(expected: np.ndarray, actual: np.ndarray, label: str):
    """Raise AssertionError naming diff images under out/golden-diffs/ if the frames differ."""
    if expected.shape == actual.shape:
        bad = np.abs(expected.astype(np.int16) - actual.astype(np.int16)) > ATOL
        if bad.mean() <= MAX_BAD_FRACTION:
            return
        diff = (bad.any(axis=2)[..., None] * np.array([255, 0, 255], np.uint8)).astype(np.uint8)
        detail = f"{bad.mean():.2%} of pixel channels differ by more than {ATOL}"
    else:
        diff = np.zeros_like(actual)
        detail = f"shape {actual.shape} != golden {expected.shape}"
    DIFFS.mkdir(parents=True, exist_ok=True)
    paths = []
    for kind, img in (("expected", expected), ("actual", actual), ("diff", diff)):
        path = DIFFS / f"{label}_{kind}.png"
        iio.imwrite(path, img)
        paths.append(str(path))
    raise AssertionError(f"{label}: {detail}; see {', '.join(paths)}. If the change is deliberate: make goldens")


@pytest.fixture(scope="module")
def rendered(preset_renders):
    return {name: frames for name, (_, _, frames) in preset_renders.items()}


@pytest.mark.parametrize("name", PRESETS)
def test_frames_match_goldens(rendered, name, update_goldens):
    frames = rendered[name]
    folder = GOLDEN / name
    if update_goldens:
        folder.mkdir(parents=True, exist_ok=True)
        for pick, frame in frames.items():
            iio.imwrite(folder / f"{pick}.png", frame, optimize=True)
        return
    missing = [p for p in PICKS if not (folder / f"{p}.png").exists()]
    assert not missing, (f"preset {name!r} has no golden frames {missing} in {folder}: create them with "
                         f"`make goldens` and commit them")
    for pick, frame in frames.items():
        compare(iio.imread(folder / f"{pick}.png"), frame, f"{name}_{pick}")


def test_goldens_are_small_and_belong_to_presets():
    for png in GOLDEN.rglob("*.png"):
        assert png.stat().st_size < 100_000, png
        assert png.parent.name in PRESETS, f"{png}: golden for a preset that no longer exists"


def test_an_altered_golden_fails_with_diff_images_and_restoring_passes(rendered):
    name = PRESETS[0]
    golden = iio.imread(GOLDEN / name / "later.png")
    compare(golden, rendered[name]["later"], "selftest_ok")
    altered = golden.copy()
    altered[40:60, 100:140] = 255 - altered[40:60, 100:140]
    with pytest.raises(AssertionError, match="golden-diffs") as err:
        compare(altered, rendered[name]["later"], "selftest")
    for kind in ("expected", "actual", "diff"):
        assert (DIFFS / f"selftest_{kind}.png").exists(), err.value
        (DIFFS / f"selftest_{kind}.png").unlink()
    compare(golden, rendered[name]["later"], "selftest_restored")


def test_same_preset_renders_byte_identical_frames_twice_and_across_thread_counts(rendered, tmp_path):
    name = "rigid_chaos"
    again = raw_frames(name, tmp_path / "a", threads=1)
    other = raw_frames(name, tmp_path / "b", threads=2)
    for pick, frame in rendered[name].items():
        assert frame.tobytes() == again[pick].tobytes(), f"{pick}: differs between runs"
        assert frame.tobytes() == other[pick].tobytes(), f"{pick}: differs between 1 and 2 threads"


@pytest.mark.parametrize("name", PRESETS)
def test_every_preset_is_the_same_bytes_at_1_and_8_threads_as_on_all_cpus(preset_renders, name, tmp_path, monkeypatch):
    """The session's renders ran on all CPUs (2 in CI); each preset again on 1 thread and on 8 gives the same
    MP4 and GIF, byte for byte (every frame is in them, and the audio track), and the same raw frames. At this
    size the simulation and the drawing would run on the launching thread (runtime.SERIAL_WORK,
    canvas.BANDED_WORK): on 8 threads both go to the pool here, so that the threads are compared with one."""
    from render.draw import canvas
    from render.physics import runtime
    _, meta, frames = preset_renders[name]
    for threads in (1, 8):
        if threads == 8:
            monkeypatch.setattr(runtime, "SERIAL_WORK", 0)
            monkeypatch.setattr(canvas, "BANDED_WORK", 0)
        _, again, again_frames = render_small(name, tmp_path / str(threads), threads)
        assert again["outputs_sha256"] == meta["outputs_sha256"], f"{threads} threads"
        for pick, frame in frames.items():
            assert frame.tobytes() == again_frames[pick].tobytes(), f"{pick} at {threads} threads"
