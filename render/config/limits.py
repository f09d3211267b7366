"""The values a preset may hold: the choices each key offers and the limits its numbers must lie within.

Each limit says why it is where it is: a number is accepted only where f64 (and f32 for drafts) arithmetic on
it is still meaningful (systems declare their own keys' ranges in render/physics/keys.py). Kept apart from the
checks that apply them (render/config/validate.py) because the loader's schema (scene.py), the option parser
(options.py), the gallery and the commands read them without checking a scene.
"""
from __future__ import annotations

from ..physics import grid, registry

SYSTEMS = registry.names()
METHODS = {name: registry.get(name).METHODS for name in SYSTEMS}
PRECISIONS = ("f32", "f64")
TRIGS = ("inline", "libm")  # integrator.trig: render/physics/sincos.py, or the C library's (bit for bit as the seed)
FORMATS = ("mp4", "gif", "png")  # png: the last frame as a still
LAYOUTS = ("fan", "grid", "shell")  # shell: on one energy shell, on the Poincaré section (render/physics/poincare.py)
FRACTALS = ("angles", "flip_time", "divergence", "lyapunov")  # how a map (effects = ["fractal"]) colours its pixels
MAP_DEFAULTS = {  # [map]: fractal maps only
    "epsilon": 1e-6,  # rad: how far a divergence map's twin starts from its pixel, on the last link
    "threshold": 0.1,  # a pair has diverged when its distance in (θ, ω) passes this
    "trust_stride": 16,  # pixels between the lattice points the trust mask is certified on
    "samples": 1,  # sub-pixel starts per pixel (render/physics/grid.py's sample_starts)
}
SAMPLES = (1, 4, 9)  # map.samples: a pixel's centre, or a regular 2 x 2 or 3 x 3 split of it
MAP_AXES = {"x": grid.AXES[0], "y": grid.AXES[1], "x_range": list(grid.RANGE), "y_range": list(grid.RANGE)}
AXIS_MAX = 1e4  # rad or rad/s: beyond it an angle has wrapped thousands of times and a rate needs µs steps
# What a scene can call for. Drawn effects need a canvas; the rest change the simulation or bookkeeping.
# New effects go at the end: the canonical order (the scene's hash) of existing scenes stays as it was.
EFFECTS = ("rods", "springs", "bobs", "trails", "damping", "energy", "fractal", "hud", "glow", "poincare", "lyapunov",
           "audio")  # audio: a stereo track in the MP4 (render/video/audio.py)
PALETTES = ("fan", "rainbow")  # video.palette: how pendulum i is coloured (render/draw/raster.py)
LINK_EFFECTS = {"rods": "rod", "springs": "spring"}  # effect -> the kind of link (System.LINKS) it draws
MAX_PENDULUMS = 4_000_000  # ~0.5 GB of f64 state and work fields; beyond that a 24 GB machine struggles
# A map's pendulums hold no trails and no HUD: a 3840x2160 flip map (a 2058² plot) is 4.2 M, 16.9 M at 4 samples a
# pixel (which MAX_PENDULUMS refuses: a supersampled map is held to it), about 0.6 GB of f32 state and event fields (and a tiled render splits them over its workers)
MAX_MAP_PENDULUMS = 20_000_000
MAX_PIXELS = 3840 * 2160
# The name becomes a folder and the files NAME.mp4 and .NAME.mp4.<owner>.<random>.part beside it; 100
# characters keep every one of them far below the 255-byte limit of common file systems.
NAME_MAX = 100
NAME_PATTERN = r"[A-Za-z0-9_][A-Za-z0-9_.\-]*"  # letters, digits, _ . -, not starting with . or -
# What OUT itself holds (the gallery, the batch's record, comparisons' and the bench's folders): a scene of
# that name would put its folder where they go, and the next batch or bench would fail after its work
RESERVED_NAMES = ("index.html", "batch.json", "compare", "bench")
DESCRIPTION_MAX = 1000  # free text shown in the gallery; longer is almost surely a mistake (a pasted file)
# Common [pendulums] keys (each system declares its own in keys.py). Angles wrap, so beyond ±1000 rad a
# spread only loses resolution (f64 resolves ~1e-13 rad there); gravity up to 1e4 m/s² (1000 g) and
# damping up to 1e3 1/s (a swing stopped within milliseconds) already need steps of microseconds.
SPREAD_MAX = 1e3
GRAVITY_MAX = 1e4
DAMPING_MAX = 1e3
# f32 (drafts) spans 1e-38..3e38: the triple pendulum's mass-matrix determinant grows like (m·l²)³, so
# lengths and masses of 1e6 overflow it and 1e-6 underflow it (NaN at the first frame). Within [1e-3, 1e3]
# every system's f32 arithmetic stays in range.
F32_SIZE_MIN, F32_SIZE_MAX = 1e-3, 1e3

REQUIRED = object()  # schema default for keys a preset must state: the scene is ambiguous without them
# The Poincaré panel's least side (render/draw/section.py): its 6x13 title, ticks and labels take 63 px of the
# height and 62 of the width around the plot, which keeps 33 px
POINCARE_MIN = 96
# Keys a fan uses and a map ignores (its pendulums are its pixels): refused in a map's preset unless at their
# defaults, which a scene's own dict carries when it round-trips
FAN_ONLY = (("pendulums", "spread"), ("pendulums", "gap"), ("video", "palette"), ("video", "trail_seconds"))
