"""What the `audio` effect's track costs (render/video/audio.py): made whole, and made as the frames come.

    .venv/bin/python benchmarks/audio_track.py [PRESET] [--rounds 6] [--chunks 2 4 8]

Takes the heard pendulums' angles at every frame of PRESET (default rigid_chaos) from pipeline.record, picked as
audio.Voices picks them, then, in interleaved rounds, for each chunk size (audio.CHUNK_FRAMES):
- `whole`: synthesise(), the whole track at once;
- `fed`: a Track fed one frame at a time as a render feeds it, timing the adds and finish() apart: finish() is
  what is left after the last frame, while the MP4's track waits for it.
Prints each one's range over the rounds in seconds, checks that every chunk size gives the same samples to the
bit, and gives the peak of Python's allocations (tracemalloc) while a Track is fed and finished, against
audio.peak_bytes(), which render/config/budget.py counts.
"""
import argparse
import os
import sys
import time
import tracemalloc
from pathlib import Path

os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

from render.config.scene import load  # noqa: E402
from render.video import audio, pipeline  # noqa: E402


def heard_angles(scene) -> np.ndarray:
    """(frames, voices, 2): the first two coordinates of the pendulums audio.Voices hears, at every frame."""
    q = pipeline.record(scene)["q"]
    picks = np.unique(np.linspace(0, q.shape[1] - 1, min(audio.VOICES, q.shape[1])).round().astype(np.int64))
    return np.ascontiguousarray(q[:, picks, :2])


def fed(angles: np.ndarray, fps: int) -> tuple[float, float, np.ndarray]:
    """(s in add(), s in finish(), samples) for a Track fed frame by frame."""
    track = audio.Track(len(angles), angles.shape[1], fps)
    t = time.perf_counter()
    for f in range(len(angles)):
        track.add(angles[f:f + 1])
    adds = time.perf_counter() - t
    t = time.perf_counter()
    samples = track.finish()[1]
    return adds, time.perf_counter() - t, samples


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("preset", nargs="?", default="rigid_chaos")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--chunks", type=int, nargs="+", default=[audio.CHUNK_FRAMES])
    args = ap.parse_args(argv)
    scene = load(args.preset, [])
    fps, angles = scene.video.fps, heard_angles(scene)
    print(f"{args.preset}: {len(angles)} frames, {angles.shape[1]} voices")
    times = {(c, k): [] for c in args.chunks for k in ("whole", "fed: adds", "fed: finish")}
    reference = None
    for _ in range(args.rounds):
        for chunk in args.chunks:
            audio.CHUNK_FRAMES = chunk
            t = time.perf_counter()
            whole = audio.synthesise(angles, fps)[1]
            times[chunk, "whole"].append(time.perf_counter() - t)
            adds, finish, samples = fed(angles, fps)
            times[chunk, "fed: adds"].append(adds)
            times[chunk, "fed: finish"].append(finish)
            reference = whole if reference is None else reference
            if not (np.array_equal(whole, reference) and np.array_equal(samples, reference)):
                print(f"chunks of {chunk}: the samples differ", file=sys.stderr)
                return 1
    for (chunk, kind), s in times.items():
        print(f"chunks of {chunk} frames, {kind}: {min(s):.3f}-{max(s):.3f} s over {len(s)} rounds")
    audio.CHUNK_FRAMES = args.chunks[0]
    tracemalloc.start()
    fed(angles, fps)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    print(f"the same samples at every chunk size; chunks of {args.chunks[0]}: allocations peak at "
          f"{peak / 1e6:.1f} MB fed and finished, audio.peak_bytes() {audio.peak_bytes(scene) / 1e6:.1f} MB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
