"""One phase of `pendulum bench` in its own process, and the peak memory of that process and its children.

Apart from render/commands/bench/command.py, which chooses and times the phases: a phase runs as a fresh Taichi runtime
(`python -m render bench --phase NAME`), and what it costs in memory is read from outside it, from /proc, since
its ffmpeg children count too.
"""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from ...errors import SimulationError


def run_phase(name: str, args, tmp: Path) -> dict:
    """One phase in a subprocess; its result plus the peak resident memory of its process tree, and `compiled`,
    how many kernels it compiled (Taichi's offline cache gained a file: it writes them when the process ends).
    Then, unless --quick (a smoke run), the phase runs once more and that run is kept (`rerun`): its warm-ups
    cannot load what the timed part compiles, since a kernel's cache key holds every field made before it in
    the process (render/commands/bench/e2e.py)."""
    before = cached_kernels(args.arch)
    out = _run_phase(name, args, tmp)
    compiled = len(cached_kernels(args.arch) - before)
    rerun = bool(compiled) and not args.quick
    if rerun:
        print(f"bench: {name} compiled {compiled} kernels; again, with them cached ...", file=sys.stderr, flush=True)
        out = _run_phase(name, args, tmp)
    return {**out, "compiled": compiled, "rerun": rerun}


def cached_kernels(arch: str) -> set[str]:
    """The kernels in the offline cache folders the phases' processes on `arch` use: their width's, and the FTLE
    map's where it takes another (empty where none exists yet). Counting the first alone, the FTLE phase's
    compiles went unseen, and its timed render compiled: 4.03 s of simulation for 30 frames, against 3.18 s with
    them cached (runs D and E, docs/performance.md)."""
    from ...physics import vector_width
    found = set()
    for folder in {vector_width.cache_folder(arch), vector_width.cache_folder(arch, tangents=True)}:
        try:
            found |= {os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".tic")}
        except OSError:
            pass
    return found


def _run_phase(name: str, args, tmp: Path) -> dict:
    result = tmp / f"{name}.json"
    cmd = [sys.executable, "-m", "render", "bench", "--phase", name, "--result", str(result), "--out", str(tmp),
           "--arch", args.arch] + (["--quick"] if args.quick else []) + (
           ["--repeat", str(args.repeat)] if args.repeat is not None else [])
    proc, peak = subprocess.Popen(cmd, stdout=subprocess.DEVNULL), 0
    try:  # the sum over the tree at one instant, which ru_maxrss (the largest single process) cannot give
        while proc.poll() is None:
            peak = max(peak, tree_rss(proc.pid))
            time.sleep(0.05)
    finally:
        if proc.poll() is None:  # interrupted: do not leave the phase running
            proc.terminate()
            proc.wait()
    code = proc.returncode
    if code != 0:
        raise SimulationError(f"bench phase {name!r} failed (exit {code}); see the messages above")
    out = json.loads(result.read_text())
    out["peak_mem_mb"] = max(peak / 2**20, out.pop("maxrss_mb"))  # /proc may be missing, or miss a spike
    return out


def tree_rss(pid: int) -> int:
    """Resident bytes of a process and all its descendants (Linux /proc; 0 elsewhere)."""
    total, todo, page = 0, [pid], os.sysconf("SC_PAGE_SIZE")
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/statm") as f:
                total += int(f.read().split()[1]) * page
            for tid in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{tid}/children") as f:
                    todo += [int(c) for c in f.read().split()]
        except (OSError, ValueError):
            pass
    return total


def maxrss_mb() -> float:  # the largest single process: this phase, or one of its ffmpeg children
    import resource
    return max(resource.getrusage(w).ru_maxrss for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)) / 1024
