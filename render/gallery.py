"""What an output root holds: the renders found there, whether one is up to date, the gallery page
out/index.html and the batch summary table.

The gallery is built from the metadata.json files on disk rather than from one batch's results, so renders
skipped as up to date, or made by `pendulum render`, show too. Links are relative, so the page works opened
from disk or served from any prefix. Everything taken from metadata is escaped: descriptions are free text.

Each MP4 shows as a <video> with its poster (render/poster.py), each card with its certificate (until when
the video is faithful) and the files' sizes. A small script marks every video and image as it loads or fails
(data-state), so a broken file says so on its card; tests/test_gallery_browser.py reads those marks from
headless Chromium. `pendulum gallery` writes the page alone; `pendulum batch` writes it after each batch.
"""
from __future__ import annotations

import datetime
import html
import json
from pathlib import Path
from urllib.parse import quote

from . import poster
from .atomic import digest, write_atomic
from .errors import SceneError
from .version import __version__

CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:2em;background:#111;color:#ddd}
h1{font-weight:600}a{color:#8cf}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(340px,1fr));gap:1.2em}
.card{background:#1c1c1c;border-radius:8px;padding:1em}
.card img,.card video{width:100%;height:auto;background:#000;border-radius:4px;display:block}
.broken{color:#f88;padding:.3em 0}
.card h2{font-size:1.1em;margin:.2em 0 .4em}.desc{color:#aaa}
.nogif{padding:3em 0;text-align:center;background:#000;color:#666}
dl{display:grid;grid-template-columns:auto 1fr;gap:.1em .8em;margin:.6em 0 0}dt{color:#888}dd{margin:0}
.failed{background:#3a1616;border-radius:8px;padding:.6em 1em;margin-bottom:1.2em}
"""

# Marks each video and image once it has loaded or failed; a failure is written on its card.
SCRIPT = """
for (const el of document.querySelectorAll("video, img")) {
  const ok = () => { el.dataset.state = "loaded"; };
  const bad = () => {
    if (el.dataset.state === "error") return;
    el.dataset.state = "error";
    el.insertAdjacentHTML("afterend", '<div class="broken">cannot load this file</div>');
  };
  el.addEventListener(el.tagName === "VIDEO" ? "loadedmetadata" : "load", ok);
  el.addEventListener("error", bad);
  if (el.tagName === "VIDEO" ? el.error : el.complete && !el.naturalWidth) bad();
  else if (el.tagName === "VIDEO" ? el.readyState >= 1 : el.complete) ok();
}
"""


def find_renders(out_root: Path) -> list[tuple[Path, dict]]:
    """(directory, metadata) for each out_root/NAME/metadata.json (and comparison,
    out_root/compare/NAME/metadata.json) that parses; sorted by name, comparisons last."""
    found = []
    root = Path(out_root)
    for meta_file in [*sorted(root.glob("*/metadata.json")), *sorted(root.glob("compare/*/metadata.json"))]:
        try:
            meta = json.loads(meta_file.read_text())
        except (OSError, ValueError):
            continue  # half-written or foreign: the gallery is best effort, the renders are not
        if isinstance(meta, dict):
            found.append((meta_file.parent, meta))
    return found


def write_index(out_root: Path, failed: list[tuple[str, str]] = ()) -> Path:
    """Regenerate out_root/index.html; `failed` lists (preset, error) from the batch that just ran."""
    out_root = Path(out_root)
    renders = find_renders(out_root)
    stamp = datetime.datetime.now().isoformat(timespec="seconds")
    parts = ["<!doctype html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width,initial-scale=1">',
             "<title>pendulum renders</title>", f"<style>{CSS}</style></head><body>",
             f"<h1>pendulum renders</h1><p>{len(renders)} render(s) in {_e(out_root.name or str(out_root))}, "
             f"page generated {_e(stamp)}.</p>"]
    if failed:
        items = "".join(f"<li><b>{_e(name)}</b>: {_e(err)}</li>" for name, err in failed)
        parts.append(f'<div class="failed"><b>Failed in the last batch</b><ul>{items}</ul></div>')
    parts.append('<div class="grid">')
    parts += [card(d, meta, d.relative_to(out_root)) for d, meta in renders]
    parts.append(f"</div><script>{SCRIPT}</script></body></html>\n")
    path = out_root / "index.html"
    write_atomic(path, "\n".join(parts))
    return path


def up_to_date(scene, out_root: Path) -> dict | None:
    """The existing metadata when out_root/NAME holds this scene's render by this version, files intact:
    each output's size and sha256 as metadata.json records them (a render without hashes is redone)."""
    d = scene.out_dir(out_root)
    try:
        meta = json.loads((d / "metadata.json").read_text())
        if meta["preset_hash"] != scene.hash() or meta["versions"]["package"] != __version__:
            return None
        outputs, sums = meta["outputs"], meta["outputs_sha256"]
        if not {f"{scene.name}.{fmt}" for fmt in scene.video.formats} <= set(outputs) or set(sums) != set(outputs):
            return None
        if any(not (d / f).is_file() or (d / f).stat().st_size != size for f, size in outputs.items()):
            return None  # the cheap test first: a file gone or resized
        if any(digest(d / f) != sums[f] for f in outputs):
            return None  # changed in place (same size): only its content hash tells
        return meta
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def row_from_meta(name: str, status: str, meta: dict, wall_s: float | None) -> dict:
    energy = meta.get("energy") or {}
    return {"preset": name, "status": status, "frames": meta.get("frames"), "wall_s": wall_s,
            "bytes": sum((meta.get("outputs") or {}).values()), "drift": energy.get("max_rel_drift"),
            "preset_hash": meta.get("preset_hash")}


def card(out_dir: Path, meta: dict, rel: Path | None = None) -> str:
    """One render's card; links go to `rel`, its folder relative to the page (default: its name)."""
    preset = _get(meta, "preset", default={})
    name = str(preset.get("name") or out_dir.name) if isinstance(preset, dict) else out_dir.name
    outputs = _get(meta, "outputs", default={})
    files = [f for f in outputs if (out_dir / f).is_file()] if isinstance(outputs, dict) else []
    gif = next((f for f in files if f.endswith(".gif")), None)
    mp4 = next((f for f in files if f.endswith(".mp4")), None)
    base = quote((rel or Path(out_dir.name)).as_posix())  # relative to index.html, which sits in out_root
    duration = _get(meta, "duration")
    still = poster.ensure(out_dir / mp4, duration / 2 if _num(duration) != "?" else 0) if mp4 else None
    if mp4:
        cover = f' poster="{base}/{_q(still.name)}"' if still else ""
        img = (f'<video src="{base}/{_q(mp4)}"{cover} controls loop muted playsinline preload="metadata" '
               f'aria-label="{_e(name)}"></video>')
    else:
        img = (f'<a href="{base}/{_q(gif)}"><img src="{base}/{_q(gif)}" loading="lazy" alt="{_e(name)}"></a>'
               if gif else '<div class="nogif">no video rendered</div>')
    links = [f'<a href="{base}/{_q(f)}">{_e(f.rsplit(".", 1)[-1].upper())}</a> ({_size(outputs[f])})'
             for f in (mp4, gif) if f]
    links.append(f'<a href="{base}/metadata.json">metadata.json</a>')
    integ, t = _get(meta, "integrator", default={}), _get(meta, "timings_s", default={})
    drift = _get(meta, "energy", "max_rel_drift")
    rows = [
        ("scene", f"{_get(preset, 'system', default='?')}, N={_get(preset, 'pendulums', 'count', default='?')}"),
        ("video", f"{_get(meta, 'frames', default='?')} frames, {_get(meta, 'width', default='?')}x"
                  f"{_get(meta, 'height', default='?')} @ {_get(meta, 'fps', default='?')} fps"),
        ("integrator", f"{_get(integ, 'method', default='?')}, dt={_num(_get(integ, 'dt'))} s "
                       f"x{_get(integ, 'substeps', default='?')}, {_get(integ, 'precision', default='?')}"),
        ("faithful", _faithful(_get(meta, "faithfulness", default={}), duration)),
        ("energy drift", _num(drift) if drift is not None else "not measured"),
        ("timings", " ".join(f"{k} {_num(t.get(k))}s" for k in ("simulate", "draw", "encode", "total")
                             if isinstance(t, dict) and k in t)),
        ("versions", " ".join(f"{k} {v}" for k, v in (_get(meta, "versions", default={}) or {}).items())),
    ]
    desc = _get(preset, "description", default="")
    return (f'<div class="card">{img}<h2>{_e(name)}</h2>'
            + (f'<div class="desc">{_e(desc)}</div>' if desc else "")
            + f"<div>{' &middot; '.join(links)}</div><dl>"
            + "".join(f"<dt>{_e(k)}</dt><dd>{_e(v)}</dd>" for k, v in rows)
            + "</dl></div>")


def _faithful(f, duration) -> str:
    """The certificate in a few words: until when the first and the median pendulum are faithful."""
    first, median, tol = (_get(f, k) for k in ("faithful_until_s", "median_until_s", "tolerance"))
    if _num(first) == "?" or _num(median) == "?":
        return "no certificate"
    end = duration if _num(duration) != "?" else float("inf")
    until = [("the end" if t >= end else f"{t:.2f} s") for t in (first, median)]
    return f"until {until[0]} (median {until[1]}) at {_num(tol)} {_get(f, 'unit', default='')}".rstrip()


def _get(d, *keys, default=None):
    """Nested lookup that tolerates metadata from older or foreign versions."""
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return default
        d = d[k]
    return d


def _e(x) -> str:
    return html.escape(str(x), quote=True)


def _q(file_name: str) -> str:
    return html.escape(quote(file_name), quote=True)


def _num(x) -> str:
    return f"{x:.3g}" if isinstance(x, (int, float)) and not isinstance(x, bool) else "?"


def _size(n) -> str:
    if not isinstance(n, int):
        return "?"
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"


def summary_table(rows: list[dict]) -> str:
    """The batch's stdout summary: one row per preset; failed rows end with their one-line error."""
    width = max([len("preset")] + [len(r["preset"]) for r in rows])
    lines = [f"{'preset':<{width}}  {'status':<7}  {'frames':>6}  {'wall':>7}  {'size':>8}  {'drift':>8}"]
    for r in rows:
        cells = [r.get("frames") if r.get("frames") is not None else "-",
                 f"{r['wall_s']:.1f}s" if r.get("wall_s") is not None else "-",
                 _size(r["bytes"]) if r.get("bytes") is not None else "-",
                 f"{r['drift']:.2g}" if r.get("drift") is not None else "-"]
        line = f"{r['preset']:<{width}}  {r['status']:<7}  {cells[0]:>6}  {cells[1]:>7}  {cells[2]:>8}  {cells[3]:>8}"
        lines.append(line + (f"  {r['error']}" if r["status"] == "failed" else ""))
    return "\n".join(lines)


# ---------------------------------------------------------------- the command


def add_parser(sub):
    g = sub.add_parser("gallery", help="write OUT/index.html: every render in OUT with its video and certificate",
                       description="Write OUT/index.html, a page of every render in OUT/ (posters, videos, "
                                   "certificates, sizes), with links relative to it: open it from disk.")
    g.add_argument("--out", type=Path, default=Path("out"), help="the output root to show (default: out)")
    g.set_defaults(func=run)


def run(args) -> int:
    if not args.out.is_dir():
        raise SceneError(f"--out {args.out}: not a directory of renders")
    index = write_index(args.out)
    print(f"{len(find_renders(args.out))} render(s) -> {index}")
    return 0
