"""The HUD's text: its words formatted (faces, seconds, step, metres, wrap, fit) and each of its blocks laid
out as glyph rows in the frame (HudText, a mixin of render/draw/hud.py's Hud), with the colours and the
spread axis that the text and the chart share.

Apart from the Hud, which holds its geometry, its baked layer and its kernels, because all of this is plain
Python on the host: run once when the HUD is made (the clock and the spread's value once a frame), never
compiled by Taichi. The split-screen labels (render/draw/split.py) use the same faces and step.
"""
import math

from . import framing
from .font import text_width

WHITE, DIM, FAINT = (0.92, 0.92, 0.92), (0.55, 0.55, 0.55), (0.22, 0.22, 0.22)
AMBER, RED, CURVE = (1.0, 0.72, 0.2), (1.0, 0.34, 0.3), (0.45, 0.85, 1.0)
LOG_LO, LOG_HI = -8.0, 0.5  # the spread axis: log10(spread / reach); neighbours are at most 2 reaches apart
UNITS = (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9))
MAX_LINES = 8  # of the caption
MIN_CHARS = 12  # a caption's column narrower than this is left out: a word a line reads as noise


def faces(h: int) -> tuple[tuple[str, int], tuple[str, int], tuple[str, int]]:
    """(small, big, label) text as (font size, scale) for a frame `h` pixels high."""
    if h < 360:
        return ("6x13", 1), ("6x13", 1), ("6x13", 1)
    if h < 720:
        return ("6x13", 1), ("10x20", 1), ("6x13", 1)
    k = h // 720
    return ("10x20", k), ("10x20", 2 * k), ("6x13", k)


def seconds(x: float) -> str:
    return f"{x:.2f} s"


def step(dt) -> str:
    """1e-3 rather than 0.001: the exponent is what a reader compares."""
    if isinstance(dt, str):
        return dt
    if dt >= 0.01:
        return f"{dt:.3g}"
    mant, exp = f"{dt:.2e}".split("e")
    return f"{mant.rstrip('0').rstrip('.')}e{int(exp)}"


def metres(d: float) -> str:
    for unit, size in UNITS:
        if d >= size:
            return f"{d / size:.3g} {unit}"
    return "< 1 nm"


def wrap(s: str, chars: int) -> list[str]:
    """s in lines of at most `chars` characters, broken at spaces (a longer word cut); [] if chars < MIN_CHARS."""
    if chars < MIN_CHARS:
        return []
    lines = []
    for word in s.split():
        word = fit(word, chars)
        if lines and len(lines[-1]) + 1 + len(word) <= chars:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return lines


def fit(s: str, chars: int) -> str:
    """s cut to `chars` characters, with an ellipsis when it was longer."""
    return s if len(s) <= chars else (s[:max(chars - 1, 0)].rstrip() + "…" if chars > 0 else "")


class HudText:
    """The Hud's blocks of text as Font.layout's glyph rows, placed by the Hud's geometry (its margin m, the
    chart's gx0, gx1, gy1, its ticks) in its fonts (small, big, lab and their scales ss, bs, ls)."""

    def cell(self, size, scale):
        return text_width("x", scale, size), self.font.text_height("x", scale, size)

    def text(self, s, x, y, colour=WHITE, size=None, scale=None, **kw):
        return self.font.layout(s, x, y, colour, scale or self.ss, size=size or self.small, **kw)

    def certificate(self) -> list:
        """The top right block: until when all, and half, of the certified pendulums are faithful."""
        i = self.info
        if i.faithful_until_s is None or not (self.words or i.one_line):
            return []
        first, half = i.faithful_until_s >= self.duration, i.median_until_s >= self.duration
        lines = [("faithful to the end", WHITE)] if first else [
            (f"all faithful to {seconds(i.faithful_until_s)}", AMBER),
            ("half faithful to the end" if half else f"half faithful to {seconds(i.median_until_s)}",
             WHITE if half else RED)]
        if not self.words:  # a GIF's small frame has room beside the pendulums for one short line
            lines = [lines[0] if first else (f"faithful to {seconds(i.faithful_until_s)}", AMBER)]
        sh = self.cell(self.small, self.ss)[1]
        return [self.text(s, self.w - self.m, self.m + k * sh, c, ha="right") for k, (s, c) in enumerate(lines)]

    def time_labels(self) -> list:
        """Under the timeline: 0, the end and each tick's time in its colour, left to right without overlap."""
        if not self.words:
            return []
        y, cw = self.gy1 + 4 * self.th, self.cell(self.lab, self.ls)[0]
        items = [("0", self.gx0, DIM)] + [(f"{t:.2f}", x, c) for (t, c), x in zip(self.until, self.ticks)]
        end = f"{self.duration:g} s"
        out, free = [], self.gx0
        for k, (s, x, c) in enumerate(items):
            left = max(x - (len(s) * cw) // 2 if k else x, free)
            out.append(self.text(s, left, y, c, self.lab, self.ls))
            free = left + (len(s) + 1) * cw
        right = max(self.gx1, free + len(end) * cw)  # the end's label, right-aligned under the end, or after the rest
        return out + [self.text(end, right, y, DIM, self.lab, self.ls, ha="right")]

    def caption(self, text: str, view, left: int, top: int) -> list:
        """The caption in the bottom right corner, right-aligned, wrapped around the pendulums' view (at most
        MAX_LINES lines, cut with an ellipsis if it still does not fit), right of `left` and below `top`."""
        cw, sh = self.cell(self.small, self.ss)
        best = []
        for n in range(1, MAX_LINES + 1):
            y0, y1 = self.h - self.m - n * sh, self.h - self.m - 1
            if y0 < top:
                break
            x0 = left
            if view is not None:
                dy = max(y0 - view.cy, view.cy - y1, 0.0)
                r = view.outer + framing.GAP + 1
                if dy < r:
                    x0 = max(x0, math.ceil(view.cx + math.sqrt(r * r - dy * dy)))
            chars = (self.w - self.m - x0) // cw
            lines = wrap(text, chars)
            if not lines:
                continue
            best = lines if len(lines) <= n else lines[:n - 1] + [fit(" ".join(lines[n - 1:]), chars)]
            if len(lines) <= n:
                break
        return [self.text(s, self.w - self.m, self.h - self.m - (len(best) - k) * sh, DIM, ha="right")
                for k, s in enumerate(best)]

    def clock_rows(self, s: str, colour):
        """The clock: top left, or in a panel (whose label covers its top) bottom right."""
        if self.info.panel:
            return self.text(s, self.w - self.m, self.h - self.m, colour, self.big, self.bs, ha="right", va="bottom")
        return self.text(s, self.m, self.m, colour, self.big, self.bs)

    def value_rows(self, spread: float):
        return self.text(f"{'spread' if self.words else 'Δ'} {metres(spread)}", *self.value_at, CURVE)

    def axis_labels(self) -> list:
        """Decades of the spread axis, in metres, right of the graph."""
        if not (self.fan and self.words):
            return []
        out = []
        for unit, size in UNITS:
            at = math.log10(size / self.reach)
            if LOG_LO <= at <= LOG_HI:
                out.append(self.text(f"1 {unit}", self.gx1 + 3, self.y_of(at), DIM, self.lab, self.ls, va="middle"))
        return out
