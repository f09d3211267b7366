"""The `pendulum` command. Exit codes: 0 ok, 1 failure while running, 2 bad input, 130/143 interrupted.

Whatever goes wrong, the user reads one line on stderr, never a traceback: bad input is exit 2, a failure
while running (the watchdog, ffmpeg, a full disk, or an error nobody foresaw) exit 1. `--debug` or
PENDULUM_DEBUG=1 prints the traceback as well.
"""
from __future__ import annotations

import _thread
import argparse
import importlib
import os
import signal
import sys
import time
import traceback
from pathlib import Path

from ..errors import BatchError, EncodeError, SceneError, SimulationError
from ..config.options import (add_budget, add_common, add_quality, add_render_options, add_tiles, budgeted, check_npz,
                              out_path, output_name, progress_wanted)

# Subcommands living in their own modules: command -> (module, the line `pendulum --help` lists it with). Each
# module has add_parser(subparsers) and run(args) -> exit code. Only the module of the command given is imported:
# most of them import Taichi or scipy (a second and more before anything runs), which `pendulum --help` and a
# mistyped command have no use for. So this module and what it imports at the top stay light, and the heavy
# imports are inside the functions that use them. tests/test_start.py checks that --help imports neither, and
# that each line here is the one its module gives.
COMMANDS = {
    "accuracy": ("accuracy", "measure error vs. time of every integrator; charts and tables"),
    "batch": ("batch", "render many presets (default: all) in parallel, locally or on Dask"),
    "bench": ("bench.command", "performance report: simulate, draw, encode, end to end, fractal, peers"),
    "compare": ("comparison", "one split-screen video of 2 to 4 variants of a preset (OUT/compare/NAME/)"),
    "gallery": ("gallery", "write OUT/index.html: every render in OUT with its video and certificate"),
    "lyapunov": ("lyapunov_cli", "the Lyapunov spectrum of chosen pendulums (OUT/NAME/lyapunov.json)"),
    "show": ("show", "play a preset live in a window (space, →, r, s, q)"),
}


class Terminated(BaseException):
    """SIGTERM (or SIGHUP: the terminal closed), turned into an exception so every `finally`/cleanup runs."""

    def __init__(self, signum: int = signal.SIGTERM):
        super().__init__(signum)
        self.signum = signum


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage too by default)
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see --help)\n")


def build_parser(argv=()) -> argparse.ArgumentParser:
    """The parser for the command line `argv`: complete for the command it gives, the others only listed."""
    p = Parser(prog="pendulum", description="Double-pendulum presets to MP4 and GIF, simulated with Taichi.",
               epilog="Presets: `pendulum presets` lists them. Your own are found in the folders of "
                      "$PENDULUM_PRESETS, then in ./presets/, before those shipped with the package; their "
                      "format: docs/presets.md in the repository.")
    p.add_argument("--debug", action="store_true", help="on an error, print the traceback too "
                   "(or set PENDULUM_DEBUG=1)")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)

    r = sub.add_parser("render", help="render presets to out/NAME/ (MP4, GIF, metadata.json)",
                       description="Simulate each preset, draw every frame offscreen and encode MP4 and GIF "
                                   "into OUT/NAME/ with a metadata.json. OUT/NAME/ is only ever the preset as "
                                   "written: with --set or --quality the render goes to OUT/NAME__<short hash of "
                                   "the resolved scene>/ (or the folder --name gives), and says where. A preset "
                                   "with a [compare] table renders its split-screen comparison into "
                                   "OUT/compare/NAME/ (see `pendulum compare`).")
    r.add_argument("presets", nargs="+", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    add_render_options(r)
    add_tiles(r)
    r.set_defaults(func=cmd_render)

    s = sub.add_parser("simulate", help="simulate without drawing; write the state at every frame to .npz",
                       description="Write t, the state (theta/omega or pos/vel) and energy at every frame time.")
    s.add_argument("preset", metavar="PRESET", help="a name from presets/ or a path to a .toml file")
    s.add_argument("--out", type=out_path, required=True, metavar="FILE.npz",
                   help="the trajectory file to write (its folder is made; written whole or not at all)")
    add_common(s)
    add_quality(s)
    add_budget(s)
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_simulate)

    ls = sub.add_parser("presets", help="list the presets, one line each",
                        description="List every preset on the search path ($PENDULUM_PRESETS, ./presets/, then "
                                    "the shipped ones; the first of a name wins): its name, system and "
                                    "description, one line each.")
    ls.set_defaults(func=cmd_presets)

    given = next((a for a in argv if not a.startswith("-")), None)  # before it come only flags (--debug, -h)
    for command, (module, line) in COMMANDS.items():
        if command == given:
            importlib.import_module(f"{__package__}.{module}").add_parser(sub)
        else:
            sub.add_parser(command, help=line)
    for command in sub.choices.values():  # --debug also after the command; main() reads it from argv
        command.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                             help="on an error, print the traceback too (or set PENDULUM_DEBUG=1)")
    return p


def load_preset(preset: str, args):
    """The preset under the command line's --set, --quality and --budget (api.load's, which needs no Taichi).
    The commands load their scenes before they import the API: its renderer imports Taichi, which a preset
    refused (exit 2) has no use for (tests/test_start.py)."""
    from ..config.scene import load

    return budgeted(load(preset, args.overrides, args.quality), args)


def cmd_render(args) -> int:
    from ..video.tiled import ENV, env_address, scheduler_address

    address = scheduler_address(args.scheduler)  # a bad one before any work
    scenes = [load_preset(p, args) for p in args.presets]  # all first
    if args.name and len(scenes) > 1:
        raise SceneError(f"--name {args.name}: names one render's folder; give one PRESET")
    overridden = bool(args.overrides or args.quality)  # then not OUT/NAME/, which is the preset as written
    scenes = distinct([output_name(s, overridden, args.name) for s in scenes], args.out)
    from . import api
    from ..config import budget

    # as for `batch`, Dask's own variable names the cluster: for the maps, which alone can be tiled; checked, with
    # what it asks of each map, before the first render as --scheduler is
    from_env = env_address() if not address and any(s.fractal for s in scenes) else None
    clusters = [address or (from_env if scene.fractal else None) for scene in scenes]
    for scene, cluster in zip(scenes, clusters):  # every scene's refusals before the first render
        how = "--scheduler" if address else f"${ENV}" if cluster else "--tiles" if args.tiles else None
        api.check_render([scene], args.out, how)
    budget.check_run(scenes, args.out)  # and their sum's; the estimate, when over a minute
    for scene, cluster in zip(scenes, clusters):
        result = api.render(scene, args.out, arch=args.arch, progress=progress_wanted(args), threads=args.threads,
                            scheduler=cluster, tiles=args.tiles)
        print(result.line())
    return 0


def distinct(scenes: list, out: Path) -> list:
    """The scenes once each; two files with the same name would overwrite one render with the other."""
    seen = {}
    for scene in scenes:
        other = seen.setdefault(scene.name, scene)
        if other.source != scene.source:
            raise SceneError(f"{other.source} and {scene.source}: name: both are {scene.name!r}, so both would "
                             f"render to {out / scene.name}/; rename one (name = \"...\")")
    return list(seen.values())


def cmd_simulate(args) -> int:
    scene = load_preset(args.preset, args)
    from . import api
    from ..config import budget

    check_npz(args.out, scene.name)
    budget.check_run([scene], args.out.parent, simulate=True)  # the estimate, when over a minute
    traj = api.simulate(scene, args.out, arch=args.arch, progress=progress_wanted(args))
    print(f"{scene.name}: {traj.info['frames']} frames, {traj.info['line']} -> {args.out}")
    return 0


def cmd_presets(args) -> int:
    from ..config.scene import list_presets, load

    paths = list_presets()
    width = max((len(p.stem) for p in paths), default=0)  # the names' column as wide as the longest
    for path in paths:
        try:
            s = load(str(path))
            print(f"{s.name:{width}s} {s.system:8s} N={s.pendulums.count:<8d} {s.description}")
        except SceneError as e:
            print(f"{path.stem:{width}s} INVALID  {e}")
    return 0


# Distributions whose import name differs: what `pip install` takes for a module found missing.
DISTRIBUTIONS = {"dask": "dask[distributed]", "distributed": "dask[distributed]", "imageio_ffmpeg": "imageio-ffmpeg"}
RESEND_S = 0.005  # a signal lost in a finalizer comes again this much later: the finalizer has returned by then
stopped_by: int | None = None  # the signal that stopped this run, once one came (main() reports it, and only it)


def on_signals():
    """SIGTERM and SIGHUP (the terminal closed) raise Terminated, SIGINT KeyboardInterrupt, so that every cleanup
    runs (main() says one line). A process started in the background by a non-interactive shell inherits SIGINT
    ignored, and Python then installs no KeyboardInterrupt for it: `kill -INT` would be lost and the render run
    on. A signal that lands in a finalizer (a __del__ of llvmlite's, say) raises there, where Python only prints
    the exception and goes on (a SIGTERM was lost so): the signal is sent again from a thread, so its handler
    runs once the finalizer has returned, and nothing is printed. Each one is remembered in `stopped_by`: an
    exception it turns into on its way out (Taichi's or numpy's, raised while it unwound their state) or one
    swallowed on the way is still reported as the interruption it was."""
    global stopped_by
    stopped_by = None  # a run of its own (tests call main() again in one process)

    def on_term(signum, frame):
        global stopped_by
        stopped_by = signum
        raise Terminated(signum)

    def on_int(signum, frame):
        global stopped_by
        stopped_by = signum
        raise KeyboardInterrupt

    def resend(signum):
        time.sleep(RESEND_S)
        os.kill(os.getpid(), signum)

    def unraisable(info, passed_on=sys.unraisablehook):
        for kind, signum in ((Terminated, signal.SIGTERM), (KeyboardInterrupt, signal.SIGINT)):
            if isinstance(info.exc_value, kind):  # raised here, the handler would run inside this hook; and
                signum = getattr(info.exc_value, "signum", signum)
                _thread.start_new_thread(resend, (signum,))  # Thread.start() waits for its thread, so it would too
                return
        passed_on(info)

    signal.signal(signal.SIGTERM, on_term)
    signal.signal(signal.SIGHUP, on_term)
    signal.signal(signal.SIGINT, on_int)
    sys.unraisablehook = unraisable


def stopped(signum: int) -> int:
    """Say that a signal stopped the run; its exit code."""
    what = {signal.SIGINT: "interrupted", signal.SIGHUP: "hung up"}.get(signum, "terminated")
    try:
        print(f"pendulum: {what}; no partial output was left", file=sys.stderr)
    except OSError:  # hung up: the terminal, and stderr with it, may be gone
        pass
    return 128 + signum


def main(argv=None) -> int:
    on_signals()
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    # read before parsing, so that even an error while parsing can show its traceback
    debug = "--debug" in argv or os.environ.get("PENDULUM_DEBUG", "") not in ("", "0")
    try:
        args = build_parser(argv).parse_args(argv)
        code = args.func(args)
        return code if stopped_by is None else stopped(stopped_by)  # a signal swallowed on the way
    except SceneError as e:
        return fail(2, "error", e, debug)
    except (SimulationError, EncodeError, BatchError) as e:
        return fail(1, "failed", e, debug)
    except KeyboardInterrupt:
        return stopped(signal.SIGINT)
    except BrokenPipeError:  # e.g. `pendulum presets | head`
        sys.stdout = open(os.devnull, "w")
        return 0
    except Terminated as e:
        return stopped(e.signum)
    except OSError as e:  # the file system while running: a full disk, a vanished folder, permissions
        where = f": {e.filename}" if e.filename else ""
        return fail(1, "failed", f"{e.strerror or e}{where}", debug)
    except MemoryError as e:
        return fail(1, "failed", f"out of memory ({e or 'MemoryError'})", debug)
    except Exception as e:  # noqa: BLE001 - a bug or an unforeseen fault: still one line, not a traceback
        need = missing(e)
        if need:
            return fail(1, "failed", f"this needs the Python package {need}, which is not installed here: "
                                     f"pip install '{need}'", debug)
        why = f"{type(e).__name__}: {e}".rstrip(": ")
        return fail(1, "unexpected error", f"{why} (run with --debug for the traceback)", debug)


def missing(e: Exception) -> str | None:
    """The distribution to install when `e` is a dependency missing where it is imported lazily (a partial
    install: matplotlib for a chart, dask for tiles), else None; one of this package's own modules missing is a
    bug. dask without distributed raises an ImportError of its own, whose cause names the module."""
    for err in (e, e.__cause__):
        name = getattr(err, "name", None) if isinstance(err, ModuleNotFoundError) else None
        if name:
            top = name.partition(".")[0]
            return None if top == __package__.partition(".")[0] else DISTRIBUTIONS.get(top, top)
    return None


def fail(code: int, kind: str, error, debug: bool) -> int:
    """Report an error as one line on stderr (with the traceback first under --debug); return the code. An error
    raised while a signal unwound the run is that signal's doing: the signal is reported."""
    if stopped_by is not None and not debug:
        return stopped(stopped_by)
    if debug:
        traceback.print_exc()  # called from an except block: the exception being handled
    print(f"pendulum: {kind}: {one_line(str(error))}", file=sys.stderr)
    return code


def one_line(text: str, limit: int = 2000) -> str:
    """A message as one printable line: control characters escaped (file names and values may hold
    newlines), and an overlong message cut."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text.strip())
    return text if len(text) <= limit else text[:limit - 3] + "..."
