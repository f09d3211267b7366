"""A split-screen panel's words: the labels' colours and fonts, which of a label's lines fit above its panel's
pendulums (shown, label_band), and how a line says a value, an error and the preset; render/draw/split.py's
SplitScreen puts them together (label_lines, labels, legend) and measures its errors with the same turned.

Apart from split.py, which holds the panels' geometry, the two passes and the metadata, because all of this is
plain Python on the host that needs no runtime: strings, their line counts and the angle wrap the error is read
through. render/video/gif.py's second split screen sizes its labels by the same label_band and LARGE.
"""
import json
from pathlib import Path

import numpy as np

LARGE = 300  # panels at least this tall get the 10x20 font, smaller ones 6x13
LABEL_SHARE = 0.4  # of a panel's height its label may cover (from the top)
COLOURS = {"title": (1.0, 1.0, 1.0), "detail": (0.7, 0.7, 0.7), "close": (0.45, 0.95, 0.5),
           "parted": (1.0, 0.55, 0.2), "finest": (0.55, 0.75, 1.0), "clock": (1.0, 1.0, 1.0)}
DROP = (1, 2, 4)  # a short panel's label leaves out the integrator's line, then the cost, then its faithful time
INTEGRATOR = ("integrator.method", "integrator.dt", "integrator.precision")  # said as run, once


def shown(lines: list, room: int) -> list:
    """The label's lines (SplitScreen.label_lines) that fit in `room` lines, in their order, empty ones left
    out: the integrator's line goes first, then the cost, then the faithful time; the variant and its error stay."""
    kept = [k for k, (text, _) in enumerate(lines) if text]
    drop = [k for k in DROP if k in kept][:max(0, len(kept) - room)]
    return [lines[k] for k in kept if k not in drop]


def label_face(height: int) -> tuple[str, int, int, int]:
    """A label's font for panels `height` pixels high: (size, padding, line step, cell width) in pixels."""
    return ("10x20", 8, 21, 10) if height >= LARGE else ("6x13", 4, 13, 6)


def label_band(scene, height: int) -> int:
    """How many pixels from a panel's top its label covers: as many lines as SplitScreen.labels shows there."""
    _, pad_, step_, _ = label_face(height)
    room = max(2, int(LABEL_SHARE * height) // step_)
    named = dict(scene.compare)
    lines = [("variant", None), ("" if all(k in named for k in INTEGRATOR) else "integrator", None),
             ("cost", None), ("error", None), ("faithful", None)]  # label_lines' lines, by whether they are empty
    return pad_ // 2 + len(shown(lines, room)) * step_ + pad_ // 2


def fit(text: str, width: int, cell: int) -> str:
    """Text cut to `width` pixels of `cell`-wide glyphs, so a label stays inside its panel."""
    room = max(width // cell, 1)
    return text if len(text) <= room else text[:room - 1] + "…"


def amount(x: float) -> str:
    """An error for a label: 3.1e-05 when small, 0.42 or 44 when large."""
    return "0" if x == 0 else f"{x:.1e}" if x < 0.1 else f"{x:.2g}" if x < 10 else f"{x:.0f}"


def turned(x):
    """Angles (rad) wrapped to (−π, π]: a difference of whole turns is no difference on screen."""
    r = np.pi - np.mod(np.pi - np.asarray(x, dtype=np.float64), 2 * np.pi)
    return np.where(r <= -np.pi, r + 2 * np.pi, r)  # mod rounds a hair above π to 2π: back to π


def error_text(delta: str, x: float, angles: bool) -> str:
    """A panel's live error: `delta` (Δθ or Δx/L) and its size; an angle's wrapped, so it never reads above π."""
    return f"{delta} {amount(abs(float(turned(x))))} rad" if angles else f"{delta} {amount(x)}"


def preset_name(scene) -> str:
    """The name of the preset a comparison came from: its file's, not the folder's (NAME__<hash>, --name)."""
    path = scene.source.split(" (compare variant", 1)[0]
    return Path(path).stem if path.endswith(".toml") else scene.name


def value_text(v) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return json.dumps(v) if isinstance(v, (list, tuple, bool)) else str(v)
