"""The bundled bitmap font: exact glyph pixels, scale, clipping, blending, layout, fallback, determinism, golden."""
import hashlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT
from render.draw import font_data
from render.physics import runtime

GOLDEN = Path(__file__).parent / "golden_text" / "hud.png"  # not a preset: apart from tests/golden/

# 6x13 glyphs as in the misc-fixed BDF (rows 0..12 of the cell, ascent 11)
A_6X13 = """
......
......
..#...
.#.#..
#...#.
#...#.
#...#.
#####.
#...#.
#...#.
#...#.
......
......
"""
THETA_6X13 = """
......
......
.##...
#..#..
#..#..
#..#..
####..
#..#..
#..#..
#..#..
.##...
......
......
"""


def art(s):
    return np.array([[c == "#" for c in line] for line in s.split()], bool)


@pytest.fixture(scope="module")
def font():
    runtime.init("cpu", "f64")
    from render.draw.font import Font
    return Font("6x13")


@pytest.fixture
def small(font):
    return font


def blank(h=20, w=40):
    return np.zeros((h, w, 3), np.uint8)


def lit(img):
    return img.max(axis=2) > 0


def test_glyphs_are_exactly_the_bdf_bitmaps(small):
    img = small.draw(blank(), "Aθ", 3, 2)
    expected = np.zeros((20, 40), bool)
    expected[2:15, 3:9] = art(A_6X13)
    expected[2:15, 9:15] = art(THETA_6X13)
    np.testing.assert_array_equal(lit(img), expected)
    assert set(np.unique(img)) == {0, 255}  # white, no antialiasing


def test_colour_bytes_and_whole_number_scale(small):
    img = small.draw(blank(), "A", 0, 0, colour=(0.5, 0.25, 1.0))
    assert tuple(img[7, 0]) == (128, 64, 255)  # round(c * 255)
    big = small.draw(blank(30, 20), "A", 0, 0, scale=2)
    np.testing.assert_array_equal(lit(big)[:26, :12], np.kron(art(A_6X13), np.ones((2, 2), bool)))
    assert not lit(big)[26:].any() and not lit(big)[:, 12:].any()
    with pytest.raises(ValueError):
        small.draw(blank(), "A", 0, 0, scale=0)


def test_every_label_character_of_the_brief_is_in_both_sizes(font):
    from render.draw.font import SIZES, has_glyph
    wanted = "t=12.34srk4dt1e-3f64θωπΔεΘΩ±×·°µ≤≥−→√∞≈²₁₂⁻"
    for ch in wanted:
        assert has_glyph(ch), ch
        for size in SIZES:
            assert font.glyph(ch, size).any(), (size, ch)
    assert not font.glyph(" ").any() and font.glyph("?").any()
    np.testing.assert_array_equal(font.glyph("A"), [int(row[::-1].replace(".", "0").replace("#", "1"), 2)
                                                    for row in A_6X13.split()])
    assert Path(font_data.__file__).stat().st_size < 20_000  # the whole bundle, both sizes


def test_unknown_characters_fall_back(small):
    from render.draw.font import text_width
    question = small.draw(blank(), "?", 0, 0)
    for ch in ("中", "\x07", "🙂"):
        np.testing.assert_array_equal(small.draw(blank(), ch, 0, 0), question, err_msg=repr(ch))
    # lookalikes before the fallback: the ohm sign is Omega, a full-width A is A, a tab is a space
    np.testing.assert_array_equal(small.draw(blank(), "\u2126", 0, 0), small.draw(blank(), "Ω", 0, 0))
    np.testing.assert_array_equal(small.draw(blank(), "\uff21", 0, 0), small.draw(blank(), "A", 0, 0))
    np.testing.assert_array_equal(small.draw(blank(), "A\tB", 0, 0), small.draw(blank(), "A B", 0, 0))
    assert text_width("中?", 1) == 12  # one cell per character, whatever is drawn


def test_text_width_and_alignment(font):
    from render.draw.font import text_height, text_width
    assert text_width("t = 12.34 s") == 66 and text_width("t = 12.34 s", 2) == 132
    assert text_width("t = 12.34 s", size="10x20") == 110
    assert text_width("ab\nlonger\nc") == 36 and text_height("ab\nlonger\nc", 2) == 78
    assert font.text_width("θ1", 3, "10x20") == 60 and font.text_height("θ1", size="10x20") == 20
    big = {"size": "10x20"}
    for ha, left in (("left", 50), ("center", 50 - 10), ("right", 50 - 20)):
        ref = font.draw(blank(60, 100), "HH", left, 10, **big)
        np.testing.assert_array_equal(font.draw(blank(60, 100), "HH", 50, 10, ha=ha, **big), ref, err_msg=ha)
    for va, top in (("top", 30), ("middle", 30 - 10), ("baseline", 30 - 16), ("bottom", 30 - 20)):
        ref = font.draw(blank(60, 100), "Hg", 10, top, **big)
        np.testing.assert_array_equal(font.draw(blank(60, 100), "Hg", 10, 30, va=va, **big), ref, err_msg=va)
    # a right-aligned string ends exactly at x (its last cell's lit columns stay left of it)
    img = font.draw(blank(60, 100), "HH", 99, 0, ha="right", **big)
    assert lit(img)[:, :79].sum() == 0 and lit(img)[:, 79:99].any()
    with pytest.raises(ValueError):
        font.draw(blank(), "A", 0, 0, size="7x13")


def test_lines_and_clipping_at_every_edge(small):
    text = "A\nθ"
    ref = small.draw(blank(60, 60), text, 20, 20)  # the whole block, well inside
    for x, y in ((-3, 5), (5, -7), (14, 5), (5, 10), (-5, -20), (17, 3)):
        got = small.draw(blank(20, 20), text, x, y)  # partly (or wholly) outside a 20×20 target
        np.testing.assert_array_equal(got, ref[20 - y:40 - y, 20 - x:40 - x], err_msg=f"{(x, y)}")
    assert not small.draw(blank(20, 20), text, 500, -500).any()
    assert not small.draw(blank(20, 20), text, -7, 0).any()  # ends one column left of the target


def test_blends_on_a_background(small):
    bg = np.full((20, 20, 3), 100, np.uint8)
    over = small.draw(bg.copy(), "A", 0, 0, colour=(1.0, 0.0, 0.2), alpha=0.5, blend="over")
    # integer alpha blend: (old·(255 − a) + c·a + 127) // 255 with a = 128
    assert tuple(over[7, 0]) == ((100 * 127 + 255 * 128 + 127) // 255, (100 * 127 + 127) // 255,
                                 (100 * 127 + 51 * 128 + 127) // 255)
    mx = small.draw(bg.copy(), "A", 0, 0, colour=(1.0, 0.0, 0.2))  # max: a dark channel leaves the background
    assert tuple(mx[7, 0]) == (255, 100, 100)
    assert (over[~lit(small.draw(blank(20, 20), "A", 0, 0))] == 100).all()  # nothing outside the glyph
    # under "over" the later string wins where two overlap
    both = small.draw_many(bg.copy(), [("A", 0, 0, {"colour": (1, 0, 0)}), ("A", 0, 0, {"colour": (0, 0, 1)})],
                           blend="over")
    assert tuple(both[7, 0]) == (0, 0, 255)
    with pytest.raises(ValueError):
        small.draw(bg, "A", 0, 0, blend="add")


def test_field_target_marks_tiles_and_matches_the_byte_path(small):
    import taichi as ti
    from render.draw.font import TILE
    h, w = 32, 48
    field = ti.Vector.field(3, ti.f32, (h, w))
    tiles = ti.field(ti.i32, (h // TILE, w // TILE))
    items = [("θ₁ ≥ π", 3, 2, {"colour": (1.0, 0.5, 0.2)}), ("A", 40, 20, {"scale": 2, "colour": (0.3, 0.9, 1.0)})]
    small.draw_many(field, items, tiles=tiles)
    as_bytes = np.floor(np.minimum(field.to_numpy(), 1.0) * 255 + 0.5).astype(np.uint8)
    np.testing.assert_array_equal(as_bytes, small.draw_many(blank(h, w), items))
    on = lit(as_bytes).reshape(h // TILE, TILE, w // TILE, TILE).any(axis=(1, 3))
    np.testing.assert_array_equal(tiles.to_numpy() == 1, on)
    field.fill(0.4)
    small.draw(field, "A", 0, 0, blend="over", alpha=0.5)  # the field path blends in f32: a = 128/255
    a = 128 / 255
    assert field[7, 0][0] == pytest.approx(0.4 * (1 - a) + a, rel=1e-6) and field[0, 0][0] == pytest.approx(0.4)


def test_draw_many_is_one_launch_equal_to_separate_draws(small):
    items = [("t = 1.00 s", 1, 1), ("rk4", 5, 15, {"colour": (0.2, 1, 0.2), "ha": "left"})]
    separate = blank(40, 80)
    for it in items:
        small.draw(separate, *it[:3], **(it[3] if len(it) > 3 else {}))
    np.testing.assert_array_equal(small.draw_many(blank(40, 80), items), separate)
    assert small.draw_many(blank(), []).sum() == 0


def hud(font):
    """A 256×144 HUD sample: both sizes, scale 2, colours, both blends, alignment, clipping, fallback."""
    img = np.zeros((144, 256, 3), np.uint8)
    img[60:100, 40:200] = (40, 60, 110)
    font.draw(img, "t = 12.34 s", 4, 3)
    font.draw(img, "rk4 dt=1e-3 f64", 252, 3, ha="right", colour=(0.6, 0.9, 0.6))
    font.draw_many(img, [("-π", 40, 130, {"ha": "center"}), ("π/2", 128, 130, {"ha": "center"}),
                         ("π", 216, 130, {"ha": "center"})], blend="over")
    font.draw(img, "θ1 θ2 ω ε Δ ± × · ° µ ≤ ≥ 中", 4, 20, colour=(1.0, 0.8, 0.3))
    font.draw(img, "over", 50, 64, blend="over", alpha=0.6, size="10x20")
    font.draw_many(img, [("x2", 128, 80, {"scale": 2, "va": "middle", "colour": (0.9, 0.4, 0.9), "size": "10x20"}),
                         ("clipped", 230, 136, {"size": "10x20"})])
    return img


def digest(img):
    return hashlib.sha256(img.tobytes()).hexdigest()


def test_hud_matches_its_golden_and_is_deterministic(font, update_goldens):
    import imageio.v3 as iio
    img = hud(font)
    assert digest(hud(font)) == digest(img)
    if update_goldens:
        GOLDEN.parent.mkdir(parents=True, exist_ok=True)
        iio.imwrite(GOLDEN, img)
    assert GOLDEN.exists(), "no golden: run `pytest tests/test_font.py --update-goldens`, look at it, commit it"
    np.testing.assert_array_equal(img, iio.imread(GOLDEN), err_msg=f"differs from {GOLDEN}")


SCRIPT = """
import hashlib, sys
sys.path.insert(0, {tests!r})
from render.physics import runtime
from test_font import hud
for precision, threads in (("f64", 1), ("f32", 2)):
    runtime.init("cpu", precision, threads)
    from render.draw.font import Font
    print(hashlib.sha256(hud(Font("6x13")).tobytes()).hexdigest())
"""


def test_same_bytes_at_any_thread_count_and_precision(font):
    here = digest(hud(font))
    r = subprocess.run([sys.executable, "-c", SCRIPT.format(tests=str(Path(__file__).parent))], cwd=ROOT,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [here, here]
