"""A map's per-pixel data: what its pixels measured at the last frame, as the arrays of NAME.npz beside its
video (render/video/pipeline.py writes it with the video), and read back by `render.load_map`.

The plot is H rows × W columns, row 0 at the top as drawn; S = map.samples (1, 4 or 9) sub-pixel starts
per pixel, row by row from the pixel's top left (render/physics/grid.py's sample_starts). Fields:

- `x` (W,), `y` (H,) float64: the axes' values at the pixels' centres; `x_quantity`, `y_quantity`: what
  they are ([map] x and y: "theta1", "omega2", ...), `x_unit`, `y_unit` theirs ("rad", "rad/s");
- `starts` (H, W, S, 2) float64: each sample's (x, y) start;
- `colouring`: the preset's `fractal`; `value`: what it measures, per sample, at the last frame: flip_time
  and divergence, the event's time in s (float32; `pending` -1: not happened by then, `never` -2: cannot
  happen, the flip map's samples below the energy barrier), (H, W, S); lyapunov, σ_t in 1/s, (H, W, S);
  angles, every link's angle in rad, (H, W, S, links); `unit`: "s", "1/s" or "rad";
- `t` (s): the time of the last frame, how far a pending sample's claim reaches;
- `cannot_flip` (H, W, S) bool: E < B, no link can ever pass the top (render/maps/fractal.py), for every
  colouring;
- `trusted_until` (H, W) float32 s: the pixel's faithful time, the least of its lattice neighbours'
  certificates over their samples (grid.faithful_map);
- `trusted` (H, W, S) bool: the mask as drawn: the sample's claim (its event's time, 0 for one that cannot
  flip on the flip map, else t) ≤ trusted_until. A pixel's colour is the mean of its samples' colours, each
  masked or not by its own claim.
"""
from __future__ import annotations

import dataclasses
import zipfile
from pathlib import Path

import numpy as np

from ..physics import grid

# An event's time (fractal.Map's event field) when it has none: plain numbers here, so that reading a map's
# data does not start Taichi
PENDING = -1.0  # not happened (yet)
NEVER = -2.0  # cannot happen: below the energy barrier
UNITS = {"flip_time": "s", "divergence": "s", "lyapunov": "1/s", "angles": "rad"}
TEXT = ("colouring", "unit", "x_quantity", "y_quantity", "x_unit", "y_unit")  # the fields that are one text each
NUMBERS = ("t", "pending", "never")  # one number each


@dataclasses.dataclass(frozen=True)
class MapData:
    """A map's NAME.npz as arrays (see the module's docstring for each field)."""
    colouring: str
    unit: str
    x_quantity: str
    y_quantity: str
    x_unit: str
    y_unit: str
    x: np.ndarray
    y: np.ndarray
    starts: np.ndarray
    value: np.ndarray
    t: float
    cannot_flip: np.ndarray
    trusted_until: np.ndarray
    trusted: np.ndarray
    pending: float = PENDING
    never: float = NEVER

    @property
    def samples(self) -> int:
        return self.value.shape[2]


def arrays(scene, mp) -> dict[str, np.ndarray]:
    """The npz's arrays of map `mp` (fractal.Map or ftle.FtleMap, or a tiled render's bands put together:
    render/maps/tiles.py) of `scene`, at its current frame: from its result()."""
    lay, n = grid.plot(scene), scene.map.samples
    res = mp.result()
    shape = (lay.h, lay.w, n)
    centres = grid.starts(scene).reshape(lay.h, lay.w, 2)
    until = res["until"].reshape(lay.h, lay.w)
    (xq, *_), (yq, *_) = grid.axes_of(scene.map)
    return {"colouring": np.str_(scene.fractal), "unit": np.str_(UNITS[scene.fractal]),
            "x_quantity": np.str_(xq), "y_quantity": np.str_(yq),
            "x_unit": np.str_(grid.unit(xq)), "y_unit": np.str_(grid.unit(yq)),
            "x": centres[0, :, 0].copy(), "y": centres[:, 0, 1].copy(),
            "starts": grid.sample_starts(scene).reshape(*shape, 2),
            "value": res["value"].reshape(*shape, *res["value"].shape[1:]), "t": np.float64(res["t"]),
            "cannot_flip": res["cannot_flip"].reshape(shape), "trusted_until": until,
            "trusted": res["claim"].reshape(shape) <= until[..., None],
            "pending": np.float32(PENDING), "never": np.float32(NEVER)}


def load(path) -> MapData:
    """A map's data from its NAME.npz, or from the render's folder OUT/NAME/ holding it. A missing file is
    FileNotFoundError; a file that is not a map's data, ValueError naming it."""
    path = Path(path)
    if path.is_dir():
        path = path / f"{path.name}.npz"
    if not path.is_file():
        raise FileNotFoundError(2, "no map data (a map render writes NAME.npz beside its video)", str(path))
    fields = {f.name for f in dataclasses.fields(MapData)}
    try:
        z = np.load(path, allow_pickle=False)
    except (ValueError, EOFError, zipfile.BadZipFile) as e:  # not an array file, or a truncated one
        raise ValueError(f"{path}: not a map's data ({e})") from None
    if not isinstance(z, np.lib.npyio.NpzFile):
        raise ValueError(f"{path}: not a map's data (one array, not an .npz of fields)")
    with z:
        missing = sorted(fields - set(z.files))
        if missing:
            raise ValueError(f"{path}: not a map's data (no {', '.join(missing)})")
        try:  # a member damaged in the file (a bad CRC, bytes that are no array) shows only as it is read
            got = {k: z[k] for k in fields}
        except (ValueError, OSError, EOFError, zipfile.BadZipFile) as e:
            raise ValueError(f"{path}: not a map's data ({e})") from None
    why = _misshapen(got)
    if why:
        raise ValueError(f"{path}: not a map's data ({why})")
    for k in TEXT:
        got[k] = str(got[k])
    for k in NUMBERS:
        got[k] = float(got[k])
    return MapData(**got)



def _misshapen(got: dict) -> str | None:
    """What in the fields does not have the shape the module's docstring gives (H, W from y and x), or None."""
    for k in (*TEXT, *NUMBERS):
        if got[k].ndim != 0 or (got[k].dtype.kind not in "USO" if k in TEXT else got[k].dtype.kind not in "fiu"):
            return f"{k} is {got[k].dtype} of shape {got[k].shape}, not one {'text' if k in TEXT else 'number'}"
    x, y = got["x"], got["y"]
    if x.ndim != 1 or y.ndim != 1 or x.dtype.kind != "f" or y.dtype.kind != "f":
        return f"x {x.shape} and y {y.shape} are not rows of numbers"
    plot = (len(y), len(x))
    for k, ndim in (("starts", 4), ("value", 3), ("cannot_flip", 3), ("trusted_until", 2), ("trusted", 3)):
        a = got[k]
        if a.ndim < ndim or a.shape[:2] != plot or a.dtype.kind not in "fbiu":
            return f"{k} is {a.dtype} of shape {a.shape}, not of the plot's {plot[0]} x {plot[1]} pixels"
    return None
