"""How long Taichi holds Python's GIL in a render's frames: whether another Python thread could work beside them.

    .venv/bin/python benchmarks/gil_hold.py [PRESET] [--frames 60] [--warm]

Builds PRESET's frames as `pendulum render` does (pipeline.open_source, and the GIF's own frames, gif.Frames)
while a second Python thread spins, noting how long it waits between two turns. Python threads take turns every
sys.getswitchinterval(), set to 0.2 ms here, so a wait over STALL_MS is a stretch where the main thread held
the GIL without giving it up: Taichi's compiling or running a kernel (its Python bindings do not release it).
Printed for the video's first frame (its canvas's kernels through Taichi's front end, the offline cache and a
first launch), the GIF's first (the same for the GIF's canvas), and the steady frames after them: each one's
wall time, the time held in such stretches, and the longest. The wall times include the spinner's turns: the
rest of each is Python (the front end, the launches' arguments), which needs the GIL anyway, so with the spinner
the first frames take about twice what they take alone (render_threads.py's slowest calls).

So a thread cannot compile the GIF's canvas beside the video's first frames, nor draw beside the simulation;
only work outside Python and Taichi (ffmpeg, a pipe's write) runs beside them. --warm renders one frame first,
as `pendulum bench` does before its timed render.
"""
import argparse
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.config.scene import load  # noqa: E402
from render.video import gif, pipeline  # noqa: E402

SWITCH_S = 0.0002  # Python's thread switch interval while measuring (its default is 5 ms)
STALL_MS = 1.0  # a wait longer than this, five switch intervals, is the GIL held by one call


class Spinner:
    """A Python thread that notes every wait between its turns longer than STALL_MS, with when it ended."""

    def __init__(self):
        self.stalls: list[tuple[float, float]] = []  # (end, length) in perf_counter seconds
        self.stop = False
        self.thread = threading.Thread(target=self.spin, daemon=True)

    def spin(self):
        last = time.perf_counter()
        while not self.stop:
            now = time.perf_counter()
            if now - last > STALL_MS / 1e3:
                self.stalls.append((now, now - last))
            last = now

    def held(self, t0: float, t1: float) -> tuple[float, float]:
        """The stalls that ended within [t0, t1]: their total and the longest, in ms."""
        inside = [length for end, length in self.stalls if t0 <= end <= t1]
        return 1e3 * sum(inside), 1e3 * max(inside, default=0.0)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--frames", type=int, default=60, help="frames timed (default 60)")
    ap.add_argument("--warm", action="store_true", help="render one frame first, as pendulum bench does")
    args = ap.parse_args(argv)
    if args.frames < 2:
        ap.error("--frames: at least 2 (the first frames, then the steady ones)")
    scene = load(args.preset)
    if args.warm:
        with tempfile.TemporaryDirectory() as tmp:
            pipeline.render(scene.replace(video={"duration": 1.0 / scene.video.fps}), Path(tmp))
    src = pipeline.open_source(scene)
    small = gif.Frames(src, src.scene.video, src.timings) if "gif" in src.scene.video.formats else None
    spinner = Spinner()
    sys.setswitchinterval(SWITCH_S)
    spinner.thread.start()
    rows = []  # (what, wall ms, held ms, longest ms)
    steady = [0.0, 0.0, 0.0, 0]  # over the steady frames: wall ms, held ms, the longest, how many
    for f in range(min(args.frames, src.frames)):
        t0 = time.perf_counter()
        frame = src.next_frame()
        t1 = time.perf_counter()
        gif_frame = small.frame(f, frame) if small else None
        t2 = time.perf_counter()
        if f == 0:
            rows.append(("video's first frame", 1e3 * (t1 - t0), *spinner.held(t0, t1)))
        if small and small.own is not None and gif_frame is not None and len(rows) == 1:
            rows.append(("GIF's first frame", 1e3 * (t2 - t1), *spinner.held(t1, t2)))
        elif f > 0:
            held, longest = spinner.held(t0, t2)
            steady = [steady[0] + 1e3 * (t2 - t0), steady[1] + held, max(steady[2], longest), steady[3] + 1]
    spinner.stop = True
    spinner.thread.join()
    n = max(steady[3], 1)
    rows.append((f"a steady frame, video and GIF (mean of {steady[3]})", steady[0] / n, steady[1] / n, steady[2]))
    print(f"{args.preset}: the GIL held in stretches over {STALL_MS:g} ms (switch interval {SWITCH_S * 1e3:g} ms)")
    print("| what | wall ms | held ms | longest ms |\n|---|---:|---:|---:|")
    for what, wall, held, longest in rows:
        print(f"| {what} | {wall:.1f} | {held:.1f} | {longest:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
