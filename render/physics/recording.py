"""A system's states read out into float64 numpy arrays: kernels that write into an array the caller holds (a
kernel argument), so that reading a frame makes no new array and no copy, as q.to_numpy() does. Read-outs,
like to_numpy, so they are not in the log of kernels (runtime.Launcher).

Recording is a mixin of the System (render/physics/system.py): it reads its state (q, n, D) and, to record a
run, steps it with the System's own advance_group or advance_one.
"""
import taichi as ti

from . import launch, runtime


class Recording:
    def read_out(self, name: str, *args):
        """Kernel `name` (q_into, rows_into) launched as prepared (render/physics/launch.py): once a frame."""
        return launch.call(self, name, *args)

    @ti.kernel
    def record(self, out: ti.types.ndarray(dtype=ti.f64, ndim=3), substeps: ti.i32, h: float,
               serial: ti.template()):
        """out[0] = q now, then out[f] = q after f frames of `substeps` steps of h, for every frame of an
        (frames, N, D) float64 array: advance and q_into a frame at a time, in one launch. The certificate's
        runs (render/trust/certify.py) draw nothing between frames, and a launch a frame cost them more than
        their steps (see stepper.Run.record). Each group of lanes (each pendulum under libm) steps through
        every frame on one thread, by the same instructions as advance's: the same states to the bit."""
        B = ti.static(1 if self.libm else self.chunk)
        S = ti.static(1 if self.libm else runtime.SPREAD)
        ti.loop_config(serialize=serial)
        for t in range(-(-self.n // B) * S):
            if t % S == 0:
                g = t // S
                for f in range(out.shape[0]):
                    if f:
                        if ti.static(self.libm):
                            self.advance_one(g, substeps, h)
                        else:
                            self.advance_group(g, substeps, h)
                    for i in range(g * B, ti.min(g * B + B, self.n)):
                        for d in ti.static(range(self.D)):
                            out[f, i, d] = ti.cast(self.q[i][d], ti.f64)

    @ti.kernel
    def q_into(self, out: ti.types.ndarray(dtype=ti.f64, ndim=3), f: ti.i32):
        """q into out[f] of an (frames, N, D) float64 array: what q.to_numpy() reads, without a new array and a
        copy every frame. A read-out, like to_numpy, so not in the log of kernels (runtime.Launcher)."""
        ti.loop_config(serialize=True)  # a certificate's subsample or lattice: fewer than waking threads costs
        for i in range(self.n):
            for d in ti.static(range(self.D)):
                out[f, i, d] = ti.cast(self.q[i][d], ti.f64)

    @ti.kernel
    def rows_into(self, out: ti.types.ndarray(dtype=ti.f64, ndim=3), f: ti.i32,
                  rows: ti.types.ndarray(dtype=ti.i64, ndim=1)):
        """q of the pendulums `rows` into out[f] of a (frames, len(rows), D) float64 array: the audio track's
        voices (render/video/audio.py). q.to_numpy() there, a parallel launch and a new array of the whole fan,
        took 319 us a frame of rigid_chaos, this 79 us (2-core Xeon, 2026-12-06)."""
        ti.loop_config(serialize=True)
        for r in range(rows.shape[0]):
            for d in ti.static(range(self.D)):
                out[f, r, d] = ti.cast(self.q[rows[r]][d], ti.f64)
