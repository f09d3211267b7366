"""What a render pays besides its frames: one-frame renders of a preset, one after another in one process.

    .venv/bin/python benchmarks/fixed_cost.py [PRESET] [--renders N]

`pendulum bench` times the same thing once (end_to_end_fixed_s: a one-frame render after the timed ones). Each
render builds its canvases, HUD and system afresh, so Taichi's front end turns their kernels into IR again
(render/physics/frontend.py) and each kernel's first launch loads it from the offline cache. Printed per render:
its wall time, the time in Taichi's Kernel.materialize (the front end) and in the kernels' first launches
through Taichi (loading, then running once), and the process's peak resident memory. The first render also pays
Taichi's start. Run it twice: the first run of a process history compiles what the cache lacks (with --renders 8,
every render from the fifth on, the first time: docs/performance-log.md, the twentieth session).
"""
import argparse
import collections
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from taichi.lang import kernel_impl  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.video import pipeline  # noqa: E402

spent = collections.Counter()


def timed(name: str, method):
    def run(*args, **kwargs):
        t = time.perf_counter()
        try:
            return method(*args, **kwargs)
        finally:
            spent[name] += time.perf_counter() - t
    return run


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--renders", type=int, default=4)
    args = ap.parse_args(argv)
    kernel_impl.Kernel.materialize = timed("front end", kernel_impl.Kernel.materialize)
    kernel_impl.Kernel.launch_kernel = timed("first launches", kernel_impl.Kernel.launch_kernel)
    scene = load(args.preset, [])
    one = scene.replace(video={"duration": 1.0 / scene.video.fps})
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.renders):
            spent.clear()
            t = time.perf_counter()
            pipeline.render(one, Path(tmp))
            print(f"render {r}: {time.perf_counter() - t:.3f} s, front end {spent['front end']:.3f} s, "
                  f"first launches {spent['first launches']:.3f} s, peak memory "
                  f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
