"""`pendulum show`: a live window playing a preset, frame for frame what `pendulum render` encodes.

Three parts, kept apart so each can change alone:

- a **frame source** (the `FrameSource` protocol, render/commands/player.py) produces the frames: `pipeline.Source`, the very
  object `pendulum render` draws its frames with;
- a **Player** (render/commands/player.py) decides what the keys do and when the next frame is due. It knows nothing of windows, so it is
  tested without a display;
- the **window** (render/commands/window.py) is Taichi's legacy `ti.GUI` (X11; GGUI would need Vulkan). Frames
  are copied straight into its pixel buffer, so the window shows the video's pixels exactly, unscaled.

A map preset (one with `fractal`) is explored instead of only played: render/commands/explore.py.

Keys: space pauses and resumes (at the end it plays again from the start), → shows exactly one more frame
(and pauses), r restarts from t = 0, s saves the frame on screen as OUT/NAME/NAME_frame_<index>.png, q or Esc
(or closing the window) quits with exit 0. Playback is paced at the preset's fps, or as fast as frames come
when they come slower. At the end of the video the last frame stays up.

Without an X display the command exits 2 with one line that suggests `pendulum render`, before anything is
compiled (window.check_display).
"""
from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path

from . import api
from ..video import pipeline
from ..config import budget
from ..config.options import (add_budget, add_common, add_quality, budgeted, out_path, output_name,
                              thread_count)
from ..config.scene import load
from .player import KEYS_HELP, FrameSource, Player, png_bytes, saves_to, say  # noqa: F401 - png_bytes: for tests
from .window import DISPLAY_TIMEOUT_S, Window, check_display  # noqa: F401 - the display timeout is show's to tell


def play(source: FrameSource, fps: float, folder, suggest: str, log=say, on_open=None) -> int:
    """Open the window and run until q/Esc or the window closes; returns the exit code. folder(): where s
    saves (player.saves_to)."""
    player = Player(source, fps, folder)
    win = Window(f"pendulum show: {source.name}", *player.frame.shape[1::-1], suggest=suggest)
    if on_open:
        on_open()
    try:
        log(f"{source.name}: {source.frames} frames at {fps:g} fps | {KEYS_HELP}")
        while win.open and not player.quit:
            for key in win.keys():
                msg = player.key(key)
                if msg:
                    log(msg)
                if player.quit:
                    break
            player.tick(player.clock())
            if player.changed:
                win.blit(player.frame)
                player.changed = False
            win.update()
            time.sleep(player.wait(player.clock()))
    finally:
        win.close()
    return 0


# ------------------------------------------------------------------ CLI
def add_parser(sub):
    s = sub.add_parser(
        "show", help="play a preset live in a window (space, →, r, s, q)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Play PRESET in a window, frame for frame what `pendulum render` writes, drawn by the\n"
                    "same canvas and paced at the preset's fps. Needs an X display (DISPLAY); without one it\n"
                    "exits 2 and suggests the `pendulum render` command instead.",
        epilog="keys:\n"
               "  space     pause / play (at the end: play again from the start)\n"
               "  →         one frame more, and pause\n"
               "  r         restart from t = 0\n"
               "  s         save the frame (without the inset and captions) where `pendulum render` writes\n"
               "            this scene: OUT/NAME/NAME_frame_<index>.png (OUT/NAME__<hash>/ with --set,\n"
               "            --quality or after a zoom; OUT/compare/NAME/ for a comparison)\n"
               "  q, Esc    quit (so does closing the window)\n"
               "At the end of the video the last frame stays up.\n"
               "A map (a preset with `fractal`) is explored with the mouse:\n"
               "  hover     the title row shows the pixel's start and value\n"
               "  click     an inset plays that pixel's pendulum\n"
               "  drag      zoom into the box (the map is recomputed; in f64 where f32 cannot resolve it)\n"
               "  b, BackSpace  close the inset, else back to the axes before the last zoom")
    s.add_argument("preset", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    add_common(s)
    s.add_argument("--out", type=out_path, default=Path("out"), help="where s saves frames (default: out)")
    add_quality(s)
    add_budget(s)
    s.add_argument("--threads", type=thread_count, default=None, help="CPU threads for Taichi (default: all cores)")
    s.set_defaults(func=run)


def render_command(args) -> str:
    """The `pendulum render` line that writes what this `show` would have played."""
    parts = ["pendulum", "render", args.preset]
    for o in args.overrides:
        parts += ["--set", o]
    if args.quality:
        parts += ["--quality", args.quality]
    if args.arch != "cpu":
        parts += ["--arch", args.arch]
    if getattr(args, "budget", None) is not None:
        parts += ["--budget", f"{args.budget:g}"]
    if args.out != Path("out"):
        parts += ["--out", str(args.out)]
    return shlex.join(parts)


def run(args) -> int:
    # frames saved with s go where `render` would write this scene: OUT/NAME__<hash>/ when overridden, and
    # never through a symlink or into a file (checked before the window opens, as render checks)
    loaded = load(args.preset, args.overrides, args.quality)
    scene = output_name(loaded, bool(args.overrides or args.quality))
    scene = budgeted(scene, args)
    # what `render` refuses, `show` refuses too: it simulates and certifies the same (a comparison records its
    # variants whole before the window opens), so panels, spectra, memory and time are those of a render
    api.check_render([scene], args.out, files=())
    estimate = budget.check_run([scene], args.out, say=False)
    suggest = render_command(args)
    probe = check_display(suggest)  # before any compiling: a missing display fails at once, its one line alone
    if estimate:
        print(estimate, file=sys.stderr, flush=True)
    try:
        if scene.fractal:  # a map to explore: click, zoom, back (render/commands/explore.py)
            from .explore import explore
            return explore(scene, args.arch, args.threads, args.out, suggest, on_open=probe.close, name=loaded.name)
        source = pipeline.open_source(scene, arch=args.arch, threads=args.threads)  # a comparison: split screen
        return play(source, scene.video.fps, saves_to(scene, args.out), suggest, on_open=probe.close)
    finally:
        probe.close()
