"""The `poincare` effect: the Poincaré section θ1 = 0 (mod 2π), ω1 > 0 of a double pendulum, drawn as the
(θ2, ω2) points where each pendulum crosses it, accumulating over the video; and the `shell` start.

- **Crossings** are found where the substeps happen (System.advance calls detect() after every step): θ1 is
  unwrapped, so a step crosses the section upwards where it passes a multiple of 2π while increasing. The
  crossing is located within the step by cubic Hermite interpolation of the step itself, from the state and
  its derivative (the system's own force) at both ends: θ1(u) = 2πk is solved by Newton from the chord,
  then θ2 and ω2 are interpolated at that u. Its error is h⁴/384 times the fourth derivative, below the
  step's own: tests/test_poincare.py checks crossings against scipy's event location on the independent
  model within 1e-6 (on poincare_shell at dt ≈ 1 ms they agree within 1e-9 s, rad and rad/s over 6 s), so
  Hénon's extra step is not needed. An advance records at most SLOTS crossings per pendulum (θ1 would have
  to turn SLOTS times within one frame to lose one); losses are counted in metadata.
- **layout = "shell"** starts every pendulum with the energy of the preset's (theta, omega), on the section:
  θ1 = 0, (θ2, ω2) spread over the section's accessible region by a low-discrepancy (R2) sequence, and ω1 > 0
  solved from the energy. The energy is the reference model's (render/reference.py): it is a quadratic in ω1,
  so three evaluations give its coefficients, and no formula is written twice.
- **The panel**: θ2 wrapped to [−π, π) across, ω2 up, over the range energy allows on the section (the
  kinetic energy's minimum over ω1 at each θ2), with axes as render/axes.py draws a map's; each crossing a
  small disc in its pendulum's colour (the canvas's palette), composed with an atomic max into a layer that
  persists over the video, so frames are the same bytes at any thread count. Beside the pendulums (when
  effects also draw them) it takes the right half of the frame; alone it takes the whole frame.
"""
import math

import numpy as np
import taichi as ti

from . import axes, reference, runtime
from .errors import SceneError
from .font import Font

SLOTS = 4  # crossings kept per pendulum and advance call
TAU = 2.0 * math.pi
PLASTIC = 1.324717957244746  # the R2 sequence's generator: frac(½ + k/p, ½ + k/p²) fills a square evenly
TITLE = ("Poincaré section θ₁ = 0, ω₁ > 0", "section θ₁ = 0")


def allocate(sim):
    """The crossing fields of a system whose scene has the effect: this step's crossings per pendulum."""
    sim.crossings = runtime.field("poincare.crossings", runtime.real(), (sim.n, SLOTS), 3)  # (t in step, θ2, ω2)
    sim.crossed = runtime.field("poincare.count", ti.i32, sim.n)


@ti.func
def hermite(y0, y1, d0, d1, u):
    """The cubic through y0, y1 with slopes d0, d1 (per unit of u) at u = 0, 1."""
    return (y0 + u * (d0 + u * (3.0 * (y1 - y0) - 2.0 * d0 - d1 + u * (2.0 * (y0 - y1) + d0 + d1))))


@ti.func
def hermite_slope(y0, y1, d0, d1, u):
    return d0 + u * (6.0 * (y1 - y0) - 4.0 * d0 - 2.0 * d1 + 3.0 * u * (2.0 * (y0 - y1) + d0 + d1))


@ti.func
def detect(sys: ti.template(), i, s, q0, v0, q1, v1, h):
    """Record pendulum i's crossing of the section in substep s (from q0, v0 to q1, v1; D × 1), if any."""
    k0, k1 = ti.floor(q0[0, 0] / TAU), ti.floor(q1[0, 0] / TAU)
    if k1 > k0 and i < sys.n:
        a0, a1 = sys.force(q0, v0), sys.force(q1, v1)
        y0, y1 = q0[0, 0] - k1 * TAU, q1[0, 0] - k1 * TAU  # below and at or above the section
        d0, d1 = h * v0[0, 0], h * v1[0, 0]
        u = y0 / (y0 - y1)
        for _ in range(4):  # Newton from the chord: its error is O(h²), squared each time
            u = ti.min(ti.max(u - hermite(y0, y1, d0, d1, u) / hermite_slope(y0, y1, d0, d1, u), 0.0), 1.0)
        th2 = hermite(q0[1, 0], q1[1, 0], h * v0[1, 0], h * v1[1, 0], u)
        w2 = hermite(v0[1, 0], v1[1, 0], h * a0[1, 0], h * a1[1, 0], u)
        k = sys.crossed[i]
        if k < SLOTS:
            sys.crossings[i, k] = ti.Vector([(s + u) * h, th2, w2])
        sys.crossed[i] = k + 1


def read(sim, t0: float) -> tuple[np.ndarray, ...]:
    """The last advance's crossings (it started at time t0): pendulum, time, θ2 (unwrapped), ω2; and how many
    were lost beyond SLOTS."""
    count, rows = sim.crossed.to_numpy(), sim.crossings.to_numpy()
    i, k = np.nonzero(np.arange(SLOTS)[None, :] < count[:, None])
    c = rows[i, k].astype(np.float64)
    return i, t0 + c[:, 0], c[:, 1], c[:, 2], int(np.maximum(count - SLOTS, 0).sum())


# ------------------------------------------------------------------ the shell start and the ω2 range (host)
def quadratic(p, th2: np.ndarray, w2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """E(ω1) = A·ω1² + B·ω1 + C on the section θ1 = 0 at each (θ2, ω2), from the reference energy at
    ω1 = 0, ±1."""
    q = np.stack([np.zeros_like(th2), th2], 1)
    e = [reference.energy(p, q, np.stack([np.full_like(w2, w1), w2], 1)) for w1 in (0.0, 1.0, -1.0)]
    return 0.5 * (e[1] + e[2]) - e[0], 0.5 * (e[1] - e[2]), e[0]


def reach(p, energy: float) -> float:
    """The largest |θ2| on the section at this energy: where the potential (E at rest) reaches it, by bisection
    (it grows with |θ2| from the hanging rest)."""
    def rest(th2):
        return quadratic(p, np.array([th2]), np.zeros(1))[2][0]
    if rest(math.pi) < energy:
        return math.pi
    lo, hi = 0.0, math.pi
    for _ in range(60):
        lo, hi = ((lo + hi) / 2, hi) if rest((lo + hi) / 2) < energy else (lo, (lo + hi) / 2)
    return hi


def omega2_range(p, energy: float, th_max: float = math.pi) -> float:
    """The largest |ω2| on the section at this energy (|θ2| <= th_max): where its minimum over ω1,
    C − B²/4A, reaches it."""
    th2 = np.linspace(-th_max, th_max, 1025)
    a, b, c0 = quadratic(p, th2, np.zeros_like(th2))
    _, b1, c1 = quadratic(p, th2, np.ones_like(th2))  # B and C − V are linear and quadratic in ω2
    room = np.maximum(energy - c0, 0.0) / (c1 - c0 - b1 * b1 / (4.0 * a))
    return 1.01 * math.sqrt(room.max())  # a margin for the grid's step


def shell_start(scene, th: np.ndarray, w: np.ndarray):
    """layout = "shell" (see the module docstring): th, w (N, 2) rewritten in place. Points of the R2 sequence
    in the box the section's accessible region fits in, kept where a positive ω1 gives them the energy: the
    region fills a fair part of its box at any energy, so a few rounds find them all."""
    p = reference.params(scene)
    energy = float(reference.energy(p, th[:1], w[:1])[0])
    if not energy > 0.0:
        raise SceneError(f"{scene.source}: pendulums.layout: \"shell\" starts pendulums with the energy of "
                         f"theta1, theta2, omega1, omega2, which is {energy:g} J here (the hanging rest, where "
                         f"the section is a point); give a start with some energy")
    th_max = reach(p, energy)
    w_max = omega2_range(p, energy, th_max)
    n, found, k = len(th), [], 0
    while sum(len(f[0]) for f in found) < n:
        j = np.arange(k, k + 2 * n + 64, dtype=np.float64)
        th2 = th_max * (2.0 * ((0.5 + j / PLASTIC) % 1.0) - 1.0)
        w2 = w_max * (2.0 * ((0.5 + j / PLASTIC ** 2) % 1.0) - 1.0)
        a, b, c = quadratic(p, th2, w2)
        disc = b * b - 4.0 * a * (c - energy)
        root = (-b + np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
        keep = (disc >= 0.0) & (root > 0.0)
        found.append((th2[keep], w2[keep], root[keep]))
        k += len(j)
    th2, w2, w1 = (np.concatenate(f)[:n] for f in zip(*found))
    th[:] = np.stack([np.zeros(n), th2], 1)
    w[:] = np.stack([w1, w2], 1)


# ------------------------------------------------------------------ the panel
def ticks(top: float, room: int = 3) -> list[float]:
    """Round values within ±top, 0 included: steps of 1, 2 or 5 times a power of ten, at most `room` each side."""
    for e in range(math.floor(math.log10(top)) - 1, math.ceil(math.log10(top)) + 2):
        for m in (1, 2, 5):
            step = m * 10.0 ** e
            if top // step <= room:
                return [k * step for k in range(-int(top // step), int(top // step) + 1)]
    return [0.0]


@ti.data_oriented
class Section(runtime.Launcher):
    """The panel of canvas `cv` in columns [x0, x0 + width) of its frame."""

    def __init__(self, cv, scene, sim, x0: int, width: int):
        self.cv, self.sim, self.n, self.fps = cv, sim, sim.n, scene.video.fps
        self.x0, self.width, self.height = x0, width, cv.h
        h = cv.h
        self.font_size = "10x20" if h >= 480 else "6x13"
        f = Font(self.font_size)
        cw, ch = f.text_width("0"), f.text_height("0")
        pad = max(3, ch // 3)
        top, bottom, left = ch + 2 * pad, 4 * pad + 2 * ch, 3 * pad + 7 * cw  # title; ticks + label; label + ticks
        self.side = max(8, min(h - top - bottom, width - left - 2 * pad))
        self.px = x0 + left + max(0, (width - left - pad - self.side) // 2)  # the plot, in frame pixels
        self.py = top + max(0, (h - top - bottom - self.side) // 2)
        q0, v0 = sim.initial_state()
        p = reference.params(scene)
        self.top = omega2_range(p, float(reference.energy(p, q0, v0).max()))  # energy only falls (damping)
        self.radius = max(0.7, 0.0016 * h)
        self.layer = runtime.field("poincare.points", ti.f32, (self.side, self.side), 3)
        self.background = self.decorate(f, scene, pad, cw, ch)
        self.restart()

    def restart(self):
        self.layer.fill(0)
        self.total, self.lost = 0, 0

    def decorate(self, f, scene, pad, cw, ch) -> np.ndarray:
        """The panel's static part: background, the plot's border, ticks and labels (as render/axes.py)."""
        bg = np.empty((self.height, self.width, 3), np.uint8)
        bg[:] = axes.BACKGROUND
        x0, y0, s = self.px - self.x0, self.py, self.side
        for x, y, w, h in ((x0 - 1, y0 - 1, s + 2, 1), (x0 - 1, y0 + s, s + 2, 1), (x0 - 1, y0 - 1, 1, s + 2),
                           (x0 + s, y0 - 1, 1, s + 2)):
            bg[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = axes.FRAME
        small = {"size": self.font_size, "colour": axes.INK}
        title = next((t for t in TITLE if len(t) * cw <= self.width - 2 * pad), "")
        texts = [(title, self.width // 2, pad, {**small, "ha": "center"}),
                 ("θ₂", x0 + s // 2, y0 + s + 3 * pad + ch, {**small, "ha": "center"}),
                 ("ω₂", max(x0 - 3 * pad - 4 * cw, 2 * cw), y0 + s // 2, {**small, "ha": "right", "va": "middle"})]
        for k in range(5):  # θ2: −π, −π/2, 0, π/2, π
            x = x0 + min(round(s * k / 4), s - 1)
            bg[y0 + s + 1:y0 + s + 1 + pad, x] = axes.FRAME
            if k % 2 == 0 or s // 4 >= 6 * cw:
                texts.append((axes.pi_label(-math.pi + k * math.pi / 2), x, y0 + s + 2 * pad,
                              {**small, "ha": "center"}))
        for v in ticks(self.top, max(1, min(3, s // (4 * ch)))):  # ω2 in rad/s, labels two lines apart
            y = y0 + min(round((self.top - v) / (2 * self.top) * s), s - 1)
            bg[y, max(x0 - 1 - pad, 0):x0 - 1] = axes.FRAME
            texts.append((axes.number(v), x0 - 2 * pad, y, {**small, "ha": "right", "va": "middle"}))
        f.draw_many(bg, [t for t in texts if t[0]])
        return bg

    def draw(self, out: np.ndarray, first: bool):
        """This frame's new crossings (none in the first frame) into the layer, then the panel into `out`."""
        out[:, self.x0:self.x0 + self.width] = self.background
        if not first:
            self.launch("poincare_plot")
            i, _, _, _, lost = read(self.sim, 0.0)
            self.total, self.lost = self.total + len(i), self.lost + lost
        self.launch("poincare_compose", out)

    def summary(self) -> dict:
        """For metadata.json."""
        return {"section": "theta1 = 0 mod 2 pi, omega1 > 0", "points": "(theta2, omega2)", "crossings": self.total,
                "lost": self.lost, "omega2_range": [-round(self.top, 6), round(self.top, 6)]}

    @ti.kernel
    def poincare_plot(self):
        s, r = ti.cast(self.side, ti.f32), self.radius
        for i in range(self.n):
            for k in range(ti.min(self.sim.crossed[i], SLOTS)):
                c = self.sim.crossings[i, k]
                th2 = c[1] - TAU * ti.floor((c[1] + math.pi) / TAU)  # wrapped to [−π, π)
                x = ti.cast((th2 + math.pi) / TAU, ti.f32) * s - 0.5
                y = ti.cast((self.top - c[2]) / (2.0 * self.top), ti.f32) * s - 0.5
                colour = self.cv.colour(i)
                for dy, dx in ti.ndrange((-2, 3), (-2, 3)):  # a disc of radius r (< 1.5 px), antialiased
                    py, px = int(ti.round(y)) + dy, int(ti.round(x)) + dx
                    d = ti.Vector([px - x, py - y]).norm()
                    cov = ti.min(ti.max(r + 0.5 - d, 0.0), 1.0)
                    if cov > 0.0 and 0 <= px < self.side and 0 <= py < self.side:
                        for ch in ti.static(range(3)):
                            ti.atomic_max(self.layer[py, px][ch], cov * colour[ch])

    @ti.kernel
    def poincare_compose(self, out: ti.types.ndarray(dtype=ti.u8, ndim=3)):
        for y, x in ti.ndrange(self.side, self.side):
            c = self.layer[y, x]
            if c.max() > 0.0:
                for ch in ti.static(range(3)):  # the canvas's byte over the background, a max (in i32: no u8 max)
                    b = ti.max(ti.cast(out[self.py + y, self.px + x, ch], ti.i32),
                               ti.cast(ti.min(c[ch], 1.0) * 255.0 + 0.5, ti.i32))
                    out[self.py + y, self.px + x, ch] = ti.cast(b, ti.u8)
