"""Supersampling (`map.samples` = 4 or 9): a pixel's colour is the mean of its sub-pixel samples' colours,
taken in linear light.

The map's colours (the palette, the greys, the mask) are sRGB values, as a screen shows them. Averaging those
directly would darken every edge between a bright and a dark sample: half of a yellow sample and half of a
black one is not sRGB 0.5 but the sRGB value of half its light, about 0.73. So each sample's colour is decoded
to linear light (the sRGB transfer curve, IEC 61966-2-1), the samples are averaged, and the mean is encoded
again. Each sample is coloured whole first, its own event and its own trust mask included: a pixel half of
whose samples are untrusted shows half the mask's light. Per-pixel arithmetic only: no sums across threads,
so the frames are the same bytes at any thread count.

The samples' starts are render/physics/grid.py's sample_starts(); where a colour has no meaning for the mean
of its samples (a curve a pixel wide), the map draws it on the samples' own finer grid: fine_grid() and
coarse() move per-sample values between the map's order and that grid.
"""
import numpy as np
import taichi as ti


@ti.func
def linear(c):
    """An sRGB colour (each channel in [0, 1]) in linear light."""
    out = ti.Vector([0.0, 0.0, 0.0])
    for k in ti.static(range(3)):
        x = ti.min(ti.max(c[k], 0.0), 1.0)
        out[k] = x / 12.92 if x <= 0.04045 else ti.pow((x + 0.055) / 1.055, 2.4)
    return out


@ti.func
def encode(c):
    """A colour in linear light back to sRGB."""
    out = ti.Vector([0.0, 0.0, 0.0])
    for k in ti.static(range(3)):
        x = ti.min(ti.max(c[k], 0.0), 1.0)
        out[k] = 12.92 * x if x <= 0.0031308 else 1.055 * ti.pow(x, 1.0 / 2.4) - 0.055
    return out


def fine_grid(values: np.ndarray, h: int, w: int, samples: int) -> np.ndarray:
    """Per-sample values in the map's order (pixel by pixel, each pixel's samples row by row) as the
    (h·k) × (w·k) image of the samples' positions, k² = samples."""
    k = int(round(samples ** 0.5))
    return values.reshape(h, w, k, k).transpose(0, 2, 1, 3).reshape(h * k, w * k)


def coarse(image: np.ndarray, h: int, w: int, samples: int) -> np.ndarray:
    """fine_grid()'s inverse: the image back in the map's order, flat."""
    k = int(round(samples ** 0.5))
    return image.reshape(h, k, w, k).transpose(0, 2, 1, 3).ravel()
