"""A map's geometry: where its plot sits in the frame, the start each pixel of the plot gets, and the lattice
of pixels its trust mask is certified on. Plain numpy, no Taichi: the scene loader (which derives the
pendulum count of a grid from it), the systems (which start from it) and the map (which draws it) share it.

- **The plot** is a square of one pendulum per pixel, with room left around it for the axes, a colour bar
  and a legend (render/draw/axes.py). A frame too small for them (under MIN_DECORATED pixels high) is all plot.
- **Starts**: pixel (row r, column c) of a w × h plot starts at the pixel's centre, θ1 = −π + (c + ½)·2π/w
  and θ2 = π − (r + ½)·2π/h (row 0 at the top), so the map is symmetric and no pixel sits exactly on ±π.
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


def layout(width: int, height: int) -> Layout:
    """The plot in a width × height frame: a square under a title row, above two rows of x ticks and label,
    right of the y label and ticks; the rest of the row holds the colour bar and the legend."""
    if height < MIN_DECORATED:
        return Layout(width, height, 0, 0, width, height, None)
    font = "10x20" if height >= 480 else "6x13"
    cw, ch = cell(font)
    pad = max(3, ch // 3)
    top = ch + 2 * pad
    bottom = 3 * pad + 2 * ch + 2 * pad  # tick marks, tick labels, the axis label
    left = pad + 2 * cw + pad + 4 * cw + 2 * pad  # "θ₂", tick labels up to "−π/2", tick marks
    side = min(height - top - bottom, width - left - 20 * cw)  # keep room for the colour bar and legend
    if side < 32:
        return Layout(width, height, 0, 0, width, height, None)
    right = max(20 * cw, (width - left - side) // 2)  # centre plot and legend as one block
    x0 = max(left, (width - (left + side + right)) // 2 + left)
    return Layout(width, height, x0, top, side, side, font, pad)


def pendulums(width: int, height: int, fractal: str | None, samples: int = 1) -> int:
    """A grid's pendulum count: `samples` per pixel of the plot, two for each in a divergence map (sample and
    twin)."""
    return layout(width, height).pixels * samples * (2 if fractal == "divergence" else 1)


def axis_values(n: int, lo: float, hi: float) -> np.ndarray:
    """The centres of n pixels spanning [lo, hi]."""
    return lo + (np.arange(n, dtype=np.float64) + 0.5) * ((hi - lo) / n)


def starts(scene) -> np.ndarray:
    """Per pixel of the plot, row-major from the top left, the (x, y) values it starts at: (pixels, 2)."""
    lay = layout(scene.video.width, scene.video.height)
    x = axis_values(lay.w, *RANGE)
    y = axis_values(lay.h, *RANGE)[::-1]  # row 0 at the top: the largest value
    return np.stack([np.tile(x, lay.h), np.repeat(y, lay.w)], axis=1)


def quantities(scene) -> tuple[str, str]:
    """The names of the quantities on the plot's x and y axes."""
    return "theta1", "theta2"


def sample_starts(scene) -> np.ndarray:
    """Per sample of every pixel, the (x, y) values it starts at: (pixels · samples, 2), pixel by pixel as
    starts() orders them, and within a pixel its map.samples = k² samples row by row from the top left, at the
    centres of a regular k × k split of the pixel. k = 1 is the pixel's centre. The pixel's extent is the
    spacing of starts()' centres, so the samples follow whatever the axes span."""
    xy = starts(scene)
    k = math.isqrt(scene.map.samples)
    if k == 1:
        return xy
    lay = layout(scene.video.width, scene.video.height)
    centre = xy.reshape(lay.h, lay.w, 2)
    dx, dy = centre[0, 1, 0] - centre[0, 0, 0], centre[1, 0, 1] - centre[0, 0, 1]  # a column, a row on
    f = (np.arange(k) + 0.5) / k - 0.5
    off = np.stack([np.tile(f * dx, k), np.repeat(f * dy, k)], axis=1)  # (k², 2): sample (b, a) is b * k + a
    return (xy[:, None, :] + off[None]).reshape(-1, 2)


def grid_state(scene, th: np.ndarray, w: np.ndarray):
    """The grid layout's initial angles and rates (each (count, links)): the plot's (sub-pixel) starts on θ1
    and θ2, the other links and all rates as the preset states them; with twins, each sample's twin ε on."""
    xy = sample_starts(scene)
    twins = scene.fractal == "divergence"
    th[:, 0] = np.repeat(xy[:, 0], 2) if twins else xy[:, 0]
    th[:, 1] = np.repeat(xy[:, 1], 2) if twins else xy[:, 1]
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
    lay, n = layout(scene.video.width, scene.video.height), scene.map.samples
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

    A lattice pixel's time is the least of its samples' (and their twins'). A pixel takes the least of the (up to) four lattice samples around it (the nearest ones at the edges),
    a pair the lesser of pixel and twin. The least, not an interpolation: in the chaotic region neighbours
    part within seconds, so a sample speaks for its surroundings only statistically, and a mask must err
    towards distrust. tests/test_fractal.py measures how often it errs the other way against a shadow at
    every pixel."""
    lay = layout(scene.video.width, scene.video.height)
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
