"""Where a whole render's main thread spends its time: each stage of pipeline.render's frame loop timed in wall
time and in this thread's CPU time, so that waiting (on x264's pipe, or for a core x264 holds) shows apart
from work.

    .venv/bin/python benchmarks/render_threads.py [PRESET] [--warm] [--x264-preset P] [--set KEY=VALUE]...

Renders PRESET (default rigid_chaos) into a temporary folder as `pendulum render` does, with a timer around
Source.next_frame (simulate and draw the video's frame, its HUD included), gif.Frames.frame (the GIF's own
frame), Hud.draw (within both), yuv.convert (the MP4's yuv420p), the rest of Encoder.write (handing frames
to the pipes: its wall time beyond its CPU time is waiting on an encoder) and Encoder.close (after the last
frame). The stages nest: the frames' figures include the HUD's, write's the conversion's. Kernels compiled
on a first run are in the first run's figures. Each stage's slowest call, and which call it was, shows where
each new object's kernels first go through Taichi's front end and the cache (the GIF's canvas: at its first
frame, the video's second).

Then the render's timeline, in seconds from its start: when the first frame reached the Encoder, when the
last one had been handed over, when each ffmpeg process exited (x264's first, then the GIF's palettegen;
the GIF's writer and the audio's mux come after) and when the render returned. --warm renders one frame
first, in the same process, as `pendulum bench` does before its timed render (Taichi started, its kernels
loaded). --x264-preset renders with another of x264's presets than render/video/mp4.py's PRESET (the same
crf), to see what the encoder's speed does to the whole render.
"""
import argparse
import collections
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from render.config.scene import load  # noqa: E402
from render.draw.hud import Hud  # noqa: E402
from render.video import encode, gif, mp4, pipeline, yuv  # noqa: E402

STAGES = [(pipeline.Source, "next_frame", "video frame (simulate + draw + HUD)"),
          (gif.Frames, "frame", "GIF frame"),
          (Hud, "draw", "HUD (the video's and the GIF's frames)"),
          (yuv, "convert", "yuv420p conversion"),
          (encode.Encoder, "write", "Encoder.write (conversion included)"),
          (encode.Encoder, "close", "Encoder.close")]


def timed(fn, totals):
    """fn, adding its wall and CPU time to totals[0:2], counting calls in totals[2], and keeping its slowest
    call as (wall, call number) in totals[3]: a kernel's first launch (front end, cache) shows there."""
    def wrapper(*args, **kwargs):
        wall, cpu = time.perf_counter(), time.thread_time()
        try:
            return fn(*args, **kwargs)
        finally:
            took = time.perf_counter() - wall
            totals[0] += took
            totals[1] += time.thread_time() - cpu
            totals[2] += 1
            totals[3] = max(totals[3], (took, totals[2]))
    return wrapper


def timeline(marks: dict):
    """Wrap the Encoder so that the render's milestones go into marks (name -> perf_counter time)."""
    write, close = encode.Encoder.write, encode.Encoder.close

    def timed_write(self, *args, **kwargs):
        marks.setdefault("first frame handed to the Encoder", time.perf_counter())
        try:
            return write(self, *args, **kwargs)
        finally:
            marks["last frame handed over"] = time.perf_counter()

    def timed_close(self, *args, **kwargs):
        def exited(proc, name):
            proc.wait()
            marks[f"{name} exited"] = time.perf_counter()

        for t in self.targets:
            name = f"ffmpeg for {t.final.name}" + (" (palettegen)" if t.kept is not None else "")
            threading.Thread(target=exited, args=(t.proc, name), daemon=True).start()
        return close(self, *args, **kwargs)

    encode.Encoder.write, encode.Encoder.close = timed_write, timed_close


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--warm", action="store_true", help="render one frame first, as pendulum bench does")
    ap.add_argument("--x264-preset", choices=["ultrafast", "superfast", "veryfast", "faster", "fast", "medium"],
                    help=f"x264's preset for the MP4 (default: the render's, {mp4.PRESET})")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    mp4.PRESET = args.x264_preset or mp4.PRESET
    scene = load(args.preset, args.overrides)
    with tempfile.TemporaryDirectory(prefix="render-threads-") as tmp:
        if args.warm:
            pipeline.render(scene.replace(video={"duration": 1.0 / scene.video.fps}), Path(tmp) / "warm")
        stats, marks = collections.defaultdict(lambda: [0.0, 0.0, 0, (0.0, 0)]), {}
        for owner, name, label in STAGES:
            setattr(owner, name, timed(getattr(owner, name), stats[label]))
        timeline(marks)
        wall, cpu = time.perf_counter(), time.process_time()
        meta = pipeline.render(scene, Path(tmp))
        marks["render returned"] = end = time.perf_counter()
        wall, cpu = end - wall, time.process_time() - cpu
    print(f"{args.preset} (x264 {mp4.PRESET}): pipeline.render {wall:.2f} s wall, {cpu:.2f} s CPU of this process (all its threads)")
    print(f"timings_s: {meta['timings_s']}")
    print("| stage | calls | wall s | main thread CPU s | wall ms a call | slowest call ms (its number) |\n"
          "|---|---:|---:|---:|---:|---:|")
    for _, _, label in STAGES:
        w, c, n, (slow, which) = stats[label]
        print(f"| {label} | {n} | {w:.2f} | {c:.2f} | {1e3 * w / max(n, 1):.2f} | {1e3 * slow:.1f} ({which}) |")
    start = end - wall
    print("timeline, s from the render's start: " + ", ".join(
        f"{k} {v - start:.2f}" for k, v in sorted(marks.items(), key=lambda kv: kv[1])))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
