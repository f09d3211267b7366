"""A map's geometry: where its plot sits in the frame, the start each pixel of the plot gets, and the lattice
of pixels its trust mask is certified on. Plain numpy, no Taichi: the scene loader (which derives the
pendulum count of a grid from it), the systems (which start from it) and the map (which draws it) share it.

- **The plot** is a square of one pendulum per pixel, with room left around it for the axes, a colour bar
  and a legend (render/draw/axes.py). A frame too small for them (under MIN_DECORATED pixels high) is all plot.
- **Axes**: [map] x and y name the quantities along the plot (θ_k or ω_k of any link, default θ1 across and
  θ2 up) and x_range, y_range their spans (default [−π, π]); every other coordinate starts as [pendulums]
  states it. A zoom is a smaller range.
- **Starts**: pixel (row r, column c) of a w × h plot starts at the pixel's centre, x = lo + (c + ½)·(hi − lo)/w
  and y = hi − (r + ½)·(hi − lo)/h (row 0 at the top), so the default map is symmetric and no pixel sits
  exactly on ±π.
- **Precision**: a window so narrow that f32 cannot tell neighbouring pixels' starts well apart (a step under
  F32_STEPS f32 ulps of the largest value on the axis) runs in f64: see f64_reason().
  A divergence map integrates a twin beside each pixel: pendulums 2p and 2p + 1, the twin ε further on the
  last link (as a fan spreads it), so a pair shares a lane group and a cache line. With map.samples = 4 or 9,
  each pixel is a 2 × 2 or 3 × 3 block of sub-pixel starts instead (sample_starts()), one pendulum each (and
  a twin each), pixel by pixel.
- **The trust lattice**: every trust_stride-th pixel in both directions, offset by half a stride. The
  certificate (render/trust/certify.py) runs on exactly these pixels (every sample, both pendulums of a pair),
  and each pixel's faithful time is the least of its (up to) four surrounding lattice samples: see faithful_map().
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np


MIN_DECORATED = 120  # frame height below which the map fills the frame, without axes or legend
RANGE = (-math.pi, math.pi)
AXES = ("theta1", "theta2")  # the default quantities across and up
# Quantities a map could put on an axis but the systems cannot vary per pixel: their kernels compile masses and
# lengths in as constants of the scene (System.__init__ reads them once, accel uses self.m1 ...).
RATIOS = {"mass_ratio": "m2/m1", "length_ratio": "l2/l1"}
# Below this many f32 ulps per pixel, f32 starts would be a visibly uneven lattice and its round-off (1 ulp
# per operation, grown by chaos) would be a sizeable part of a pixel step from the first step on.
F32_STEPS = 1e3
F32_EPS = 2.0 ** -23


@dataclasses.dataclass(frozen=True)
class Layout:
    width: int  # the frame
    height: int
    x0: int  # the plot's top-left pixel and size
    y0: int
    w: int
    h: int
    font: str | None  # the font size the decorations use; None: no decorations
    pad: int = 0  # spacing unit of the decorations, in pixels

    @property
    def pixels(self) -> int:
        return self.w * self.h

    def cell(self) -> tuple[int, int]:
        """(width, height) of one character of the decorations' font."""
        return cell(self.font)


def cell(font: str) -> tuple[int, int]:
    """A font's character cell: its name says it ("10x20" is 10 px wide, 20 high; render/draw/font_data.py holds
    the glyphs). Read from the name so that the plot's geometry, which the physics needs for a grid's starts, does
    not depend on the drawing layer."""
    w, h = font.split("x")
    return int(w), int(h)


def quantities(links: int) -> tuple[str, ...]:
    """What an axis of a map of a chain of `links` links can show: each link's angle, then each rate."""
    return tuple(f"theta{k}" for k in range(1, links + 1)) + tuple(f"omega{k}" for k in range(1, links + 1))


def unit(quantity: str) -> str:
    return "rad" if quantity.startswith("theta") else "rad/s"


def axes_of(spec) -> tuple[tuple[str, float, float], tuple[str, float, float]]:
    """((x quantity, lo, hi), (y quantity, lo, hi)) of a scene's [map], the defaults without one."""
    if spec is None:
        return (AXES[0], *RANGE), (AXES[1], *RANGE)
    return (spec.x, *spec.x_range), (spec.y, *spec.y_range)


def pi_units(lo: float, hi: float) -> bool:
    """Whether an angle axis over [lo, hi] is labelled in units of π: both ends on multiples of π/4 and the span
    a multiple of π, so that its five ticks (ends, quarters) all fall on multiples of π/4."""
    def multiple(v, of):
        return abs(v / of - round(v / of)) < 1e-9
    return multiple(lo, math.pi / 4) and multiple(hi, math.pi / 4) and multiple(hi - lo, math.pi) and hi > lo


def label_chars(quantity: str, lo: float, hi: float) -> int:
    """The widest tick label (characters) an axis can need: "−π/2"-like in units of π, else a signed decimal
    with the digits a tick step of about a tenth of the span needs (render/draw/axes.py formats them)."""
    if quantity.startswith("theta") and pi_units(lo, hi):
        return 4
    decimals = max(0, -math.floor(math.log10((hi - lo) / 10)))
    whole = len(str(int(max(abs(lo), abs(hi)))))
    return 1 + whole + (1 + decimals if decimals else 0)


def layout(width: int, height: int, spec=None) -> Layout:
    """The plot in a width × height frame: a square under a title row, above two rows of x ticks and label,
    right of the y label and ticks; the rest of the row holds the colour bar and the legend. `spec` (a scene's
    [map]) sizes the room for the y axis's labels: the default axes' are "θ₂" and up to "−π/2"; a decimal
    axis's labels are as long as its digits, and its name ("ω₂") sits over its unit ("rad/s")."""
    if height < MIN_DECORATED:
        return Layout(width, height, 0, 0, width, height, None)
    font = "10x20" if height >= 480 else "6x13"
    cw, ch = cell(font)
    pad = max(3, ch // 3)
    top = ch + 2 * pad
    bottom = 3 * pad + 2 * ch + 2 * pad  # tick marks, tick labels, the axis label
    y = axes_of(spec)[1]
    name = 2 if y[0].startswith("theta") and pi_units(*y[1:]) else len(unit(y[0]))
    left = pad + name * cw + pad + max(4, label_chars(*y)) * cw + 2 * pad  # axis name, tick labels, tick marks
    side = min(height - top - bottom, width - left - 20 * cw)  # keep room for the colour bar and legend
    if side < 32:
        return Layout(width, height, 0, 0, width, height, None)
    right = max(20 * cw, (width - left - side) // 2)  # centre plot and legend as one block
    x0 = max(left, (width - (left + side + right)) // 2 + left)
    return Layout(width, height, x0, top, side, side, font, pad)


def pendulums(width: int, height: int, fractal: str | None, spec=None) -> int:
    """A grid's pendulum count: map.samples per pixel of the plot (one without a [map]), two for each in a
    divergence map (sample and twin)."""
    samples = 1 if spec is None else spec.samples
    return layout(width, height, spec).pixels * samples * (2 if fractal == "divergence" else 1)


def plot(scene) -> Layout:
    """A map scene's layout."""
    return layout(scene.video.width, scene.video.height, scene.map)


def f64_reason(width: int, height: int, spec) -> str | None:
    """Why this map's plot must run in f64 whatever integrator.precision says, or None: an axis whose pixel step
    is under F32_STEPS ulps of f32 at the axis's largest |value|."""
    lay = layout(width, height, spec)
    for (q, lo, hi), n in zip(axes_of(spec), (lay.w, lay.h)):
        step, big = (hi - lo) / n, max(abs(lo), abs(hi))
        if step < F32_STEPS * F32_EPS * big:
            return (f"{q}'s pixel step ({step:.3g} {unit(q)}) is under {F32_STEPS:g} f32 ulps at |{q}| = {big:.4g}: "
                    f"the map runs in f64")
    return None


def axis_values(n: int, lo: float, hi: float) -> np.ndarray:
    """The centres of n pixels spanning [lo, hi]."""
    return lo + (np.arange(n, dtype=np.float64) + 0.5) * ((hi - lo) / n)


def axes_summary(scene) -> dict:
    """For a map's metadata: each axis's quantity, unit and range, and why it ran in f64 if a zoom made it."""
    v = scene.video
    out = {axis: {"quantity": q, "unit": unit(q), "range": [lo, hi]}
           for axis, (q, lo, hi) in zip(("x", "y"), axes_of(scene.map))}
    why = f64_reason(v.width, v.height, scene.map)
    if why:
        out["f64"] = why
    return out


def starts(scene) -> np.ndarray:
    """Per pixel of the plot, row-major from the top left, the (x, y) values it starts at: (pixels, 2)."""
    lay = plot(scene)
    (_, xlo, xhi), (_, ylo, yhi) = axes_of(scene.map)
    x = axis_values(lay.w, xlo, xhi)
    y = axis_values(lay.h, ylo, yhi)[::-1]  # row 0 at the top: the largest value
    return np.stack([np.tile(x, lay.h), np.repeat(y, lay.w)], axis=1)


def sample_starts(scene) -> np.ndarray:
    """Per sample of every pixel, the (x, y) values it starts at: (pixels · samples, 2), pixel by pixel as
    starts() orders them, and within a pixel its map.samples = k² samples row by row from the top left, at the
    centres of a regular k × k split of the pixel. k = 1 is the pixel's centre. The pixel's extent is the
    spacing of starts()' centres, so the samples follow whatever the axes span."""
    xy = starts(scene)
    k = math.isqrt(scene.map.samples)
    if k == 1:
        return xy
    lay = plot(scene)
    centre = xy.reshape(lay.h, lay.w, 2)
    dx, dy = centre[0, 1, 0] - centre[0, 0, 0], centre[1, 0, 1] - centre[0, 0, 1]  # a column, a row on
    f = (np.arange(k) + 0.5) / k - 0.5
    off = np.stack([np.tile(f * dx, k), np.repeat(f * dy, k)], axis=1)  # (k², 2): sample (b, a) is b * k + a
    return (xy[:, None, :] + off[None]).reshape(-1, 2)


def grid_state(scene, th: np.ndarray, w: np.ndarray):
    """The grid layout's initial angles and rates (each (count, links)): the plot's (sub-pixel) starts on its two
    axes' quantities, every other coordinate as the preset states it; with twins, each sample's twin ε on."""
    xy = sample_starts(scene)
    twins = scene.fractal == "divergence"
    for (q, *_), col in zip(axes_of(scene.map), xy.T):
        target = th if q.startswith("theta") else w
        target[:, int(q[5:]) - 1] = np.repeat(col, 2) if twins else col
    if twins:
        th[1::2, -1] += scene.map.epsilon
    return th, w


# ---------------------------------------------------------------- the trust lattice

def lattice_axis(n: int, stride: int) -> np.ndarray:
    """Pixel positions of the lattice along one axis of n pixels: half a stride in, then every stride."""
    stride = max(1, min(stride, n))
    return np.arange(stride // 2, n, stride)


def trust_indices(scene) -> np.ndarray:
    """The pendulums the certificate runs on for a map: every sample of the lattice's pixels (with their twins)."""
    lay, n = plot(scene), scene.map.samples
    rows = lattice_axis(lay.h, scene.map.trust_stride)
    cols = lattice_axis(lay.w, scene.map.trust_stride)
    pix = (rows[:, None] * lay.w + cols[None, :]).ravel()
    pix = (pix[:, None] * n + np.arange(n)).ravel()
    if scene.fractal == "divergence":
        pix = np.stack([2 * pix, 2 * pix + 1], axis=1).ravel()
    return pix.astype(np.int64)


def faithful_map(scene, until_s: np.ndarray) -> np.ndarray:
    """Per pixel of the plot (h, w), the time until which its integration is estimated faithful, from the
    certificate's per-pendulum times on the lattice (in trust_indices() order).

    A lattice pixel's time is the least of its samples' (and their twins'). A pixel takes the least of the (up
    to) four lattice samples around it (the nearest ones at the edges), a pair the lesser of pixel and twin. The
    least, not an interpolation: in the chaotic region neighbours
    part within seconds, so a sample speaks for its surroundings only statistically, and a mask must err
    towards distrust. tests/test_fractal.py measures how often it errs the other way against a shadow at
    every pixel."""
    lay = plot(scene)
    rows = lattice_axis(lay.h, scene.map.trust_stride)
    cols = lattice_axis(lay.w, scene.map.trust_stride)
    until = np.asarray(until_s, dtype=np.float64)
    if scene.fractal == "divergence":
        until = np.minimum(until[0::2], until[1::2])
    at = until.reshape(len(rows), len(cols), scene.map.samples).min(-1)
    r0, r1 = _neighbours(lay.h, rows)
    c0, c1 = _neighbours(lay.w, cols)
    out = np.minimum(at[r0][:, c0], at[r0][:, c1])
    return np.minimum(out, np.minimum(at[r1][:, c0], at[r1][:, c1]))


def _neighbours(n: int, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of n pixels, the lattice positions (indices into `at`) just before and after it."""
    after = np.searchsorted(at, np.arange(n), side="left")  # first sample at or beyond the pixel
    hi = np.minimum(after, len(at) - 1)
    lo = np.where(at[hi] == np.arange(n), hi, np.maximum(after - 1, 0))
    return lo, hi
