"""512-bit vectors where LLVM would keep 256: its loop vectoriser told how many lanes to take.

Taichi 1.7.4 compiles kernels with LLVM 15 for the host CPU by name, and LLVM's tuning for Intel's AVX-512
CPUs (Skylake-X to Sapphire Rapids) prefers 256-bit vectors: the rigid f64 advance's optimised IR holds 849
`<4 x double>` operations and none wider, so half of every register sat idle (779 `<16 x double>` at 16
lanes; TI_PRINT_KERNEL_LLVM_IR_OPTIMIZED=1, docs/performance-log.md). No ti.init option sets the width, but LLVM's
own command-line options live in Taichi's library, and `-force-vector-width=16` has the loop vectoriser take
16 lanes in every loop it vectorises: a group of 16 f64 pendulums (System.CHUNK) in two 512-bit registers a
value, 32 f32 ones in two. benchmarks/vector_width.py measures what each width gives (docs/performance-log.md).
A CPU with AVX-512 that LLVM 15 does not know (AMD's Zen 5) it names "generic", and there its own choice was
slower still: 16 lanes ran rigid RK4 5.4 times as fast in f64 (NARROW), 32 faster again (WIDER), and the FTLE
map is quickest at 8 (TANGENTS). The loops sized for the vectoriser take lanes() columns, at least the width, so
that a wider one is never left scalar.

No arithmetic changes: fast_math is off, so no float reduction may be reassociated, and each lane computes
what it computed at 4 or 8 lanes (tests/test_vector_width.py: the same states and frames at 0, 8, 16 and 32 lanes).

LLVM's C entry point LLVMParseCommandLineOptions is in the library but not exported, so it is looked up in the
library's ELF symbol table and called at its address. Where that cannot be done (no symbol table, another
OS), or the CPU lacks AVX-512, or LLVM names it outside NARROW, nothing changes. PENDULUM_VECTOR_WIDTH sets the
width by hand (0 = LLVM's own choice), for measuring. A forced width also has LLVM print a remark for each loop
it could not vectorise at it, which is dropped (_quiet_compiles).

Taichi's offline cache keys a kernel by its source and Taichi's settings, not LLVM's options, so kernels
compiled at a forced width are cached in a subfolder of their own: a cache filled at the other width is never
taken for this one.
"""
from __future__ import annotations

import ctypes
import functools
import mmap
import os
import re
import struct
import weakref

import numpy as np
import taichi as ti  # maps the library this module reads

from . import held_stderr
from ..errors import SceneError

# LLVM 15's CPUs with AVX-512 whose tuning has "prefer-256-bit" (llvm/lib/Target/X86/X86.td). AMD's Zen 4 is
# not among them: LLVM 15 predates it and names it znver3, an AVX2 CPU, so Taichi compiles for AVX2 there.
PREFER_256 = frozenset({"skylake-avx512", "cascadelake", "cooperlake", "cannonlake", "icelake-client",
                        "icelake-server", "rocketlake", "tigerlake", "sapphirerapids"})
# "generic": LLVM 15's name for a CPU it does not know, such as AMD's Zen 5 (family 26, EPYC 9005), tuned as a
# baseline x86-64: the rigid f64 advance's optimised IR held 782 `<2 x double>` operations, SSE2's width, and
# 833 `<16 x double>` at 16 lanes. With AVX-512 in /proc/cpuinfo, 16 lanes there took rigid RK4 at N = 1e5 from
# 38 to 207 M steps/s in f64 and 90 to 261 M in f32, the same states (`python benchmarks/vector_width.py
# --widths 0 8 16 --rounds 2`, 2-core AMD EPYC, 2026-12-07; 8 lanes: 154 and 179 M).
NARROW = PREFER_256 | {"generic"}  # where a width is set unless PENDULUM_VECTOR_WIDTH says otherwise
# Lanes: a group's 16 f64 values in 2 zmm registers, its 32 f32 ones in two passes of one. 8 gave less in f64.
# 32 was measured on the Xeon only before lanes() sized the loops to the width, when it left a 16-lane f64 loop
# to its scalar remainder (23M against 128M steps/s); it has not been measured there since.
WIDTH = 16
# Where LLVM names the CPU "generic" (Zen 5), 32 lanes, and every loop sized for the vectoriser takes at least
# that many columns (lanes()), so none is left to its scalar remainder. From 16 to 32 lanes, alternating: rigid
# RK4 at N = 1e5 207 → 236 M steps/s in f64 (groups of 32), 263 → 337 M in f32; a 720p frame's simulation, flip
# map 14.7-18.0 → 13.5-14.2 ms, divergence map 43.9-52.7 → 39.0-39.4 ms; rigid_chaos's frame simulated and drawn
# 1.63-1.66 → 1.54 ms; the same states and frames (2-core AMD EPYC, 2026-12-07: docs/performance.md names the
# commands). Not measured on the Intel CPUs of PREFER_256, which keep 16.
WIDER = {"generic": 32}
# But the FTLE map's kernels carry four tangent vectors a pixel, 20 values a lane, and spill their registers when
# wide. A 720p frame's simulation took 144-151 ms at 32 lanes against 121-123 at 16; then 114-117 ms at 8 in three
# rounds of four (the other 253) against 123-137 at 16; a 1 s render of it at 720p 5.81-7.57 s at 8 against
# 6.75-8.27 s at 16, the same bytes (python benchmarks/map_frame.py fractal_lyapunov --seconds 0.5, and pendulum
# render, alternating; 2-core AMD EPYC). So a process that starts with an FTLE scene takes this width for its CPU
# (apply(tangents=True)), else the CPU's own (WIDER, WIDTH).
TANGENTS = {"generic": 8}
ENV, WIDTHS = "PENDULUM_VECTOR_WIDTH", ("0", "1", "2", "4", "8", "16", "32", "64")  # LLVM takes powers of 2
_SYM = np.dtype([("name", "<u4"), ("info", "u1"), ("other", "u1"), ("shndx", "<u2"), ("value", "<u8"),
                 ("size", "<u8")])
_done: int | None = None  # the width this process set (0: none); LLVM's options are parsed once per process


def apply(tangents: bool = False) -> int:
    """Set the loop vectoriser's width for this process, once, before any kernel compiles; returns the width
    set, 0 where LLVM keeps its own. tangents: the process is for the FTLE map (TANGENTS), where the width is
    the CPU's and not asked for. Also points Taichi's offline cache at the width's own subfolder."""
    global _done
    if _done is None:
        width, parse = _plan(tangents)
        if width:
            argv = [b"pendulum", f"-force-vector-width={width}".encode()]
            parse(len(argv), (ctypes.c_char_p * len(argv))(*argv), b"")
            _own_cache(f"llvm-vf{width}")
            _quiet_compiles()
        _done = width
    return _done


def planned(tangents: bool = False) -> int:
    """The width apply(tangents) sets, or set, in this process (0: LLVM's own), without setting it."""
    return _done if _done is not None else _plan(tangents)[0]


def _plan(tangents: bool = False):
    """(width, LLVMParseCommandLineOptions as a callable): the width PENDULUM_VECTOR_WIDTH asks for, else WIDTH
    (or WIDER's or TANGENTS' for the CPU) where the CPU has AVX-512 and LLVM targets it as one of NARROW;
    (0, None) where it is LLVM's own or cannot be set."""
    asked = os.environ.get(ENV, "").strip()
    if asked and asked not in WIDTHS:
        raise SceneError(f"${ENV}: {asked!r} is not a width: one of {', '.join(WIDTHS)} (0: LLVM's own)")
    if asked == "0" or not (asked or "avx512f" in simd_flags()):  # no AVX-512: nothing to look up
        return 0, None
    llvm = _llvm()
    if llvm is None:
        return 0, None
    cpu = _host_cpu(llvm)
    if not (asked or cpu in NARROW):
        return 0, None
    parse = ctypes.CFUNCTYPE(None, ctypes.c_int, ctypes.POINTER(ctypes.c_char_p), ctypes.c_char_p)
    width = int(asked) if asked else (TANGENTS if tangents else WIDER).get(cpu, WIDTH)
    return width, parse(llvm["LLVMParseCommandLineOptions"])


def lanes(least: int) -> int:
    """Columns for a loop sized for the vectoriser (a group of pendulums, a run of pixels): `least`, or the
    width this process set where that is more, since a loop of fewer iterations than the width is left to its
    scalar remainder. Call after runtime.init (apply()); the columns never change a result's bits."""
    return max(least, _done or 0)


def llvm_cpu() -> str | None:
    """The CPU LLVM compiles Taichi's kernels for, by LLVM's name ("generic" where it does not know it), or None
    where it cannot be asked: for the bench's report."""
    llvm = _llvm()
    return None if llvm is None else _host_cpu(llvm)


@functools.cache  # the library's symbol table is read once a process (the bench asks for the CPU twice)
def _llvm() -> dict[str, int] | None:
    """The addresses, in this process, of the LLVM functions called here, or None where they cannot be found."""
    lib = _library()
    names = ("LLVMParseCommandLineOptions", "_ZN4llvm3sys14getHostCPUNameEv", "PyInit_taichi_python")
    syms = _symbols(lib, names) if lib else {}
    if len(syms) < len(names):
        return None
    so = ctypes.CDLL(lib)  # already loaded by taichi: the same handle, so the same load address
    base = ctypes.cast(so.PyInit_taichi_python, ctypes.c_void_p).value - syms["PyInit_taichi_python"]
    return {name: base + at for name, at in syms.items()}


def _host_cpu(llvm: dict[str, int]) -> str:
    cpu = ctypes.CFUNCTYPE(_StringRef)(llvm["_ZN4llvm3sys14getHostCPUNameEv"])()
    return ctypes.string_at(cpu.data, cpu.size).decode()


def simd_flags() -> list[str]:
    """The CPU's vector extensions that matter here, from /proc/cpuinfo (Linux; empty elsewhere)."""
    try:
        flags = next(x.split(":", 1)[1].split() for x in open("/proc/cpuinfo") if x.startswith("flags"))
    except (OSError, StopIteration):
        return []
    return [f for f in ("avx2", "fma", "avx512f") if f in flags]


class _StringRef(ctypes.Structure):  # llvm::StringRef, returned in two registers
    _fields_ = [("data", ctypes.c_void_p), ("size", ctypes.c_size_t)]


def _library() -> str | None:
    """The path of Taichi's compiled library, as this process mapped it."""
    try:
        with open("/proc/self/maps") as maps:
            for line in maps:
                if "taichi_python" in line and line.rstrip().endswith(".so"):
                    return line.split(maxsplit=5)[5].strip()
    except OSError:
        pass
    return None


def _symbols(path: str, names: tuple[str, ...]) -> dict[str, int]:
    """{name: address relative to the load base} of the functions named, from a 64-bit little-endian ELF's
    .symtab; a name absent or found more than once is left out."""
    found = {}
    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
        if m[:6] != b"\x7fELF\x02\x01":
            return found
        shoff, = struct.unpack_from("<Q", m, 0x28)
        shentsize, shnum = struct.unpack_from("<HH", m, 0x3A)
        sections = [struct.unpack_from("<IIQQQQIIQQ", m, shoff + i * shentsize) for i in range(shnum)]
        for _, kind, _, _, offset, size, link, _, _, _ in sections:
            if kind != 2:  # SHT_SYMTAB
                continue
            str_at, str_size = sections[link][4], sections[link][5]
            # a copy, not a view: an mmap with a view of it alive cannot close, and an interrupt here would then
            # end as BufferError ("cannot close exported pointers exist") instead of itself
            syms = np.frombuffer(m[offset:offset + size // _SYM.itemsize * _SYM.itemsize], _SYM)
            funcs = syms[(syms["info"] & 0xF) == 2]  # STT_FUNC
            for name in names:
                # a name may end another one in the string table, so every place it ends a string counts
                key, starts = name.encode() + b"\0", []
                at = m.find(key, str_at, str_at + str_size)
                while at >= 0:
                    starts.append(at - str_at)
                    at = m.find(key, at + 1, str_at + str_size)
                hit = funcs["value"][np.isin(funcs["name"], starts)]
                if len(hit) == 1:
                    found[name] = int(hit[0])
    return found


# A width asked for makes LLVM report every loop it could not vectorise at it, on stderr ("remark: <unknown>:0:0:
# loop not vectorized: call instruction cannot be vectorized": Taichi's own runtime loops make several per
# kernel); asked-for widths make it a remark that always prints, whatever LLVM's remark options say.
_REMARK = re.compile(rb"^remark: [^\n]*loop not vectorized[^\n]*(\n|$)", re.M)


def _quiet_compiles():
    """Drop those remarks: LLVM runs when a kernel is first launched (compiled, or found in the offline cache)
    and when fields are finalised, so fd 2 is held through those calls alone and what else was written there
    is passed on."""
    from taichi._snode.fields_builder import FieldsBuilder
    from taichi.lang import kernel_impl

    launch, finalize, launched = kernel_impl.Kernel.launch_kernel, FieldsBuilder.finalize, weakref.WeakSet()

    def launch_kernel(self, t_kernel, *args):
        if t_kernel in launched:
            return launch(self, t_kernel, *args)
        launched.add(t_kernel)
        with held_stderr.held(_without_remarks):
            return launch(self, t_kernel, *args)

    def finalize_fields(self, *args, **kwargs):
        with held_stderr.held(_without_remarks):
            return finalize(self, *args, **kwargs)

    kernel_impl.Kernel.launch_kernel, FieldsBuilder.finalize = launch_kernel, finalize_fields


def _without_remarks(text: bytes, ok: bool) -> bytes:
    return _REMARK.sub(b"", text)


def _own_cache(sub: str):
    """Point Taichi's offline cache (TI_OFFLINE_CACHE_FILE_PATH, else Taichi's default) at its subfolder sub;
    a child process inherits the path and keeps it."""
    os.environ["TI_OFFLINE_CACHE_FILE_PATH"] = _in_cache(sub)


def cache_root() -> str:
    """Taichi's offline cache folder as this process's environment sets it, else Taichi's default."""
    return os.environ.get("TI_OFFLINE_CACHE_FILE_PATH") or ti.lang.impl.default_cfg().offline_cache_file_path


def _in_cache(sub: str) -> str:
    path = cache_root()
    return path if os.path.basename(os.path.normpath(path)) == sub else os.path.join(path, sub)


def cache_folder(arch: str = "cpu", tangents: bool = False) -> str:
    """The folder Taichi's offline cache writes this process's kernels to, or a child's it starts on `arch`
    (tangents: for the FTLE map): apply()'s subfolder where it sets a width (runtime.init applies it on the CPU
    only), else the cache itself."""
    width = planned(tangents) if arch == "cpu" else 0
    return _in_cache(f"llvm-vf{width}") if width else cache_root()
