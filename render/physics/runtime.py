"""One place that owns the Taichi runtime: arch, precision, and the log of kernels launched.

Precision is chosen by re-initialising Taichi with default_fp, not by casting: with default_fp=f64 an f32
value times a float literal is computed in f64, so "f32" would silently be f64 arithmetic.
"""
from __future__ import annotations

import contextlib
import io
import os
import stat
import sys
import tempfile
import warnings

import taichi as ti

from . import frontend, held_stderr, launch, vector_width  # noqa: F401 (frontend: its memos, on import)

_current: tuple | None = None
_generation = 0  # how many times Taichi was (re)initialised: fields of an older generation are gone
launched: list[str] = []  # kernel names in first-launch order, since the last init

# Taichi 1.7.4's CPU backend hands a parallel range-for to its threads in blocks of at least 512 iterations,
# whatever loop_config(block_dim=...), default_cpu_block_dim or cpu_block_dim_adaptive say
# (benchmarks/thread_blocks.py: 95 heavy iterations ran on one of 2 threads, 600 split 512 to 88). A loop over
# groups of pendulums has few, heavy iterations: the certificate's 1521 pixels in f64 are 96 groups, all on one
# thread, and 1e5 pendulums in f32 3125 groups, 7 blocks for 2 threads. So such a loop runs over SPREAD
# iterations per group, of which only the first works (`if t % SPREAD == 0`): a block is then 512 / SPREAD
# groups, and the idle iterations cost a compare each. Which thread steps a group never changes its bits.
SPREAD = 128

# A parallel loop wakes Taichi's thread pool and waits for it, whatever its work: a kernel of one loop of 100
# trivial iterations took 116-127 us a launch on the thread pool, at 1 or 2 threads, and 17-20 us serial (2-core
# Xeon under KVM, 2026-12-06). So a loop of little work runs serially (ti.loop_config(serialize=...)), its work
# counted in RK4 pendulum-steps. `python benchmarks/serial_loops.py` there, µs per launch serial / parallel: the
# rigid advance of 100 pendulums by 17 steps (rigid_chaos's frame) 114 / 324, 1000 pendulums 495 / 641, 4000
# 1514 / 1361; the energies (about two steps' work each) of 4000 pendulums 223 / 358, of 16000 905 / 758.
SERIAL_WORK = 8192


def serial(work: int) -> bool:
    """Whether a loop of `work` RK4 pendulum-steps runs on the launching thread (SERIAL_WORK): on the CPU only,
    where that thread is a core like the pool's (on CUDA it would be one GPU thread)."""
    return work < SERIAL_WORK and _current is not None and _current[1] == "cpu"


def init(arch: str = "cpu", precision: str = "f64", threads: int | None = None, keep_log: bool = False,
         tangents: bool = False) -> str:
    """(Re)initialise Taichi if the settings differ; returns the arch actually in use. The log of kernels and
    fields starts afresh, unless keep_log and Taichi runs on as it was. Called by render/physics/stepper.py's
    Run, which builds the system it is for: no caller has to start Taichi, or in which precision. tangents: for
    the FTLE map, whose kernels take fewer lanes well (vector_width.apply), heeded by the process's first init."""
    global _current, _generation
    want = (arch, precision, threads)
    if _current is not None and _current[0] == want:
        if not keep_log:
            launched.clear()
            allocated.clear()
        return _current[1]
    # fast_math off: IEEE arithmetic, so no compiler may reassociate a float expression, and what it may do
    # depends on the CPU it targets. With it on, AVX-512 code generation folded sincos's exact range reduction
    # away (2.3e8 ulp near k·π/2) where AVX2's did not; off, the kernels give the same bits on either kind.
    kw = dict(default_fp=ti.f64 if precision == "f64" else ti.f32, log_level=ti.ERROR,
              random_seed=0, offline_cache=True, fast_math=False)
    if threads:
        kw["cpu_max_num_threads"] = threads
    writable_cache()
    if arch == "cpu":  # before the first kernel compiles: LLVM reads its options then
        vector_width.apply(tangents)
    # Never ti.gpu: it segfaults where there is no GPU. ti.cuda falls back to the CPU by itself.
    # ti.init prints "[Taichi] Starting on arch=..." to stdout unconditionally; stdout is for results.
    with contextlib.redirect_stdout(io.StringIO()), held_stderr.held(_unless_failed):
        ti.init(arch=ti.cuda if arch == "cuda" else ti.cpu, **kw)
    used = "cuda" if ti.lang.impl.current_cfg().arch == ti.cuda else "cpu"
    if arch == "cuda" and used == "cpu":
        print("warning: --arch cuda: no CUDA device found, running on the CPU", file=sys.stderr)
    _current = (want, used)
    _generation += 1
    launched.clear()
    allocated.clear()
    return used


def writable_cache():
    """Taichi 1.7.4 segfaults as the process exits, after a run has succeeded, where its offline cache's
    folder cannot be made (a read-only or missing $HOME, as in some containers): exit code 139 for a finished
    render. Such a process caches its kernels in a folder of its own under the temporary folder, and says so."""
    root = vector_width.cache_root()
    try:  # a file made and removed there: os.access says yes to root on a read-only or immutable folder
        os.makedirs(root, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=root, prefix=".pendulum-probe-"):
            return
    except OSError:
        pass
    spare = None
    if hasattr(os, "getuid"):  # one folder a user, kept between runs (Windows has no uid: one a run)
        spare = os.path.join(tempfile.gettempdir(), f"pendulum-taichi-cache-{os.getuid()}")
        with contextlib.suppress(FileExistsError):
            os.mkdir(spare, 0o700)
        st = os.lstat(spare)
        if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid():  # a shared folder: that name is another's
            spare = None
    if spare is None:
        spare = tempfile.mkdtemp(prefix="pendulum-taichi-cache-")
    os.environ["TI_OFFLINE_CACHE_FILE_PATH"] = spare
    print(f"warning: Taichi's kernel cache {root} cannot be written; caching kernels in {spare} "
          f"(TI_OFFLINE_CACHE_FILE_PATH chooses the folder)", file=sys.stderr)


def generation() -> int:
    return _generation


def forget():
    """Have the next init() start Taichi afresh, whatever runs now (the fields of earlier runs go with it).

    Taichi's offline cache keys a kernel by the fields allocated before it in the process, so a kernel is
    found there again only after the same history: tests/conftest.py starts each test module afresh, so
    that its kernels are found whichever modules its worker ran before."""
    global _current
    _current = None


def _unless_failed(text: bytes, ok: bool) -> bytes:
    """When ti.init fails it logs the error on fd 2 and then raises it, and the CLI reports the exception as its
    one line: what it wrote passes on only if it succeeded."""
    return text if ok else b""


def real():
    """The float type of the current init."""
    return ti.lang.impl.current_cfg().default_fp


class Launcher:
    """Mixin: launch kernels by name so a run can report exactly which kernels it used; after its first launch a
    kernel is launched as prepared (render/physics/launch.py), without Taichi's per-call Python."""

    def launch(self, name: str, *args):
        if name not in launched:
            launched.append(name)
        return launch.launches(self).launch(name, lambda: self.kernel(name), args)

    def kernel(self, name: str):
        return getattr(self, name)


allocated: dict[str, int] = {}  # field name -> bytes, since the last init


def field(name: str, dtype, shape, n: int | None = None, block: int | None = None):
    """Allocate a (vector) field and account for its bytes, so a run can show what it allocated.

    block: a 2-D field stored as block×block tiles, each contiguous (its shape rounded up to whole tiles),
    so that a walk along either axis stays in a few cache lines."""
    if block is None:
        f = ti.field(dtype, shape) if n is None else ti.Vector.field(n, dtype, shape)
    else:
        f = ti.field(dtype) if n is None else ti.Vector.field(n, dtype)
        tiles = tuple(-(-s // block) for s in shape)
        ti.root.dense(ti.ij, tiles).dense(ti.ij, (block, block)).place(f)
        shape = tuple(t * block for t in tiles)
    count = 1
    for s in (shape if isinstance(shape, tuple) else (shape,)):
        count *= s
    allocated[name] = allocated.get(name, 0) + count * (n or 1) * _size(dtype)
    return f


def _size(dtype) -> int:
    return {ti.f64: 8, ti.i64: 8, ti.f32: 4, ti.i32: 4, ti.u32: 4, ti.u8: 1}[dtype]


warnings.filterwarnings("ignore", category=DeprecationWarning, module="taichi")
