"""What the API returns, and how it shows: a RenderResult (the files, the metadata, the certificate) and a
Trajectory (the arrays of `pendulum simulate`). Both print as one line and display inline in Jupyter
through `_repr_html_`: the video itself and a short table.

A render shows as a <video> whose src is the MP4's path relative to the current directory, which is the
notebook's own folder in Jupyter, so the page stays small however long the video; a render without an MP4
shows its GIF, embedded as base64 when it is small enough to keep inside the notebook (up to EMBED_BYTES),
else by its relative path.
"""
from __future__ import annotations

import base64
import html
import os
from collections.abc import Mapping
from pathlib import Path
from urllib.parse import quote

import numpy as np

from ..trust import faithful

EMBED_BYTES = 2_000_000  # a GIF up to this size is embedded: the notebook then shows it anywhere it is opened


class RenderResult:
    """One render: `dir` (OUT/NAME/), `paths` (format -> Path, and "metadata"), `metadata` (the dict in
    metadata.json) and `certificate` (its "faithfulness": until when the video is true to the physics)."""

    def __init__(self, scene, out_dir: Path, metadata: dict):
        self.scene, self.dir, self.metadata = scene, Path(out_dir), metadata
        outputs = metadata.get("outputs") or {}
        self.paths = {f.rsplit(".", 1)[-1]: self.dir / f for f in outputs}
        self.paths["metadata"] = self.dir / "metadata.json"

    @property
    def certificate(self) -> dict:
        return self.metadata["faithfulness"]

    @property
    def frames(self) -> int:
        return self.metadata["frames"]

    @property
    def wall_s(self) -> float:
        return self.metadata["timings_s"]["total"]

    def line(self) -> str:
        """What `pendulum render` prints for this render: size, integrator, certificate, timings."""
        meta = self.metadata
        if "compare" in meta:  # a split screen: each variant's cost, divergence and certificate
            return _compare_line(meta, self.dir)
        i, t = meta["integrator"], meta["timings_s"]
        drift = meta["energy"]["max_rel_drift"] if meta["energy"] else None
        drift_s = f", energy drift {drift:.2g}" if drift is not None else ""
        q = meta["quality"]
        level = f" ({q['level']}: {'met' if q.get('met') else 'NOT met'})" if q["level"] else " (as the preset states)"
        if "f64" in meta.get("map", {}).get("axes", {}):  # promoted: a zoom finer than f32 resolves (physics/grid.py)
            level = (level if q["level"] else "") + " (f64: the zoom is finer than f32 resolves)"
        return (f"{meta['preset']['name']}: {meta['frames']} frames {meta['width']}x{meta['height']}@{meta['fps']} | "
                f"{_method(i)}{level}{drift_s} | {faithful.sentence(self.certificate, meta['duration'])} | "
                f"simulate {t['simulate']:.2f}s draw {t['draw']:.2f}s encode {t['encode']:.2f}s "
                f"total {t['total']:.2f}s -> {self.dir}/")

    def __repr__(self) -> str:
        return f"<RenderResult {self.scene.name}: {self.frames} frames -> {self.dir}/>"

    def _repr_html_(self) -> str:
        meta = self.metadata
        files = ", ".join(f"{p.name} ({_size(p.stat().st_size)})" for k, p in self.paths.items()
                          if k != "metadata" and p.is_file())
        rows = [("frames", f"{meta['frames']} ({meta['width']}x{meta['height']} at {meta['fps']} fps, "
                           f"{meta['duration']:g} s)"),
                ("method", _method(meta["integrator"])),
                ("faithful", faithful.sentence(self.certificate, meta["duration"])),
                ("wall time", f"{self.wall_s:.2f} s"),
                ("files", files or "none")]
        return f"<div>{self.media_html()}{_table(rows)}</div>"

    def media_html(self) -> str:
        """The <video> (or the GIF, or the last frame's still) that shows this render."""
        mp4 = self.paths.get("mp4")
        if mp4 is not None and mp4.is_file():
            return (f'<video src="{_src(mp4)}" controls loop muted autoplay playsinline '
                    f'style="max-width:100%;display:block"></video>')
        for kind in ("gif", "png"):  # a png-only render (formats = ["png"]) shows its still
            image = self.paths.get(kind)
            if image is not None and image.is_file():
                if image.stat().st_size <= EMBED_BYTES:
                    data = base64.b64encode(image.read_bytes()).decode()
                    return f'<img src="data:image/{kind};base64,{data}" alt="{_e(image.name)}" style="max-width:100%">'
                return f'<img src="{_src(image)}" alt="{_e(image.name)}" style="max-width:100%">'
        return "<p>(no video file)</p>"


class Trajectory(Mapping):
    """A simulation's arrays as the .npz of `pendulum simulate` holds them (float64): `t` (F,), `energy`
    (F, N) and the system's state, e.g. `theta`, `omega` (F, N, links) or `pos`, `vel` (F, N, bobs, 2).
    Read them as traj["theta"] or traj.theta; `info` holds the integrator used and the certificate."""

    def __init__(self, scene, arrays: dict, info: dict, path: Path | None = None):
        self.scene, self.arrays, self.info, self.path = scene, dict(arrays), info, path

    def __getitem__(self, key: str) -> np.ndarray:
        return self.arrays[key]

    def __iter__(self):
        return iter(self.arrays)

    def __len__(self) -> int:
        return len(self.arrays)

    def __getattr__(self, key: str):
        arrays = self.__dict__.get("arrays", {})  # absent while unpickling
        if key in arrays:
            return arrays[key]
        raise AttributeError(key)

    @property
    def certificate(self) -> dict:
        return self.info["faithfulness"]

    def energy_drift(self) -> float:
        """The largest relative energy error over pendulums and frames, |E - E0| / |E0|."""
        e = self.arrays["energy"]
        e0 = np.abs(e[0])
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(e0 > 0, np.abs(e - e[0]) / np.where(e0 > 0, e0, 1), 0.0)
        return float(rel.max()) if rel.size else 0.0

    def save(self, path: str | os.PathLike) -> Path:
        """Write the arrays to a .npz as `pendulum simulate` does (atomically)."""
        from ..config.options import check_npz
        from ..video.atomic import replacing

        path = Path(path)
        check_npz(path, self.scene.name)  # as simulate(out=) checks it: before the file is compressed
        path.parent.mkdir(parents=True, exist_ok=True)
        with replacing(path, suffix=".npz") as tmp:
            np.savez_compressed(tmp, **self.arrays)
        self.path = path
        return path

    def __repr__(self) -> str:
        shapes = ", ".join(f"{k} {tuple(v.shape)}" for k, v in self.arrays.items())
        return f"<Trajectory {self.scene.name}: {shapes}>"

    def _repr_html_(self) -> str:
        t = self.arrays.get("t", np.zeros(0))
        rows = [("scene", f"{self.scene.name} ({self.scene.system}, N = {self.scene.pendulums.count})"),
                ("frames", f"{len(t)}, t = 0 to {t[-1]:g} s" if len(t) else "0"),
                ("arrays", ", ".join(f"{k} {'x'.join(map(str, v.shape))}" for k, v in self.arrays.items())),
                ("method", _method(self.info["integrator"]) if "integrator" in self.info else "?"),
                ("faithful", faithful.sentence(self.certificate, self.scene.video.duration)
                 if "faithfulness" in self.info else "?"),
                ("energy drift", f"{self.energy_drift():.2g}" if "energy" in self.arrays else "?"),
                ("file", str(self.path) if self.path else "not written (traj.save('x.npz') writes it)")]
        return _table(rows)


def _compare_line(meta: dict, out_dir: Path) -> str:
    """The comparison's line: each variant's cost, divergence and certificate, and where it went."""
    parts = []
    for i, v in enumerate(meta["compare"]["variants"]):
        if i == meta["compare"]["finest"]:
            how = "finest"
        else:
            how = "never parts" if v["divergence_s"] is None else f"parts at {v['divergence_s']:.2f} s"
        until = faithful.until(v["faithfulness"]["faithful_until_s"], meta["duration"])
        parts.append(f"{v['label'].removesuffix('  (finest)')}: {1e3 * v['cost_s_per_simulated_s']:.3g} ms/s, {how}, "
                     f"faithful until {until}")
    t = meta["timings_s"]
    return (f"{meta['preset']['name']}: {len(parts)} panels, {meta['frames']} frames {meta['width']}x{meta['height']}"
            f"@{meta['fps']} | " + " | ".join(parts) + f" | total {t['total']:.2f}s -> {out_dir}/")


def _method(i: dict) -> str:
    return f"{i['method']} dt={i['dt']:.3g}s x{i['substeps']} {i['precision']}"


def _table(rows) -> str:
    cells = "".join(f'<tr><th style="text-align:left">{_e(k)}</th><td style="text-align:left">{_e(v)}</td></tr>'
                    for k, v in rows)
    return f"<table>{cells}</table>"


def _src(path: Path) -> str:
    """A path as a URL relative to the current directory (the notebook's folder in Jupyter)."""
    return _e(quote(os.path.relpath(path, Path.cwd()).replace(os.sep, "/")))


def _e(x) -> str:
    return html.escape(str(x), quote=True)


def _size(n: int) -> str:
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"
