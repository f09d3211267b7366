"""Text for the canvas: a bundled bitmap font drawn by Taichi kernels, with no system font and no Pillow.

The glyphs are X.Org's misc-fixed fonts (public domain; see render/draw/font_data.py and
benchmarks/make_font_data.py), in two sizes:

- "6x13": 6×13 pixel cells (ascent 11), for small renders (256×144) and labels;
- "10x20": 10×20 pixel cells (ascent 16), for a 720p HUD.

Either can be scaled by a whole factor (each font pixel becomes scale×scale pixels). The fonts are
fixed-width, so a string is len(s) cells wide. Both carry ASCII, Latin-1 (± × · ° µ ² ½ ...), Greek
(θ ω π Δ ε ...), dashes, quotes, ′ ″ ‰, superscripts and subscripts (⁰..⁹ ⁻ ₀..₉), arrows, and the maths
signs − ∓ √ ∞ ≈ ≠ ≡ ≤ ≥ ∂ ∆ ∇ ∑ ∫ ∝ ∈ ⋅. A character outside that set is drawn as a lookalike where there
is one (ϴ as Θ, the ohm sign as Ω, a thin space as a space, full-width or circled letters and digits as
plain ones, ...) and otherwise as '?'. A tab is one space, and '\\n' starts a new line.

Usage (after ti.init; a Font holds every size in one Taichi field of 50 KB):

    font = Font("10x20")                                               # the default size for its calls
    font.draw(frame, f"t = {t:5.2f} s", 20, 20)                        # frame: H×W×3 uint8 numpy array
    font.draw(canvas.rgb, "θ1", x, y, colour=(1, .8, .2), ha="right", va="middle", tiles=canvas.drawn)
    font.draw_many(frame, [("-π", x0, y, {"ha": "center", "size": "6x13"}), ("π", x1, y, {"ha": "center"})])
    text_width("rk4 dt=1e-3 f64", scale=1, size="10x20")              # host-side layout: 150

The target is either an H×W×3 uint8 numpy array (C-contiguous) or a ti.Vector.field(3, ti.f32, (H, W))
holding colours in [0, 1]. `blend` is "max" (per channel, the canvas's own compositing: order-independent)
or "over" (alpha blend: target·(1 − alpha) + colour·alpha). With `tiles` (an i32 field of TILE×TILE tiles,
like Canvas.drawn) every tile a glyph pixel lands in is set to 1, so a tile-based compositor picks it up.

Every call is one serial kernel launch over the glyphs of all its strings, in order, clipped to the target:
frames are byte-identical whatever the thread count, later strings paint over earlier ones under "over",
and colour arithmetic happens in f32 (fields) or integers (uint8 arrays) whatever Taichi's default_fp.
Cost (benchmarks/font_cost.py): one Taichi launch per call, whatever the number of strings, plus about
1 µs of host layout per glyph; draw a frame's whole HUD with one draw_many. Another kernel can draw rows of
layout() itself with glyph_max (a ti.func), one thread per glyph of a line, as render/draw/hud.py does.
"""

import base64
import math
import unicodedata
import zlib

import numpy as np
import taichi as ti

from . import font_data
from ..physics import runtime

SIZES = tuple(font_data.FONTS)  # ("6x13", "10x20")
COLUMNS = 10  # per glyph drawn: atlas row, left, top, scale, r, g, b, alpha, cell width, cell height
FALLBACK = "?"
TILE = 8  # the canvas's tile size, for `tiles`
BLENDS = ("max", "over")
HA = ("left", "center", "right")
VA = ("top", "middle", "baseline", "bottom")
# lookalikes for characters the font lacks (tried before the fallback); '\t' is a space
SUBSTITUTES = {
    "\t": " ", "\u2002": " ", "\u2003": " ", "\u2007": " ", "\u2009": " ", "\u202f": " ",  # spaces
    "\u03f4": "\u0398", "\u03d0": "\u03b2", "\u03f0": "\u03ba", "\u03f1": "\u03c1", "\u03d6": "\u03c0",  # ϴ ϐ ϰ ϱ ϖ
    "\u2010": "-", "\u2011": "-", "\u2012": "\u2013", "\u2015": "\u2014",  # hyphens and dashes
    "\u2715": "\u00d7", "\u2716": "\u00d7", "\u2a2f": "\u00d7",  # multiplication x
    "\u201a": ",", "\u201b": "\u2018", "\u201e": "\u201c", "\u201f": "\u201c",  # low and reversed quotes
    "\u2a7d": "\u2264", "\u2a7e": "\u2265",  # slanted ≤ ≥
    "\u2044": "/", "\u2215": "/", "\u2236": ":", "\u223c": "~", "\u2217": "*", "\u2223": "|",
}
# NFKD folds many more (ﬁ, ①, full-width letters ...) to something drawable; only single characters count


def _glyph_table() -> dict[int, int]:
    """Code point -> glyph index, in the order of font_data.RANGES."""
    table, i = {}, 0
    for lo, hi in font_data.RANGES:
        for cp in range(lo, hi + 1):
            table[cp] = i
            i += 1
    return table


GLYPHS = _glyph_table()
_index_cache: dict[str, int] = {}


def glyph_index(ch: str) -> int:
    """The glyph drawn for one character: its own, a lookalike's, or the fallback's."""
    i = _index_cache.get(ch)
    if i is None:
        i = GLYPHS.get(ord(ch))
        if i is None and ch in SUBSTITUTES:
            i = GLYPHS.get(ord(SUBSTITUTES[ch]))
        if i is None:
            folded = unicodedata.normalize("NFKD", ch)
            base = "".join(c for c in folded if not unicodedata.combining(c))
            if len(base) == 1:
                i = GLYPHS.get(ord(base))
        if i is None:
            i = GLYPHS[ord(FALLBACK)]
        _index_cache[ch] = i
    return i


def has_glyph(ch: str) -> bool:
    """Whether the font draws `ch` itself (not a lookalike, not the fallback)."""
    return ord(ch) in GLYPHS


def _face(size: str) -> dict:
    if size not in font_data.FONTS:
        raise ValueError(f"unknown font size {size!r}; bundled: {', '.join(SIZES)}")
    return font_data.FONTS[size]


def text_width(s: str, scale: int = 1, size: str = "6x13") -> int:
    """Width in pixels of the widest line of `s`, as draw() lays it out."""
    return max(len(line) for line in s.split("\n")) * _face(size)["width"] * int(scale)


def text_height(s: str, scale: int = 1, size: str = "6x13") -> int:
    """Height in pixels of `s`: one cell height per line."""
    return (s.count("\n") + 1) * _face(size)["height"] * int(scale)


def glyph_rows(size: str) -> np.ndarray:
    """(glyphs, height) uint32 row masks of one size, bit c set when column c (0 = left) is lit."""
    spec = _face(size)
    w, h = spec["width"], spec["height"]
    nbytes = (w + 7) // 8
    raw = np.frombuffer(zlib.decompress(base64.b64decode("".join(spec["bitmap"]))), np.uint8)
    raw = raw.reshape(-1, h, nbytes).astype(np.uint32)
    packed = np.zeros(raw.shape[:2], np.uint32)
    for b in range(nbytes):  # big-endian bytes, leftmost pixel in the top bit
        packed = (packed << 8) | raw[:, :, b]
    lead = 8 * nbytes - 1
    out = np.zeros_like(packed)
    for c in range(w):
        out |= ((packed >> (lead - c)) & 1) << c
    return out


def _byte(v: float) -> int:
    return min(255, max(0, int(math.floor(float(v) * 255.0 + 0.5))))


@ti.data_oriented
class Font(runtime.Launcher):
    """Every bundled size in one Taichi field of glyph rows, and the kernels that draw strings with them.

    `size` is the default for calls that name none; any call can pick another, and one draw_many can mix
    sizes, so a whole HUD is one kernel launch.
    """

    def __init__(self, size: str = "6x13"):
        self.size = size
        _face(size)
        self.faces = {}  # size -> (first atlas row, width, height, ascent)
        rows = [glyph_rows(name) for name in SIZES]
        atlas = np.zeros((sum(len(r) for r in rows), max(r.shape[1] for r in rows)), np.uint32)
        first = 0
        for name, r in zip(SIZES, rows):
            atlas[first:first + len(r), :r.shape[1]] = r
            spec = font_data.FONTS[name]
            self.faces[name] = (first, spec["width"], spec["height"], spec["ascent"])
            first += len(r)
        self.rows = atlas  # host copy, for tests and tools
        self.atlas = runtime.field("font.glyphs", ti.u32, atlas.shape)
        self.atlas.from_numpy(atlas)

    # ------------------------------------------------------------ host-side layout
    def text_width(self, s: str, scale: int = 1, size: str | None = None) -> int:
        return text_width(s, scale, size or self.size)

    def text_height(self, s: str, scale: int = 1, size: str | None = None) -> int:
        return text_height(s, scale, size or self.size)

    def glyph(self, ch: str, size: str | None = None) -> np.ndarray:
        """The row masks `ch` is drawn with (after lookalikes and the fallback)."""
        first, _, h, _ = self.faces[size or self.size]
        return self.rows[first + glyph_index(ch), :h]

    def layout(self, s: str, x, y, colour=(1.0, 1.0, 1.0), scale: int = 1, ha: str = "left", va: str = "top",
               alpha: float = 1.0, size: str | None = None) -> np.ndarray:
        """One row per drawn glyph: atlas row, left, top, scale, r, g, b, alpha (bytes), cell width, height.

        (x, y) is where the text's anchor goes: ha picks the left edge, centre or right edge of each line,
        va the top, middle, baseline (of the first line) or bottom of the block. Spaces are not listed.
        Text that does not change can be laid out once and drawn with each frame's other rows via draw_glyphs.
        """
        return np.array(self._rows(s, x, y, colour, scale, ha, va, alpha, size), np.int32).reshape(-1, COLUMNS)

    def _rows(self, s, x, y, colour=(1.0, 1.0, 1.0), scale=1, ha="left", va="top", alpha=1.0, size=None):
        size = size or self.size
        if size not in self.faces:
            _face(size)  # raises
        first, w, h, ascent = self.faces[size]
        scale = int(scale)
        if scale < 1:
            raise ValueError(f"scale must be a whole number >= 1, got {scale}")
        if ha not in HA or va not in VA:
            raise ValueError(f"ha must be one of {HA} and va one of {VA}, got {ha!r}, {va!r}")
        lines = s.split("\n")
        cw, ch = w * scale, h * scale
        x, y = math.floor(x + 0.5), math.floor(y + 0.5)
        top = (y if va == "top" else y - len(lines) * ch // 2 if va == "middle" else
               y - ascent * scale if va == "baseline" else y - len(lines) * ch)
        tail = (scale, _byte(colour[0]), _byte(colour[1]), _byte(colour[2]), _byte(alpha), w, h)
        out = []
        for row, line in enumerate(lines):
            left = x if ha == "left" else x - len(line) * cw // 2 if ha == "center" else x - len(line) * cw
            y_row = top + row * ch
            out += [(first + glyph_index(c), left + k * cw, y_row, *tail) for k, c in enumerate(line) if c != " "]
        return out

    # ------------------------------------------------------------ drawing
    def draw(self, target, s: str, x, y, colour=(1.0, 1.0, 1.0), scale: int = 1, ha: str = "left",
             va: str = "top", alpha: float = 1.0, size: str | None = None, blend: str = "max", tiles=None):
        """Draw `s` into `target` (see the module docstring); returns target."""
        return self.draw_glyphs(target, self.layout(s, x, y, colour, scale, ha, va, alpha, size), blend, tiles)

    def draw_many(self, target, items, blend: str = "max", tiles=None):
        """Several strings in one kernel launch. items: (text, x, y) or (text, x, y, {layout keywords})."""
        rows = []
        for it in items:
            rows += self._rows(*it[:3], **(it[3] if len(it) > 3 else {}))
        return self.draw_glyphs(target, np.array(rows, np.int32).reshape(-1, COLUMNS), blend, tiles)

    def draw_glyphs(self, target, glyphs: np.ndarray, blend: str = "max", tiles=None):
        """Draw rows made by layout() (concatenated as you like) in one kernel launch."""
        if blend not in BLENDS:
            raise ValueError(f"blend must be one of {BLENDS}, got {blend!r}")
        n = len(glyphs)
        if n == 0:
            return target
        if glyphs.dtype != np.int32 or not glyphs.flags.c_contiguous:
            glyphs = np.ascontiguousarray(glyphs, np.int32)
        over = blend == "over"
        if isinstance(target, np.ndarray):
            if target.dtype != np.uint8 or target.ndim != 3 or target.shape[2] != 3:
                raise TypeError(f"a numpy target must be H×W×3 uint8, got {target.dtype} {target.shape}")
            if not target.flags.c_contiguous:
                raise ValueError("a numpy target must be C-contiguous")
            if tiles is None:
                self.launch("text_bytes", target, glyphs, n, over)
            else:
                self.launch("text_bytes_tiled", target, glyphs, n, over, tiles)
        else:  # without tiles, the atlas stands in for them (a template needs a field; it is not written)
            self.launch("text_field", target, glyphs, n, over, self.atlas if tiles is None else tiles,
                        tiles is not None)
        return target

    # ------------------------------------------------------------ kernels
    @ti.kernel
    def text_bytes(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3), glyphs: ti.types.ndarray(dtype=ti.i32, ndim=2),
                   n: ti.i32, over: ti.template()):
        ti.loop_config(serialize=True)  # in order: deterministic, later strings over earlier ones
        for i in range(n):
            self._glyph(out, glyphs, i, over, out, False, False)

    @ti.kernel
    def text_bytes_tiled(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3),
                         glyphs: ti.types.ndarray(dtype=ti.i32, ndim=2), n: ti.i32, over: ti.template(),
                         tiles: ti.template()):
        ti.loop_config(serialize=True)
        for i in range(n):
            self._glyph(out, glyphs, i, over, tiles, True, False)

    @ti.kernel
    def text_field(self, target: ti.template(), glyphs: ti.types.ndarray(dtype=ti.i32, ndim=2), n: ti.i32,
                   over: ti.template(), tiles: ti.template(), mark: ti.template()):
        ti.loop_config(serialize=True)
        for i in range(n):
            self._glyph(target, glyphs, i, over, tiles, mark, True)

    @ti.func
    def glyph_max(self, out: ti.template(), glyphs: ti.template(), i):
        """Row i of `glyphs` into a uint8 target with a max, as draw_glyphs draws it. It writes only inside
        its own cell, and the cells of one line do not overlap: one thread per glyph of a line is no race."""
        self._glyph(out, glyphs, i, False, out, False, False)

    @ti.func
    def _glyph(self, out: ti.template(), glyphs: ti.template(), i, over: ti.template(), tiles: ti.template(),
               mark: ti.template(), field: ti.template()):
        """One glyph, clipped: rows of the cell, then the lit font pixels of a row, each scale pixels wide."""
        g = ti.Vector([glyphs[i, k] for k in ti.static(range(COLUMNS))])
        s, a8 = g[3], g[7]
        full = ti.cast(255.0, ti.f32)
        a = ti.cast(a8, ti.f32) / full  # f32 whatever default_fp, for the field path
        col = ti.Vector([ti.cast(g[4 + k], ti.f32) / full for k in ti.static(range(3))])
        h, w = out.shape[0], out.shape[1]
        y0, y1 = ti.max(g[2], 0), ti.min(g[2] + g[9] * s, h)
        x0, x1 = ti.max(g[1], 0), ti.min(g[1] + g[8] * s, w)
        for y in range(y0, y1):
            bits = self.atlas[g[0], (y - g[2]) // s]
            if bits:
                for c in range(g[8]):
                    if (bits >> ti.cast(c, ti.u32)) & ti.u32(1):
                        left = g[1] + c * s
                        for x in range(ti.max(left, x0), ti.min(left + s, x1)):
                            if ti.static(field):
                                if ti.static(over):
                                    out[y, x] = out[y, x] * (ti.cast(1.0, ti.f32) - a) + col * a
                                else:
                                    out[y, x] = ti.max(out[y, x], col * a)
                            else:
                                for k in ti.static(range(3)):
                                    old = ti.cast(out[y, x, k], ti.i32)
                                    if ti.static(over):  # integer alpha blend, rounded: exact whatever default_fp
                                        out[y, x, k] = ti.cast((old * (255 - a8) + g[4 + k] * a8 + 127) // 255, ti.u8)
                                    else:
                                        out[y, x, k] = ti.cast(ti.max(old, (g[4 + k] * a8 + 127) // 255), ti.u8)
                            if ti.static(mark):
                                tiles[y // TILE, x // TILE] = 1
