"""The GIF's colours: one palette for the whole GIF, chosen by ffmpeg's palettegen from a sample of its frames.

A GIF holds at most 256 colours; ours get GIF_COLOURS, one palette for the whole file. Which ones is
palettegen's choice (a median cut), made from every palette_step()-th GIF frame (PALETTE_FPS a second) with
its colours cut to PALETTE_BITS per channel; it sees them as the render hands them over and gives the palette
after the last one. Every frame is then dithered and mapped to the palette by render/video/dither.py, in
this process, and ffmpeg only writes the GIF (pal8 frames, its palette with each).

Why so, on rigid_chaos (20 s, its 400 GIF frames of 352x198; 2-core Xeon with AVX-512, 2026-12-06):
- Counting each changed pixel's colour (a hash whose buckets are searched one entry at a time) was palettegen's
  cost: the first 100 frames, a coherent fan of few colours, took it 0.09 s, the last 100, in chaos, 1.1 s; all
  400 4.9 s of CPU in ffmpeg's graph that also mapped them, 2.9 s with every 4th counted, 2.6 s every 8th.
- Its colours cut to 7 bits: palettegen's median cut sorts every distinct colour after the last frame on one
  thread (1.83 M of them uncut, 773 k at 7 bits, 194 k at 6; `python benchmarks/gif_palette.py`), for 0.04 dB
  (0.10 in the clock's corner) against the raw frames, 6 bits 0.18 dB (0.96).
- ffmpeg's paletteuse mapped every frame after the last one, when the palette is known, on one thread: 2.7 s
  the render waited for. Mapped here instead (render/video/dither.py), the GIF decodes back closer to the
  frames drawn: 27.83 dB over the frame and 35.07 dB in the clock's corner, against paletteuse's 26.96 and
  34.08 dB with the same palette, 4.63 MB against 4.61 MB.
- 48 colours: the trails fade every frame, so nearly every lit pixel changes in every frame and what makes the
  file big is pixels x frames x palette size, not dithering: 352 px x 20 fps x 48 colours made 4.69 MB (64
  colours 5.11 MB; 480 px x 25 fps x 256 colours 14.7 MB); 48 cost the clock's corner 0.2 dB.

A rainbow (video.palette = "rainbow") is the exception: one small palette for the whole GIF keeps few of the
hue circle's greens and purples, so each frame gets 256 colours of its own, chosen and mapped by ffmpeg as the
frames come (palettegen stats_mode=single, paletteuse new=1; rainbow_args). On rainbow_1000 (20 s) the hue
distance of its GIF to its MP4 (tests/test_gif.py's measure) is 0.72 with 48 colours for the whole GIF, 0.28
with 256 for the whole GIF (9.3 MB) or 96 per frame (8.5 MB), 0.14 with 256 per frame; but that GIF is 11.1 MB.
"""
from __future__ import annotations

import numpy as np

from . import gif
from ..errors import EncodeError

GIF_COLOURS, RAINBOW_COLOURS = 48, 256
PALETTE_BITS = 7
PALETTE_FPS = 5
BAYER_SCALE = 3  # the ordered dither's amplitude: steps of 2**BAYER_SCALE, -4..3 (as paletteuse's bayer_scale=3)


def palette_cut(bits: int | None = None) -> tuple[int, int]:
    """(mask, centre): a channel value v counts for the GIF's palette as (v & mask) | centre, cut to `bits`
    (default PALETTE_BITS)."""
    drop = 8 - (PALETTE_BITS if bits is None else bits)
    return (0xFF << drop) & 0xFF, (1 << drop) >> 1


def palette_step(video) -> int:
    """Every how many GIF frames palettegen counts one (PALETTE_FPS)."""
    return max(1, round(gif.rate(video) / PALETTE_FPS))


def stats_args() -> list[str]:
    """ffmpeg's output arguments for the palette: the sampled frames it is fed, cut, to palettegen, and its
    256 entries as RGBA on stdout after the last one (read())."""
    cut = ""
    if PALETTE_BITS < 8:
        keep, centre = palette_cut()
        cut = "lutrgb=" + ":".join(f"{c}='bitor(bitand(val\\,{keep})\\,{centre})'" for c in "rgb") + ","
    return ["-vf", f"{cut}palettegen=stats_mode=diff:max_colors={GIF_COLOURS}", "-f", "rawvideo",
            "-pix_fmt", "rgba", "-"]


def rainbow_args() -> list[str]:
    """ffmpeg's output arguments for a rainbow's GIF: each frame's own palette, as frames come."""
    graph = (f"split[a][b];[a]palettegen=stats_mode=single:max_colors={RAINBOW_COLOURS}[p];"
             f"[b][p]paletteuse=new=1:dither=bayer:bayer_scale={BAYER_SCALE}")
    return ["-vf", graph, "-loop", "0", "-f", "gif"]


def read(rgba: bytes) -> np.ndarray:
    """The opaque colours of palettegen's 256 RGBA entries, (K, 3) int32 in its order, each once (it pads
    the palette by repeating its last colour, and reserves a transparent entry)."""
    entries = np.frombuffer(rgba, np.uint8).reshape(-1, 4)
    if len(entries) != 256:
        raise EncodeError(f"ffmpeg's palettegen gave {len(rgba)} bytes, not a palette of 256 RGBA entries")
    opaque = entries[entries[:, 3] == 255, :3]
    _, first = np.unique(opaque, axis=0, return_index=True)
    return np.ascontiguousarray(opaque[np.sort(first)], np.int32)


def pal8(colours: np.ndarray) -> bytes:
    """The palette ffmpeg's rawvideo pal8 frames carry after their indices: 256 entries of 0xAARRGGBB in
    native (little-endian) order, the unused ones transparent black."""
    entries = np.zeros(256, np.uint32)
    c = colours.astype(np.uint32)
    entries[:len(c)] = 0xFF000000 | c[:, 0] << 16 | c[:, 1] << 8 | c[:, 2]
    return entries.astype("<u4").tobytes()


def dither() -> np.ndarray:
    """The 8x8 ordered (Bayer) dither added to each channel, flat by (y % 8) * 8 + x % 8: the recursive Bayer
    matrix's thresholds 0..63, scaled to steps of 2**BAYER_SCALE around 0."""
    m = np.zeros((1, 1), np.int32)
    while len(m) < 8:
        m = np.block([[4 * m, 4 * m + 2], [4 * m + 3, 4 * m + 1]])
    return ((m >> BAYER_SCALE) - (1 << (5 - BAYER_SCALE))).astype(np.int32).reshape(-1)
