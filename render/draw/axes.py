"""What a map's frame shows around its plot, and where: a title row, axes with ticks and labels (θ in units of
π where the range is a simple multiple of π, else decimals with as many digits as the tick step needs, with
the unit), a colour bar with its unit and a legend. Plain Python: it lays out, render/maps/paint.py draws (the text
with the bundled font, the bars and swatches with the same colour functions as the plot).

Everything here is static for a render, so the map draws it once into a background that each frame copies;
only the clock (t = ... s, top right) is drawn per frame.
"""
from __future__ import annotations

import dataclasses
import math

from ..physics import grid

BACKGROUND = (12, 12, 16)  # bytes: a near-black, so the map's own black ("cannot flip") shows against it
INK = (0.86, 0.86, 0.86)  # text
FRAME = (90, 90, 100)  # the plot's border and tick marks, bytes
TITLE = {"angles": ("angles θ₁, θ₂ at time t", "angles"), "flip_time": ("flip time: first |θ₁| or |θ₂| > π", "flip time"),
         "divergence": ("divergence time: when a twin ε away parts", "divergence"),
         "lyapunov": ("FTLE σ = ln s_max(DΦ(t)) / t", "FTLE")}  # long, short


@dataclasses.dataclass
class Decor:
    texts: list = dataclasses.field(default_factory=list)  # (text, x, y, font.layout keywords)
    rects: list = dataclasses.field(default_factory=list)  # (x, y, w, h, rgb bytes): filled
    swatches: list = dataclasses.field(default_factory=list)  # (x, y, w, h, what): drawn by the map's colours
    clock: tuple = (0, 0)  # where the per-frame clock goes: right end of the title row


def pi_label(v: float) -> str:
    """v in units of π: "−π", "−π/2", "0", "π/2", "3π/4" (v a multiple of π/4)."""
    k = round(4 * v / math.pi)
    if k == 0:
        return "0"
    num, den = abs(k), 4
    for d in (2, 2):
        if num % d == 0 and den % d == 0:
            num, den = num // d, den // d
    s = ("" if num == 1 else str(num)) + "π" + ("" if den == 1 else f"/{den}")
    return ("−" if k < 0 else "") + s


def symbol(quantity: str) -> str:
    """theta2 -> θ₂, omega1 -> ω₁."""
    sub = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
    name, k = ("θ", quantity[5:]) if quantity.startswith("theta") else ("ω", quantity[5:])
    return name + k.translate(sub)


@dataclasses.dataclass(frozen=True)
class Tick:
    value: float
    at: int  # where its mark goes: pixels from the axis's low end (0 .. n − 1), the boundary nearest the value
    label: str | None  # None: a mark without a label (no room)


def axis_ticks(quantity: str, lo: float, hi: float, n: int, spacing) -> list[Tick]:
    """The ticks of an axis of n pixels over [lo, hi]. spacing(label) is the least distance in pixels from one
    labelled tick to the next that keeps their labels apart.

    In units of π (grid.pi_units): the ends and quarters, the odd quarters labelled where they fit. Otherwise
    multiples of a 1-2-5 step, the finest that keeps its labels apart (but at most about ten ticks, so the
    labels never need more digits than grid.label_chars made room for), each with the step's decimals; where
    no step's labels fit, the coarsest step with two ticks or more, every k-th labelled."""
    def at(v):
        return min(round(n * (v - lo) / (hi - lo)), n - 1)

    if quantity.startswith("theta") and grid.pi_units(lo, hi):
        out = []
        for k in range(5):
            v = lo + k * (hi - lo) / 4
            out.append(Tick(v, min(round(n * k / 4), n - 1),
                            pi_label(v) if k % 2 == 0 or n // 4 >= spacing(pi_label(v)) else None))
        return out
    span = hi - lo
    e = math.floor(math.log10(span / 10))
    fallback, single = None, []
    for step in (m * 10.0 ** k for k in range(e, e + 3) for m in (1, 2, 5)):
        if step < span / 10 * (1 - 1e-9):
            continue
        decimals = max(0, -math.floor(math.log10(step) + 1e-9))
        ks = range(math.ceil(lo / step - 1e-6), math.floor(hi / step + 1e-6) + 1)  # ends on a tick count
        ticks = [(k * step, decimal(k * step, decimals)) for k in ks]
        gap = n * step / span
        need = max(spacing(label) for _, label in ticks) if ticks else 0
        if len(ticks) >= 2 and gap >= need:
            return [Tick(v, at(v), label) for v, label in ticks]
        single = single or [Tick(v, at(v), label) for v, label in ticks]
        if len(ticks) >= 2:  # if none fits: the coarsest with two ticks or more, every k-th labelled
            every = math.ceil(need / gap - 1e-9)
            fallback = [Tick(v, at(v), label if i % every == 0 else None) for i, (v, label) in enumerate(ticks)]
    return fallback or single


def x_ticks(lay: grid.Layout, quantity: str, lo: float, hi: float) -> list[Tick]:
    """The x axis's ticks: labels side by side need 6 characters (π units: "−π/2" and a space) or their length
    and two."""
    cw, _ = lay.cell()
    ticks, end = axis_ticks(quantity, lo, hi, lay.w, lambda s: max(6, len(s) + 2) * cw), -math.inf
    for i, t in enumerate(ticks):  # a label shifted clear of the legend may meet the one before: it goes
        if t.label:
            x = x_label_at(lay, t)
            if x - len(t.label) * cw / 2 < end + cw:
                ticks[i] = dataclasses.replace(t, label=None)
            else:
                end = x + len(t.label) * cw / 2
    return ticks


def y_ticks(lay: grid.Layout, quantity: str, lo: float, hi: float) -> list[Tick]:
    """The y axis's ticks: labels one above the other need two rows."""
    _, ch = lay.cell()
    return axis_ticks(quantity, lo, hi, lay.h, lambda s: 2 * ch)


def x_label_at(lay: grid.Layout, t: Tick) -> int:
    """Where an x tick's label is centred: on its mark, but clear of the legend's column (long decimals at the
    right end shift left)."""
    cw, _ = lay.cell()
    return min(lay.x0 + t.at, lay.x0 + lay.w + 3 * lay.pad - len(t.label) * cw // 2)


def decimal(v: float, decimals: int) -> str:
    text = f"{v:.{decimals}f}"
    return ("0" if float(text) == 0 else text).replace("-", "−")


def axis_label(quantity: str, lo: float, hi: float) -> tuple[str, str | None]:
    """The axis's name and unit: ("θ₁", None) in units of π, else ("ω₁", "rad/s")."""
    if quantity.startswith("theta") and grid.pi_units(lo, hi):
        return symbol(quantity), None
    return symbol(quantity), grid.unit(quantity)


def time_ticks(lo: float, hi: float, room: int) -> list[float]:
    """Log-scale ticks between lo and hi: 1-2-5 per decade, thinned to 1-3 or decades when fewer fit."""
    for mantissas in ((1, 2, 5), (1, 3), (1,)):
        ticks = [m * 10.0 ** e for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1)
                 for m in mantissas if lo * (1 - 1e-9) <= m * 10.0 ** e <= hi * (1 + 1e-9)]
        if len(ticks) <= room:
            return ticks
    return [lo, hi]


def linear_ticks(lo: float, hi: float, room: int) -> list[float]:
    """Ticks at a 1-2-5 step from lo to hi, the finest of which no more than `room` fit."""
    for step in sorted(m * 10.0 ** e for e in range(-3, 4) for m in (1, 2, 5)):
        ticks = [k * step for k in range(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1)]
        if len(ticks) <= room:
            return [round(t, 12) for t in ticks]
    return [lo, hi]


def number(v: float) -> str:
    return f"{v:g}".replace("-", "−")


def power(v: float) -> str:
    """10 to an integer power, with a superscript exponent: 10⁻⁶."""
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return "10" + str(round(math.log10(v))).translate(sup)


def decorate(scene, lay: grid.Layout, times: tuple[float, float], run: str) -> Decor:
    """The decorations of a map in a frame laid out as `lay`; times is the colour scale's (lo, hi) in s and
    run says how it was integrated ("rk4 dt=1.85 ms f32")."""
    d = Decor()
    if lay.font is None:
        return d
    cw, ch = lay.cell()
    pad, x0, y0, w, h = lay.pad, lay.x0, lay.y0, lay.w, lay.h
    small = {"size": lay.font}
    d.clock = (lay.width - pad, pad)
    room = (lay.width - pad - len("t = 000.00 s") * cw - (x0 - 5 * cw)) // cw - 2  # characters left of the clock
    long, short = TITLE[scene.fractal]
    title = next((t for t in (f"{long}   {scene.system}, {run}", long, short) if len(t) <= room), short)
    d.texts.append((title, x0 - 5 * cw, pad, small))
    # the plot's border, just outside it
    d.rects += [(x0 - 1, y0 - 1, w + 2, 1, FRAME), (x0 - 1, y0 + h, w + 2, 1, FRAME),
                (x0 - 1, y0 - 1, 1, h + 2, FRAME), (x0 + w, y0 - 1, 1, h + 2, FRAME)]
    tick = max(1, lay.height // 360)
    (xq, *xr), (yq, *yr) = grid.axes_of(scene.map)
    for t in x_ticks(lay, xq, *xr):
        d.rects.append((x0 + t.at, y0 + h + 1, tick, pad, FRAME))
        if t.label:
            d.texts.append((t.label, x_label_at(lay, t), y0 + h + 2 * pad, {**small, "ha": "center"}))
    for t in y_ticks(lay, yq, *yr):
        y = y0 + h - 1 - t.at
        d.rects.append((x0 - 1 - pad, y, pad, tick, FRAME))
        if t.label:
            d.texts.append((t.label, x0 - 2 * pad, y, {**small, "ha": "right", "va": "middle"}))
    name, unit = axis_label(xq, *xr)
    d.texts.append((name + (f" [{unit}]" if unit else ""), x0 + w // 2, y0 + h + 3 * pad + ch,
                    {**small, "ha": "center"}))
    name, unit = axis_label(yq, *yr)
    right = x0 - 3 * pad - max(4, grid.label_chars(yq, *yr)) * cw  # left of the widest tick label
    if unit:  # the name over its unit
        d.texts.append((name, right, y0 + h // 2 - pad // 2, {**small, "ha": "right", "va": "bottom"}))
        d.texts.append((unit, right, y0 + h // 2 + pad // 2, {**small, "ha": "right", "va": "top"}))
    else:
        d.texts.append((name, right, y0 + h // 2, {**small, "ha": "right", "va": "middle"}))
    legend(d, scene, lay, times, x0 + w + 4 * pad)
    return d


def legend(d: Decor, scene, lay: grid.Layout, times: tuple[float, float], x: int):
    """The colour bar(s) and legend entries, in a column starting at x."""
    cw, ch = lay.cell()
    pad, y, bar_h = lay.pad, lay.y0, max(3 * ch, lay.h // 2)
    small = {"size": lay.font}
    if scene.fractal == "angles":
        for line in ("colour:", "red   sin θ₁", "green sin θ₂", "blue  cos(θ₁ + θ₂)"):
            d.texts.append((line, x, y, small))
            y += ch + pad // 2
        d.swatches.append((x, y + pad, ch * 4, ch, "angles"))
        y += 2 * ch + pad
    else:
        room = (lay.width - x - pad) // cw  # characters that fit in the legend's column
        unit = {"flip_time": "flip time [s]", "lyapunov": "σ [1/s]"}.get(scene.fractal, "time to part [s]")
        if scene.fractal == "divergence":  # two bars side by side: labels as long as they fit
            unit, apart = ("time to part [s]", "together: distance") if room >= 36 else ("t [s]", "|Δ|")
        d.texts.append((unit, x, y, small))
        y += ch + pad
        bar(d, x, y, ch, bar_h, times, lay, "time", linear=scene.fractal == "lyapunov")
        if scene.fractal == "divergence":  # pairs still together: their distance, ε to the threshold
            bx = x + max(ch + 8 * cw, (len(unit) + 2) * cw)
            d.texts.append((apart, bx, y - ch - pad, small))
            m = scene.map
            d.swatches.append((bx, y, ch, bar_h, "distance"))
            for v, at in ((m.epsilon, 0.0), (m.threshold, 1.0)):
                label = power(v) if abs(math.log10(v) - round(math.log10(v))) < 1e-9 else number(v)
                d.texts.append((label, bx + ch + pad, y + bar_h - 1 - round(at * (bar_h - 1)),
                                {**small, "va": "middle"}))
        y += bar_h + 2 * pad
    entries = [("untrusted: after faithful time", "untrusted", "untrusted")]
    if scene.fractal == "flip_time":
        entries = [("cannot flip (energy)", "never", "cannot flip"), ("not flipped yet", "pending", "not yet")] + entries
    if scene.fractal == "lyapunov":
        entries = [("energy barrier: no flip inside", "never", "barrier")] + entries
    room = (lay.width - x - ch - pad) // cw
    for text, what, short in entries:
        text = text if len(text) <= room else short
        d.rects.append((x - 1, y - 1, ch + 2, ch + 2, FRAME))  # a border: "never" is black on near-black
        d.swatches.append((x, y, ch, ch, what))
        d.texts.append((text, x + ch + pad, y + ch // 2, {**small, "va": "middle"}))
        y += ch + pad


def bar(d: Decor, x: int, y: int, w: int, h: int, times: tuple[float, float], lay: grid.Layout, what: str,
        linear: bool = False):
    """A vertical colour bar, low at the bottom, log-scaled (times) or linear, with tick labels on its right."""
    lo, hi = times
    _, ch = lay.cell()
    d.swatches.append((x, y, w, h, what))
    room = max(2, h // (ch + 2))
    for t in (linear_ticks(lo, hi, room) if linear else time_ticks(lo, hi, room)):
        at = (t - lo) / (hi - lo) if linear else (math.log(t) - math.log(lo)) / (math.log(hi) - math.log(lo))
        ty = y + h - 1 - round(at * (h - 1))
        d.rects.append((x + w, ty, lay.pad, 1, FRAME))
        d.texts.append((number(t), x + w + lay.pad + 2, ty, {"size": lay.font, "va": "middle"}))
