"""The golden frames, and optionally the sin/cos tests and the state digests, on the other CPU kind: AVX2, emulated
on an AVX-512 machine.

    .venv/bin/python tests/emulated_cpu.py [--cpu Haswell] [--sincos] [--bits] [--keep] [PRESET ...]

The suite must hold on AVX2 and on AVX-512 (docs/numerics.md), but `make test` checks only the machine's own
kind. QEMU's user-mode emulator (Debian: `apt-get install -y qemu-user`; QEMU 7.2 emulates AVX2 and FMA but no
AVX-512) runs this venv's Python as if on --cpu: LLVM then compiles Taichi's kernels for that CPU, and numpy
and libm take its code paths. Each preset (default: all of presets/) is rendered as tests/test_golden.py
renders it (tests/conftest.py's render_small), in an emulated process of its own, and its frames are held here
to tests/golden/ by test_golden's rule (ATOL, MAX_BAD_FRACTION). --sincos runs tests/test_sincos.py emulated
too. Not part of `make test`: emulation is slow. On the 2-core Xeon (2026-12-06): 45 s to 3.5 min a preset,
but fractal_lyapunov (7.6 s of CPU natively) 50 min on both cores; 2-3 min for test_sincos.py.

Everything it writes is under out/emulated-CPU/ (renders, frames, a Taichi kernel cache of its own, so that
kernels compiled for this machine's CPU are never loaded there), removed at the end unless --keep. Exit
status 0 when every preset matches (and test_sincos.py passes), 1 otherwise, 2 (one line, nothing written)
without qemu-x86_64 or for a --cpu or preset it does not know.
"""
import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]  # render/, and conftest and test_golden, in either process
QEMU = "qemu-x86_64"


def child(preset: str, npz: Path, out: Path) -> int:
    """In the emulated process: render `preset` small, save its golden picks to `npz`, say what numpy saw."""
    import numpy as np
    from numpy._core._multiarray_umath import __cpu_features__ as features

    # Under QEMU 7.2 numpy's AVX2 quicksort argsort crashed the emulated process (SIGSEGV) within a render, on
    # values it sorted in a fresh process (render/physics/stability.py's, for compare_methods); its stable sort
    # did not. Values all distinct have one order, whatever the algorithm: those go to the stable sort.
    argsort = np.argsort

    def distinct_stable(a, *args, **kwargs):
        a = np.asarray(a)
        if a.ndim == 1 and not args and kwargs.get("kind") is None and len(np.unique(a)) == len(a):
            return argsort(a, kind="stable", **{k: v for k, v in kwargs.items() if k != "kind"})
        return argsort(a, *args, **kwargs)

    np.argsort = distinct_stable
    import conftest
    frames = conftest.render_small(preset, out)[2]
    np.savez(npz, **frames)
    print(" ".join(f"{k}={int(features.get(k, False))}" for k in ("AVX2", "FMA3", "AVX512F")))
    return 0


def compare(preset: str, npz: Path) -> tuple[bool, str]:
    """(matches, a line) for the emulated frames against tests/golden/PRESET/, by test_golden's rule."""
    import imageio.v3 as iio
    import numpy as np
    import test_golden

    worst, ok, frames = 0, True, np.load(npz)
    for pick in frames.files:
        golden = iio.imread(test_golden.GOLDEN / preset / f"{pick}.png").astype(np.int16)
        diff = np.abs(golden - frames[pick].astype(np.int16))
        worst = max(worst, int(diff.max()))
        ok &= bool((diff > test_golden.ATOL).mean() <= test_golden.MAX_BAD_FRACTION)
    return ok, f"largest difference {worst} level(s) over {len(frames.files)} frames"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("presets", nargs="*", metavar="PRESET", help="default: every preset in presets/")
    ap.add_argument("--cpu", default="Haswell", help="QEMU's CPU model (`qemu-x86_64 -cpu help`; default Haswell)")
    ap.add_argument("--sincos", action="store_true", help="also run tests/test_sincos.py emulated")
    ap.add_argument("--bits", action="store_true", help="also run tests/test_state_bits.py emulated: the "
                                                        "simulated states' digests")
    ap.add_argument("--keep", action="store_true", help="keep out/emulated-CPU/ (renders, frames, kernel cache)")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)  # PRESET NPZ OUT, in the emulated process
    args = ap.parse_args(argv)
    if args.child:
        return child(args.child[0], Path(args.child[1]), Path(args.child[2]))
    qemu = shutil.which(QEMU)
    if qemu is None or platform.machine() != "x86_64":
        print(f"emulated_cpu: needs {QEMU} on an x86-64 Linux (Debian: apt-get install -y qemu-user)",
              file=sys.stderr)
        return 2
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", args.cpu):  # it names a folder under out/
        print(f"emulated_cpu: --cpu {args.cpu!r} is not a CPU model's name (`{QEMU} -cpu help`)", file=sys.stderr)
        return 2
    shipped = sorted(p.stem for p in (ROOT / "presets").glob("*.toml"))
    names = args.presets or shipped
    unknown = [n for n in names if n not in shipped or not (ROOT / "tests" / "golden" / n).is_dir()]
    if unknown:
        print(f"emulated_cpu: {', '.join(unknown)}: not a preset of presets/ with golden frames in tests/golden/",
              file=sys.stderr)
        return 2
    work = ROOT / "out" / f"emulated-{args.cpu}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    env = {**os.environ, "TI_OFFLINE_CACHE_FILE_PATH": str(work / "taichi-cache"), "TI_SKIP_VERSION_CHECK": "ON"}
    emulated = [qemu, "-cpu", args.cpu, sys.executable]
    failed = 0
    try:
        for wanted, tests in ((args.sincos, "tests/test_sincos.py"), (args.bits, "tests/test_state_bits.py")):
            if not wanted:
                continue
            res = subprocess.run([*emulated, "-m", "pytest", "-q", "-p", "no:cacheprovider", tests],
                                 cwd=ROOT, env=env, capture_output=True, text=True)
            tail = res.stdout.strip().splitlines()[-1:] or ["(no output)"]
            print(f"{tests} on {args.cpu}: {tail[0]}", flush=True)
            failed += res.returncode != 0
        for name in names:
            npz = work / f"{name}.npz"
            res = subprocess.run([*emulated, __file__, "--child", name, str(npz), str(work / "renders")],
                                 cwd=ROOT, env=env, capture_output=True, text=True)
            if res.returncode:
                last = [x for x in res.stderr.splitlines() if x.strip() and "TCG doesn't support" not in x][-1:]
                print(f"{name}: the emulated render failed (exit status {res.returncode}): {''.join(last)}",
                      flush=True)
                failed += 1
                continue
            ok, line = compare(name, npz)
            seen = (res.stdout.strip().splitlines() or ["features not reported"])[-1]
            print(f"{name}: {'matches' if ok else 'DIFFERS FROM'} its golden frames on {args.cpu} ({seen}); {line}",
                  flush=True)
            failed += not ok
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
