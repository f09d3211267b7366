"""The simulated states' bits, pinned: docs/numerics.md says every preset with the inline sin/cos gives the same
bits on AVX2 and on AVX-512 (IEEE arithmetic, fast_math off, no libm in the step), at any thread count. The
goldens cannot hold that (they allow a level on a few pixels, and end at 2.9 s), so each case's states after
1 s are held here to a digest: one machine kind computed them, and `make test` on the other kind, or `make
check-avx2` on an AVX-512 machine (tests/emulated_cpu.py --bits), checks that kind gives the same bits."""
import hashlib

import pytest

from render.config.scene import load
from render.physics.stepper import Run

# preset and overrides -> sha256 of its positions' and velocities' bytes after 1 s (10 frames), first 16 digits.
# Computed on an AVX-512 Xeon (2026-12-07) and matched under QEMU's Haswell (AVX2) by tests/emulated_cpu.py --bits.
DIGESTS = {
    ("rigid_chaos",): "ac2e7fc4c1ac9507",
    ("rigid_chaos", "integrator.precision=f32"): "cabdeef3805932d6",
    ("classic", "integrator.method=implicit_midpoint"): "8dcfc158cf70213f",
    ("damped_heavy",): "0f46a9fe7221c67e",
    ("triple_chaos",): "cf1dad298becb423",
    ("elastic_fan",): "6cc2ee812c068f72",
    ("elastic_fan", "integrator.method=yoshida4", "integrator.precision=f32"): "a2f436fd2315aae9",
    ("elastic_fan", "pendulums.damping=0.7", "integrator.method=yoshida4"): "e912100b4ec9d0a9",
}


def digest(preset: str, *sets: str) -> str:
    run = Run(load(preset, [*sets, "video.duration=1", "video.fps=10"]), "cpu")
    for _ in run.frames():
        pass
    q, v = run.sim.q.to_numpy(), run.sim.v.to_numpy()
    return hashlib.sha256(q.tobytes() + v.tobytes()).hexdigest()[:16]


@pytest.mark.parametrize("case", DIGESTS, ids=[" ".join(c) for c in DIGESTS])
def test_the_states_are_the_bits_every_cpu_kind_gives(case):
    assert digest(*case) == DIGESTS[case]
