"""What an output root holds: the renders found there, whether one is up to date, the gallery page
out/index.html and the batch summary table.

The gallery is built from the metadata.json files on disk rather than from one batch's results, so renders
skipped as up to date, or made by `pendulum render`, show too. Links are relative, so the page works opened
from disk or served from any prefix. Everything taken from metadata is escaped: descriptions are free text.

Each MP4 shows as a <video> with its poster (render/video/poster.py), each card with its certificate (until when
the video is faithful), the overrides it was made with and the files' sizes; a comparison's card also lists its
variants, each with when it parts from the finest and until when it is faithful. A small script marks every video
and image as it loads or fails (data-state), so a broken file says so on its card; tests/test_gallery_browser.py
reads those marks from headless Chromium. `pendulum gallery` writes the page alone; `pendulum batch` writes it
after each batch.
"""
from __future__ import annotations

import datetime
import html
import math
import os
import tempfile
from pathlib import Path
from typing import NamedTuple
from urllib.parse import quote

from . import confined
from ..trust import faithful
from ..video import poster
from ..video.atomic import digest, together, write_atomic
from ..errors import SceneError
from ..config.limits import DESCRIPTION_MAX
from ..config.options import check_replaceable, out_path
from ..video.version import __version__

CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:2em;background:#111;color:#ddd}
h1{font-weight:600}a{color:#8cf}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(340px,1fr));gap:1.2em}
.card{background:#1c1c1c;border-radius:8px;padding:1em}
.card img,.card video{width:100%;height:auto;background:#000;border-radius:4px;display:block}
.broken{color:#f88;padding:.3em 0}
.card h2{font-size:1.1em;margin:.2em 0 .4em;overflow-wrap:anywhere}.desc{color:#aaa}.skip{color:#f88}
.nogif{padding:3em 0;text-align:center;background:#000;color:#666}
dl{display:grid;grid-template-columns:auto 1fr;gap:.1em .8em;margin:.6em 0 0}dt{color:#888}dd{margin:0}
code.set{overflow-wrap:anywhere}
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


LISTED = 40  # overrides or variants a card lists; metadata.json holds them all (and a hostile one, any number)


class Found(NamedTuple):
    """A render folder under OUT: its metadata and its outputs still there, or why it is not shown."""
    folder: Path
    meta: dict | None
    files: dict[str, Path]
    skipped: str = ""


def find_renders(out_root: Path) -> list[Found]:
    """Each out_root/NAME (and comparison, out_root/compare/NAME) holding a metadata.json, sorted by name,
    comparisons last; one that cannot be shown without leaving out_root, or whose metadata is not a render's,
    is there with why (render/commands/confined.py). A symlink there may lead anywhere: it is listed, never followed."""
    root, found = Path(out_root), []
    for where in (root, root / "compare"):
        try:
            with os.scandir(confined.folder(root, where)) as it:
                entries = sorted(it, key=lambda e: e.name)
        except (OSError, confined.Refused):
            continue  # no comparisons (a symlinked compare/ shows below, as a folder of out_root)
        for entry in entries:
            path = Path(entry.path)
            try:
                if not entry.is_dir(follow_symlinks=False):
                    if entry.is_symlink():
                        confined.folder(root, path)  # raises, saying where it leads
                    continue
                os.lstat(path / "metadata.json")  # FileNotFoundError: a folder but not a render
                found.append(Found(path, *confined.metadata(path)))
            except FileNotFoundError:
                continue
            except confined.Refused as e:
                found.append(Found(path, None, {}, str(e)))
            except OSError as e:
                found.append(Found(path, None, {}, f"cannot be read: {e.strerror}"))
    return found


def write_index(out_root: Path, failed: list[tuple[str, str]] = (), renders: list[Found] | None = None) -> Path:
    """Regenerate out_root/index.html from `renders` (default: find_renders); `failed` lists (preset, error)
    from the batch that just ran."""
    shown, root = Path(out_root), Path(out_root).resolve()  # resolved: every check below is against the real root
    renders = find_renders(root) if renders is None else renders
    skipped = sum(bool(r.skipped) for r in renders)
    stamp = datetime.datetime.now().isoformat(timespec="seconds")
    parts = ["<!doctype html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width,initial-scale=1">',
             "<title>pendulum renders</title>", f"<style>{CSS}</style></head><body>",
             f"<h1>pendulum renders</h1><p>{len(renders) - skipped} render(s) in {_e(shown.name or str(shown))}"
             f"{f', {skipped} skipped' if skipped else ''}, page generated {_e(stamp)}.</p>"]
    if failed:
        items = "".join(f"<li><b>{_e(name)}</b>: {_e(err)}</li>" for name, err in failed)
        parts.append(f'<div class="failed"><b>Failed in the last batch</b><ul>{items}</ul></div>')
    parts.append('<div class="grid">')
    with together():  # the posters a card makes appear with the page, or not at all
        parts += [card(r, r.folder.relative_to(root)) for r in renders]
        parts.append(f"</div><script>{SCRIPT}</script></body></html>\n")
        write_atomic(root / "index.html", "\n".join(parts))
    return shown / "index.html"


def up_to_date(scene, out_root: Path) -> dict | None:
    """The existing metadata when out_root/NAME holds this scene's render by this version, files intact:
    each output's size and sha256 as metadata.json records them (a render without hashes is redone).
    Read as the gallery reads (render/commands/confined.py): a FIFO or a symlink there is no render, and outputs
    naming a file outside the folder make it none either."""
    root = Path(out_root).resolve()
    try:
        d = confined.folder(root, scene.out_dir(root))
        meta, files = confined.metadata(d)
        if meta["preset_hash"] != scene.hash() or meta["versions"]["package"] != __version__:
            return None
        outputs, sums = meta["outputs"], meta["outputs_sha256"]
        if not {f"{scene.name}.{fmt}" for fmt in scene.video.formats} <= set(outputs) or set(sums) != set(outputs):
            return None
        if set(files) != set(outputs) or any(files[f].stat().st_size != size for f, size in outputs.items()):
            return None  # the cheap test first: a file gone or resized
        if any(digest(files[f]) != sums[f] for f in outputs):
            return None  # changed in place (same size): only its content hash tells
        return meta
    except (OSError, ValueError, KeyError, TypeError):  # confined.Refused is a ValueError
        return None


def row_from_meta(name: str, status: str, meta: dict, wall_s: float | None) -> dict:
    energy = meta.get("energy") or {}
    return {"preset": name, "status": status, "frames": meta.get("frames"), "wall_s": wall_s,
            "bytes": sum((meta.get("outputs") or {}).values()), "drift": energy.get("max_rel_drift"),
            "preset_hash": meta.get("preset_hash")}


def card(r: Found, rel: Path) -> str:
    """One render's card, or the note of why it is skipped; links go to `rel`, its folder relative to the page.
    `r` is as find_renders checked it: each section of confined.SECTIONS an object (or null where
    confined.NULLABLE), each file inside."""
    if r.skipped:
        return f'<div class="card"><h2>{_e(rel.as_posix())}</h2><div class="skip">skipped: {_e(r.skipped)}</div></div>'
    meta, preset = r.meta, r.meta.get("preset", {})
    name = _v(preset, "name", default="") or r.folder.name
    gif = next((f for f in r.files if f.endswith(".gif")), None)
    mp4 = next((f for f in r.files if f.endswith(".mp4")), None)
    base = quote(rel.as_posix())  # relative to index.html, which sits in out_root
    duration = meta.get("duration")
    at = duration / 2 if _num(duration) != "?" and math.isfinite(duration) else 0
    still = poster.ensure(r.files[mp4], at) if mp4 else None
    if mp4:
        cover = f' poster="{base}/{_q(still.name)}"' if still else ""
        img = (f'<video src="{base}/{_q(mp4)}"{cover} controls loop muted playsinline preload="metadata" '
               f'aria-label="{_e(name)}"></video>')
    else:
        img = (f'<a href="{base}/{_q(gif)}"><img src="{base}/{_q(gif)}" loading="lazy" alt="{_e(name)}"></a>'
               if gif else '<div class="nogif">no video rendered</div>')
    links = [f'<a href="{base}/{_q(f)}">{_e(f.rsplit(".", 1)[-1].upper())}</a> ({_size(meta["outputs"][f])})'
             for f in (mp4, gif) if f]
    links.append(f'<a href="{base}/metadata.json">metadata.json</a>')
    integ, t, versions = (meta.get(k, {}) for k in ("integrator", "timings_s", "versions"))
    drift = _get(meta, "energy", "max_rel_drift")
    rows = [
        ("scene", f"{_v(preset, 'system')}, N={_v(preset, 'pendulums', 'count')}"),
        ("video", f"{_v(meta, 'frames')} frames, {_v(meta, 'width')}x{_v(meta, 'height')} @ {_v(meta, 'fps')} fps"),
        ("integrator", f"{_v(integ, 'method')}, dt={_num(integ.get('dt'))} s x{_v(integ, 'substeps')}, "
                       f"{_v(integ, 'precision')}"),
        ("faithful", _faithful(meta.get("faithfulness", {}), duration)),
        ("energy drift", _num(drift) if drift is not None else "not measured"),
        ("timings", " ".join(f"{k} {_num(t.get(k))}s" for k in ("simulate", "draw", "encode", "total") if k in t)),
        ("versions", " ".join(f"{_cut(k)} {_v(versions, k)}" for k in versions)),
    ]
    desc = _v(preset, "description", default="")
    items = [(k, _e(v)) for k, v in rows] + [("overrides", _overrides(meta.get("overrides")))]
    if isinstance(meta.get("compare"), dict):
        items.append(("variants", _variants(meta["compare"], duration)))
    return (f'<div class="card">{img}<h2>{_e(name)}</h2>'
            + (f'<div class="desc">{_e(desc)}</div>' if desc else "")
            + f"<div>{' &middot; '.join(links)}</div><dl>"
            + "".join(f"<dt>{_e(k)}</dt><dd>{v}</dd>" for k, v in items)
            + "</dl></div>")


def _overrides(given) -> str:
    """HTML: each override as given (--quality as quality=LEVEL, then each --set), one per line, escaped."""
    if not isinstance(given, list):
        return "not recorded"  # made before metadata recorded them, or not a list
    if not given:
        return "none: the preset as written"
    shown = [f'<code class="set">{_e(_cut(x))}</code>' for x in given[:LISTED] if isinstance(x, str)]
    more = len(given) - LISTED
    return ("<br>".join(shown) or "?") + (f"<br>and {more} more in metadata.json" if more > 0 else "")


def _variants(compare: dict, duration) -> str:
    """HTML: each variant of a comparison, when it parts from the finest and until when it is faithful."""
    variants, finest = compare.get("variants"), compare.get("finest")
    if not isinstance(variants, list):
        return "not recorded"
    lines = []
    for i, v in enumerate(variants[:LISTED]):
        label = _v(v, "label", default=f"variant {i + 1}")
        parted = _get(v, "divergence_s")
        parts = ("the one the others part from" if finest == i and not isinstance(finest, bool) else
                 "never parts from the finest" if parted is None else
                 f"parts from the finest at {parted:.2f} s" if _num(parted) != "?" else "parts from the finest at ?")
        until = faithful.until(_get(v, "faithfulness", "faithful_until_s"), duration)
        lines.append(f'<span class="variant">{_e(label)}: {parts}, faithful until {until}</span>')
    more = len(variants) - LISTED
    return "<br>".join(lines) + (f"<br>and {more} more in metadata.json" if more > 0 else "") or "none"


def _faithful(f, duration) -> str:
    """The certificate in a few words (faithful.sentence, brief), its unit cut as every text on a card is."""
    if not isinstance(f, dict) or "?" in (_num(f.get("faithful_until_s")), _num(f.get("median_until_s"))):
        return "no certificate"
    return faithful.sentence({**f, "unit": _v(f, "unit", default="")}, duration, brief=True)


def _get(d, *keys):
    """Nested lookup that tolerates metadata from older or foreign versions."""
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def _v(d, *keys, default="?") -> str:
    """The number or text at d[keys...], `default` when missing or not a scalar (a list, an object, null)."""
    x = _get(d, *keys)
    if isinstance(x, str):
        return _cut(x)
    return str(x) if isinstance(x, (int, float)) else default


def _cut(text: str, most: int = DESCRIPTION_MAX) -> str:
    return text if len(text) <= most else text[:most - 3] + "..."


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
    g.add_argument("--out", type=out_path, default=Path("out"), help="the output root to show (default: out)")
    g.set_defaults(func=run)


def run(args) -> int:
    if not args.out.is_dir():
        raise SceneError(f"--out {args.out}: not a directory of renders")
    root = args.out.resolve()
    try:  # bad input, refused before any poster is made: the page could not be written there
        tempfile.TemporaryFile(dir=root).close()
    except OSError as e:
        raise SceneError(f"--out {args.out}: cannot write the gallery there: {e.strerror}") from None
    check_replaceable(root / "index.html")  # e.g. a folder of that name: refused before any poster is made
    renders = find_renders(root)
    index = write_index(args.out, renders=renders)
    skipped = sum(bool(r.skipped) for r in renders)
    print(f"{len(renders) - skipped} render(s)" + (f", {skipped} skipped" if skipped else "") + f" -> {index}")
    return 0
