"""Where the pendulums are drawn: the view, a disc that holds everything a pendulum can ever draw, fitted
into what the HUD, a panel's label and the caption leave free.

A pendulum's chain points never leave the circle of sim.reach() metres around its pivot (the full length of
a rigid chain; for springs, the energy bound). Drawn, that is `radius` pixels, and its bobs, rods and trails
spill over it by at most `pad` pixels: so no pixel a pendulum draws is closer to the pivot than radius + pad.

Boxes are (x0, y0, x1, y1), inclusive pixel ranges the text owns. The view is the nominal one (the pivot at
the centre of its area, the reach at 0.46 of the area's smaller side, as the canvas has always framed it)
when it keeps at least GAP pixels clear of every box; otherwise the largest disc that does, its pivot on a
grid of candidate points (ties: the one nearest the centre), within the same margin of the area's edges.
It is plain numpy on the host, once per canvas; the same numbers give the same view.
"""
import dataclasses

import numpy as np

SHARE = 0.46  # the reach's share of the area's smaller side: the margin to the edges is 0.04 of it
GAP = 2  # px between the view and any text
GRID = 160  # candidate pivots per side of the area at most, when the nominal view does not fit


@dataclasses.dataclass(frozen=True)
class View:
    cx: float  # the pivot, in pixels
    cy: float
    radius: float  # px of the chain's reach
    pad: float  # px a drawing spills beyond it (bob radius, line width, antialiasing)

    @property
    def outer(self) -> float:
        """Every pixel a pendulum draws lies closer than this to the pivot."""
        return self.radius + self.pad

    def reachable(self, h: int, w: int) -> np.ndarray:
        """H×W bool: the pixels a pendulum can draw in (within `outer` of the pivot)."""
        y, x = np.mgrid[0:h, 0:w]
        return np.hypot(x - self.cx, y - self.cy) < self.outer


def box_of(rows: np.ndarray) -> tuple[int, int, int, int] | None:
    """The box Font.layout's glyph rows cover (left, top, scale, cell width and height: columns 1, 2, 3, 8, 9)."""
    if len(rows) == 0:
        return None
    left, top, cw, ch = rows[:, 1], rows[:, 2], rows[:, 8] * rows[:, 3], rows[:, 9] * rows[:, 3]
    return int(left.min()), int(top.min()), int((left + cw).max()) - 1, int((top + ch).max()) - 1


def distance(boxes, x, y):
    """Distance from points (x, y) (arrays) to the nearest box's pixels; inf with no boxes."""
    d = np.full(np.broadcast(x, y).shape, np.inf)
    for x0, y0, x1, y1 in boxes:
        dx = np.maximum(np.maximum(x0 - x, x - x1), 0.0)
        dy = np.maximum(np.maximum(y0 - y, y - y1), 0.0)
        d = np.minimum(d, np.hypot(dx, dy))
    return d


def fit(area: int, h: int, pad: float, boxes=()) -> View:
    """The view in an area `area` pixels wide from the left edge and `h` high, clear of `boxes`."""
    side = min(area, h)
    cx, cy, r = 0.5 * area, 0.5 * h, SHARE * side
    boxes = [b for b in boxes if b is not None]
    if float(distance(boxes, cx, cy)) >= r + pad + GAP:
        return View(cx, cy, r, pad)
    edge = (0.5 - SHARE) * side
    step = max(1.0, side / GRID)
    x, y = np.meshgrid(np.arange(0.0, area, step) + 0.5 * (area % step), np.arange(0.0, h, step) + 0.5 * (h % step))
    room = np.minimum(np.minimum(x, area - x), np.minimum(y, h - y)) - edge
    room = np.minimum(np.minimum(room, r), distance(boxes, x, y) - pad - GAP)
    best = room.max()
    near = np.where(room >= best - 1e-9, np.hypot(x - cx, y - cy), np.inf)
    k = np.unravel_index(np.argmin(near), near.shape)
    return View(float(x[k]), float(y[k]), max(float(best), 1.0), pad)
