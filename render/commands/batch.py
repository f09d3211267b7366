"""`pendulum batch`: render many presets, or a sweep of one, in worker processes or on a Dask cluster.

Every preset is loaded and validated in the parent (batch_plan.py: which scenes, and their folder names), so
a bad one fails alone before any worker starts and an up-to-date output is skipped without one. Renders run in
spawned processes (each owns its Taichi runtime) or as Dask tasks; each returns a plain dict, errors included,
so nothing depends on pickling exceptions. A summary table goes to stdout, out/batch.json records the rows and
out/index.html is rebuilt.
"""
from __future__ import annotations

import hashlib
import json
import os
import signal
import sys
import threading
import time
from pathlib import Path

from ..config import budget
from . import api, gallery
from .batch_plan import expand_refs, parse_sweeps, plan
from ..video.atomic import output_dir, write_atomic
from ..errors import BatchError, SceneError
from ..config.options import (add_budget, add_common, add_quality, budgeted, check_replaceable, check_writable,
                              out_path, positive_int, progress_wanted, thread_count, usable_cores)
from ..video.tiled import close, connect, env_address, quiet, scheduler_address
from ..video.version import __version__

_RENDER_LOCK = threading.Lock()  # one Taichi runtime per process: Dask threads in one worker take turns
STOP_S = 30.0  # how long a stopped worker may take to remove its partial files before it is killed


def add_parser(sub):
    b = sub.add_parser("batch", help="render many presets (default: all) in parallel, locally or on Dask",
                       description="Render every preset (or those named or globbed) into OUT/NAME/ like "
                                   "`render`, skipping up-to-date outputs; print a summary, write "
                                   "OUT/batch.json and the gallery OUT/index.html.")
    b.add_argument("presets", nargs="*", metavar="PRESET|GLOB",
                   help="preset names, .toml paths or globs of either (default: every preset on the search path, "
                        "$PENDULUM_PRESETS then presets/)")
    add_common(b)
    b.add_argument("--out", type=out_path, default=Path("out"), help="output root (default: out)")
    b.add_argument("--jobs", "-j", type=positive_int, default=None, metavar="J",
                   help="local worker processes (default: the number of cores)")
    b.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="run on this Dask scheduler, e.g. tcp://host:8786 (default: $DASK_SCHEDULER_ADDRESS); "
                        "--out must then be a directory the workers share")
    b.add_argument("--force", action="store_true", help="render again even when the output is up to date")
    b.add_argument("--sweep", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="render one variant per value (OUT/NAME__KEY_VALUE, then __<hash> with --set); repeat for "
                        "a grid")
    add_quality(b)
    add_budget(b)
    b.add_argument("--threads", type=thread_count, default=None,
                   help="Taichi CPU threads per render (default: cores / jobs locally, all cores on Dask)")
    b.add_argument("--digest", action="store_true",
                   help="record a sha256 of each render's raw frames in OUT/batch.json (reproducibility checks)")
    b.add_argument("--no-progress", action="store_true", help="no per-preset progress lines on stderr")
    b.set_defaults(func=run)


# ---------------------------------------------------------------- rendering (worker side)


def render_one(scene, out_root: str, arch: str = "cpu", threads: int | None = None, digest: bool = False,
               progress: bool = False) -> dict:
    """Render one scene; never raises for a failed render, so every executor reports it the same way."""
    t0 = time.perf_counter()
    h = hashlib.sha256() if digest else None
    hook = (lambda f, frame: h.update(frame.tobytes())) if digest else None
    try:
        with _RENDER_LOCK:
            from ..video import pipeline
            meta = pipeline.render(scene, Path(out_root), arch=arch, progress=progress, threads=threads,
                                   frame_hook=hook)
    except Exception as e:  # noqa: BLE001 - any failure is this preset's row, not the batch's end
        lines = [line.strip() for line in str(e).splitlines() if line.strip()] or [""]
        # One line for the table; Taichi puts the cause last, after "File ..., line N, in kernel".
        msg = lines[0] if len(lines) == 1 else f"{lines[-1]} ({lines[0].rstrip(':')})"
        if not isinstance(e, (SceneError, RuntimeError)) or not msg:
            msg = f"{type(e).__name__}: {msg}".rstrip(": ")
        return {"preset": scene.name, "status": "failed", "error": msg, "wall_s": time.perf_counter() - t0}
    row = gallery.row_from_meta(scene.name, "ok", meta, time.perf_counter() - t0)
    row["raw_frames_sha256"] = h.hexdigest() if h else None
    return row


def _worker_init():
    # The parent handles Ctrl-C and stops workers with SIGTERM; SystemExit lets the pipeline remove partials.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # a closed terminal reaches the parent too, which stops us
    signal.signal(signal.SIGTERM, _stop)
    os.dup2(2, 1)  # Taichi's start-up line would interleave with the parent's summary table on stdout
    # tqdm makes a multiprocessing lock for any bar, a disabled one too: a named semaphore that the resource
    # tracker reported as leaked, on stderr after "interrupted", when a stopped worker left by os._exit
    from tqdm import tqdm
    tqdm.set_lock(threading.RLock())


def _stop(signum, frame):
    """SIGTERM in a worker: once. The group's and the parent's both come, and a second SystemExit would cut the
    render's cleanup short, leaving its partial files."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    sys.exit(143)


def _render_in_worker(*args):
    """render_one in a pool's worker: stopped by SIGTERM, it exits once the render has removed its partial
    files. The pool's worker loop catches the SystemExit of a task and waits for the next one, which never
    comes: the parent then waited for that worker forever."""
    try:
        return render_one(*args)
    except SystemExit:
        os._exit(143)


def run_local(scenes, out_root, jobs, arch, threads, digest, progress):
    """Yield result rows as renders finish: in this process for one job, else in spawned workers."""
    if jobs == 1:
        for scene in scenes:
            yield render_one(scene, str(out_root), arch, threads, digest, progress)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed
    pool = ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("spawn"), initializer=_worker_init)
    try:
        futs = {pool.submit(_render_in_worker, s, str(out_root), arch, threads, digest): s for s in scenes}
        for fut in as_completed(futs):
            try:
                yield fut.result()
            except Exception as e:  # noqa: BLE001 - e.g. a worker killed by the OS
                yield {"preset": futs[fut].name, "status": "failed",
                       "error": f"worker died: {str(e) or type(e).__name__}"}
    except BaseException:
        procs = list((getattr(pool, "_processes", None) or {}).values())
        for proc in procs:
            proc.terminate()  # no public API stops running tasks; SIGTERM lets each clean up its partials
        for proc in procs:
            proc.join(STOP_S)
            if proc.is_alive():  # stuck: its temporaries are swept by the next write into its folder
                proc.kill()
                proc.join()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def run_dask(scenes, out_root, address, arch, threads, digest):
    """Yield result rows as Dask tasks finish; outputs are written by the workers into out_root."""
    from dask.distributed import as_completed
    with quiet():  # a lost scheduler: its tasks' rows say so, not distributed's tracebacks
        client = connect(address)
        futs = {}
        try:
            for s in scenes:
                fut = client.submit(render_one, s, str(out_root), arch, threads, digest, pure=False,
                                    key=f"pendulum-render-{s.name}-{os.urandom(4).hex()}")
                futs[fut] = s
            for fut in as_completed(list(futs), loop=client.loop):
                try:
                    yield fut.result()
                except Exception as e:  # noqa: BLE001 - e.g. KilledWorker
                    yield {"preset": futs[fut].name, "status": "failed", "error": f"{type(e).__name__}: {e}"}
        finally:
            client.cancel(list(futs))  # a no-op for finished tasks; stops queued ones when we are interrupted
            close(client)


# ---------------------------------------------------------------- the command


def run(args) -> int:
    t0 = time.perf_counter()
    address = scheduler_address(args.scheduler) if args.scheduler is not None else env_address()
    jobs_plan = plan(expand_refs(args.presets), args.overrides, parse_sweeps(args.sweep), args.quality)
    check_writable(args.out)
    for own in ("batch.json", "index.html"):  # written last, after every render: refused before the first
        check_replaceable(args.out / own)
    out_root = args.out.resolve()  # absolute: Dask workers may run elsewhere with another cwd
    cores = usable_cores()
    rows: dict[str, dict] = {}
    todo = []
    for job in jobs_plan:
        if "scene" in job:
            try:  # where each render writes and what it costs, refused before any work as a bad preset is
                job["scene"] = budgeted(job["scene"], args)
                api.check_render([job["scene"]], out_root)  # what `render` refuses, e.g. OUT/NAME a symlink
            except SceneError as e:
                job["error"] = str(e)
        if "error" in job:
            rows[job["name"]] = {"preset": job["name"], "status": "failed", "error": job["error"]}
        elif not args.force and (meta := gallery.up_to_date(job["scene"], out_root)):
            rows[job["name"]] = gallery.row_from_meta(job["name"], "skipped", meta, None)
        else:
            todo.append(job["scene"])
    if not todo and all(r["status"] == "failed" for r in rows.values()):
        # nothing can run: bad input as a lone render's would be (exit 2, nothing written), not a batch that failed
        first = rows[jobs_plan[0]["name"]]["error"]
        more = f" (and {len(jobs_plan) - 1} more preset(s) refused likewise)" if len(jobs_plan) > 1 else ""
        raise SceneError(f"{first}{more}")
    if todo:
        budget.check_run(todo, out_root)  # the renders to do, summed: refused together before the first
    n, done = len(jobs_plan), 0

    def report(row):
        nonlocal done
        done += 1
        rows[row["preset"]] = row
        if not args.no_progress:
            wall = f" in {row['wall_s']:.1f}s" if row.get("wall_s") is not None else ""
            err = f": {row['error']}" if row["status"] == "failed" else ""
            print(f"[{done}/{n}] {row['preset']}: {row['status']}{wall}{err}", file=sys.stderr, flush=True)

    for row in list(rows.values()):
        report(row)
    jobs = min(args.jobs or cores, max(1, len(todo)))  # no idle workers to spawn
    mode = f"dask {address}" if address else f"local, {args.jobs or cores} job(s)"
    if todo:
        if address:
            results = run_dask(todo, out_root, address, args.arch, args.threads, args.digest)
        else:
            # Workers share the cores: a Taichi pool per worker sized to its share avoids oversubscription.
            threads = args.threads or (max(1, cores // jobs) if jobs > 1 else None)
            results = run_local(todo, out_root, jobs, args.arch, threads, args.digest,
                                jobs == 1 and progress_wanted(args))
        try:
            with output_dir(out_root):  # made here, not by the first worker: removed again if stopped while empty
                for row in results:
                    report(row)
        except BatchError as e:
            print(f"pendulum: failed: {e}", file=sys.stderr)
            return 1
    if address:
        folders = {j["name"]: j["scene"].out_dir(out_root) for j in jobs_plan if "scene" in j}
        for name, row in rows.items():
            if row["status"] == "ok" and not (folders[name] / "metadata.json").is_file():
                print(f"warning: {name} was rendered but {folders[name]} is not visible here; --out must be "
                      f"a directory shared by this machine and the workers", file=sys.stderr)
    ordered = [rows[j["name"]] for j in jobs_plan]
    wall = time.perf_counter() - t0
    record = {"package": __version__, "mode": mode, "wall_s": round(wall, 3), "results": ordered}
    out_root.mkdir(parents=True, exist_ok=True)  # absent when nothing rendered, e.g. every preset was bad
    write_atomic(out_root / "batch.json", json.dumps(record, indent=2) + "\n")
    index = gallery.write_index(out_root, [(r["preset"], r["error"]) for r in ordered if r["status"] == "failed"])
    print(gallery.summary_table(ordered))
    counts = {s: sum(r["status"] == s for r in ordered) for s in ("ok", "skipped", "failed")}
    print(f"{n} preset(s): {counts['ok']} ok, {counts['skipped']} skipped, {counts['failed']} failed "
          f"in {wall:.1f}s ({mode}) -> {index}")
    return 1 if counts["failed"] else 0

