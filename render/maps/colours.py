"""The maps' colours: the palette their times and σ are drawn in, the grey of a pending pixel, the mask over an
untrusted one, and the angles map's cheap sine. sRGB values, as a screen shows them (render/maps/supersample.py
averages them in linear light).
"""
import math

import taichi as ti

# matplotlib's plasma at 9 points, read backwards on the map (early events bright): saturated everywhere,
# so a desaturated (untrusted) pixel stands apart, and its dark end is blue, not the black of "never"
PALETTE = ((0.05, 0.03, 0.528), (0.3, 0.01, 0.632), (0.495, 0.012, 0.658), (0.665, 0.139, 0.586),
           (0.798, 0.28, 0.47), (0.902, 0.425, 0.36), (0.973, 0.586, 0.252), (0.993, 0.772, 0.155),
           (0.94, 0.975, 0.131))
STOPS = len(PALETTE)
PENDING_GREY = 0.24  # a flip map's pixels that may still flip
HATCH = 5  # pixels between the diagonal lines over untrusted pixels


@ti.func
def palette(u):
    """u in [0, 1] to PALETTE, piecewise linear."""
    x = ti.min(ti.max(u, 0.0), 1.0) * (STOPS - 1)
    k = ti.min(ti.cast(ti.floor(x), ti.i32), STOPS - 2)
    f = x - k
    c = ti.Vector([0.0, 0.0, 0.0])
    for j in ti.static(range(STOPS - 1)):
        if k == j:
            c = (1.0 - f) * ti.Vector(PALETTE[j]) + f * ti.Vector(PALETTE[j + 1])
    return c


@ti.func
def sin8(x):
    """sin(x) to within 1e-4, plenty for a colour byte and about 3x cheaper than libm's call. Reduced to
    [-pi/2, pi/2], then the Taylor series to x^9 (error < 4e-6 there)."""
    x = x - 2.0 * math.pi * ti.round(x * (0.5 / math.pi))
    if x > 0.5 * math.pi:
        x = math.pi - x
    elif x < -0.5 * math.pi:
        x = -math.pi - x
    x2 = x * x
    return x * (1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880)))))


@ti.func
def untrusted(c, x, y):
    """The mask: most of the colour drained, and a diagonal hatch that shows on dark pixels too."""
    lum = 0.3 * c[0] + 0.59 * c[1] + 0.11 * c[2]
    c = 0.75 * (lum + 0.3 * (c - lum))
    if (x + y) % HATCH == 0:
        c = ti.Vector([0.1, 0.1, 0.1]) if lum > 0.45 else ti.Vector([0.5, 0.5, 0.5])
    return c
