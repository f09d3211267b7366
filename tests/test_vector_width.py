"""render/physics/vector_width.py: LLVM's loop vectoriser at 8, 16 or 32 lanes changes the code, never the numbers.

The width is set by hand here (PENDULUM_VECTOR_WIDTH), so every width is checked on either CPU kind: on an
AVX2 machine a 16-lane vector is 4 registers, on AVX-512 2.
"""
import ctypes
import json
import os
import subprocess
import sys
from pathlib import Path

from conftest import run_cli
from render.physics import vector_width

ROOT = Path(__file__).resolve().parent.parent

CHILD = r"""
import hashlib, json, pathlib, sys
from render.config.scene import load
from render.physics import vector_width
from render.physics.stepper import Run
ir_only = sys.argv[1] == "ir"
out = {}
for prec in (("f64",) if ir_only else ("f64", "f32")):
    for preset in (("rigid_chaos",) if ir_only else ("rigid_chaos", "triple_chaos")):
        scene = load(preset, ["pendulums.count=40", 'integrator.method="rk4"', f'integrator.precision="{prec}"',
                              'effects=["bobs"]'])
        sim = Run(scene, "cpu").sim
        sim.launch(f"{sim.NAME}_advance", 300)
        out[f"{preset} {prec}"] = hashlib.sha1(sim.q.to_numpy().tobytes() + sim.v.to_numpy().tobytes()).hexdigest()
if ir_only:  # the optimised IR of every kernel compiled, from an empty cache
    ir = [p.read_text() for p in pathlib.Path().glob("*.ll")]
    advance = [t for t in ir if "define void @advance_" in t]  # the system's advance kernel
    out["kernels"], out["advance"] = len(ir), len(advance)
    out["wide"] = sum(t.count(" <16 x double>") for t in ir)
    out["wide_in_advance"] = sum(t.count("fmul <16 x double>") for t in advance)
else:  # a frame as render draws it (trails, bobs, HUD), as the MP4 takes it (YUV) and shrunk as the GIF's
    from render.video import downscale, pipeline, yuv
    src = pipeline.Source(load("rigid_chaos", ["video.width=320", "video.height=180", "video.duration=1"]))
    for _ in range(12):
        frame = src.next_frame()
    out["frame"] = hashlib.sha1(frame.tobytes()).hexdigest()
    out["yuv"] = hashlib.sha1(yuv.convert(frame).tobytes()).hexdigest()
    out["shrunk"] = hashlib.sha1(downscale.shrink(frame, 136, 76).tobytes()).hexdigest()
    # an FTLE map's frame: its tangent vectors in the system's groups (render/maps/ftle.py)
    ftle = pipeline.Source(load("fractal_lyapunov", ["video.width=96", "video.height=54", "video.duration=0.2"]))
    for _ in range(3):
        frame = ftle.next_frame()
    out["ftle"] = hashlib.sha1(frame.tobytes()).hexdigest()
out["width"] = vector_width.apply()
print(json.dumps(out))
"""


def child(mode: str, width: int, cwd: Path, cache: Path | None = None) -> dict:
    env = dict(os.environ, PENDULUM_VECTOR_WIDTH=str(width))
    if mode == "ir":  # an empty cache, so every kernel compiles and its IR is printed
        env.update(TI_OFFLINE_CACHE_FILE_PATH=str(cache), TI_PRINT_KERNEL_LLVM_IR_OPTIMIZED="1")
    r = subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(ROOT)!r})\n" + CHILD, mode],
                       cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "remark" not in r.stderr  # LLVM's report of each loop not vectorised at 16 lanes, dropped
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_sixteen_lanes_compile_wider_and_integrate_and_draw_the_same_bits(tmp_path):
    runs = {}
    for width in (0, 16):
        (tmp_path / f"ir{width}").mkdir()
        runs[width] = child("ir", width, tmp_path / f"ir{width}", tmp_path / f"cache{width}")
        runs[width].update({f"drawn {k}": v for k, v in child("draw", width, tmp_path).items()})
    narrow, wide = runs[0], runs[16]
    assert narrow["width"] == 0 and wide["width"] == 16
    assert narrow["kernels"] > 0 and narrow["advance"] == 1 and wide["advance"] == 1
    assert narrow["wide"] == 0  # LLVM's own width is 2 to 8 f64 lanes (2 where it names the CPU generic)
    assert wide["wide_in_advance"] > 100  # the RK4 step's products, each on 16 pendulums at once
    same = {k: v for k, v in narrow.items() if k not in ("width", "wide", "wide_in_advance", "drawn width")}
    assert sorted(same) == ["advance", "drawn frame", "drawn ftle", "drawn rigid_chaos f32", "drawn rigid_chaos f64",
                            "drawn shrunk", "drawn triple_chaos f32", "drawn triple_chaos f64", "drawn yuv", "kernels",
                            "rigid_chaos f64"]
    assert same == {k: wide[k] for k in same}, "the width changed the numbers"
    # the other widths set on a CPU LLVM calls generic: 32 lanes, with groups of 32 pendulums, the canvas's trails
    # faded 32 pixels at a time, the YUV conversion and the GIF's shrink 32 words at a time (vector_width.lanes),
    # and the FTLE map's 8
    drawn = {k[len("drawn "):]: v for k, v in same.items() if k.startswith("drawn ")}
    for width in (8, 32):
        other = child("draw", width, tmp_path)
        assert other["width"] == width
        assert drawn == {k: v for k, v in other.items() if k != "width"}, f"{width} lanes changed the numbers"


def test_the_elf_symbol_table_gives_the_address_the_dynamic_linker_gives():
    """An exported function's address, found in .symtab plus the library's load base, is the one dlsym finds;
    names absent from the table are left out."""
    import taichi  # noqa: F401  (loads the library)
    lib = vector_width._library()
    assert lib and Path(lib).is_file()
    got = vector_width._symbols(lib, ("PyInit_taichi_python", "LLVMParseCommandLineOptions", "no_such_function"))
    assert set(got) == {"PyInit_taichi_python", "LLVMParseCommandLineOptions"}
    with open("/proc/self/maps") as maps:
        base = min(int(line.split("-")[0], 16) for line in maps if line.rstrip().endswith(lib))
    dlsym = ctypes.cast(ctypes.CDLL(lib).PyInit_taichi_python, ctypes.c_void_p).value
    assert base + got["PyInit_taichi_python"] == dlsym


def test_width_zero_sets_nothing_and_keeps_the_cache(tmp_path):
    env = dict(os.environ, PENDULUM_VECTOR_WIDTH="0", TI_OFFLINE_CACHE_FILE_PATH=str(tmp_path))
    code = ("import os, taichi; from render.physics import vector_width as v; before = v.cache_folder('cpu'); "
            "gpu = v.cache_folder('cuda'); "
            "print(v.planned(), v.apply(), os.environ['TI_OFFLINE_CACHE_FILE_PATH'], before, gpu)")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert r.stdout.split() == ["0", "0", str(tmp_path), str(tmp_path), str(tmp_path)], r.stderr
    env["PENDULUM_VECTOR_WIDTH"] = "16"  # cache_folder() names, before apply(), the folder apply() then sets
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert r.stdout.split() == ["16", "16", str(tmp_path / "llvm-vf16"), str(tmp_path / "llvm-vf16"),
                                str(tmp_path)], r.stderr  # runtime.init applies no width for CUDA


def test_a_width_that_is_not_one_exits_2_with_one_line_and_writes_nothing(tmp_path):
    env = dict(os.environ, PENDULUM_VECTOR_WIDTH="12")
    for command in (["render", "rigid_chaos", "--set", "video.duration=0.2"], ["bench", "--quick"]):
        r = run_cli(*command, "--out", tmp_path / "out", env=env)
        assert r.returncode == 2, r.stderr
        assert r.stderr.strip() == ("pendulum: error: $PENDULUM_VECTOR_WIDTH: '12' is not a width: one of 0, 1, 2, "
                                    "4, 8, 16, 32, 64 (0: LLVM's own)")
        assert not (tmp_path / "out").exists()
