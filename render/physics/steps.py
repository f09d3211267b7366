"""One step of each integration method, written once as Taichi functions (their facts: integrators.METHOD).

A method works on any system: it needs only the system's `force(q, v)` (and, for the implicit midpoint, its
canonical hooks `momenta`, `velocities`, `momentum_rate` and `p_scale`). States are "lane matrices": row k is
coordinate k, column l is pendulum l of a group (see System.advance), so a method is plain matrix arithmetic.
The method is chosen at compile time with ti.static, so a run compiles only the one it uses.
"""
import taichi as ti

# Yoshida's 4th-order composition of three velocity-Verlet steps.
_CBRT2 = 2.0 ** (1.0 / 3.0)
YOSHIDA_W1 = 1.0 / (2.0 - _CBRT2)
YOSHIDA_W0 = -_CBRT2 / (2.0 - _CBRT2)


@ti.func
def step(sys: ti.template(), q, v, h):
    """One step of sys.method from (q, v)."""
    if ti.static(sys.method == "symplectic_euler"):
        q, v = symplectic_euler(sys, q, v, h)
    elif ti.static(sys.method == "verlet"):
        q, v = verlet(sys, q, v, h)
    elif ti.static(sys.method == "yoshida4"):
        q, v = verlet(sys, q, v, YOSHIDA_W1 * h)
        q, v = verlet(sys, q, v, YOSHIDA_W0 * h)
        q, v = verlet(sys, q, v, YOSHIDA_W1 * h)
    elif ti.static(sys.method == "rk2"):
        q, v = rk2(sys, q, v, h)
    elif ti.static(sys.method == "rk4"):
        q, v = rk4(sys, q, v, h)
    elif ti.static(sys.method == "implicit_midpoint"):
        q, v = implicit_midpoint(sys, q, v, h)
    return q, v


@ti.func
def symplectic_euler(sys: ti.template(), q, v, h):
    """The seed's v += a·h; x += v·h. Symplectic for a separable system (springs) only: on the rigid chain
    (θ, ω) are not canonical, so its energy error grows slowly (see docs/accuracy.md)."""
    v += h * sys.force(q, v)
    return q + h * v, v


@ti.func
def verlet(sys: ti.template(), q, v, h):
    """Velocity Verlet. Damping −c·v, the one force that depends on v on the systems that offer it, is split off
    symmetrically (Strang): half a step of it, the undamped Verlet step, half a step of it. Kept in the kicks, it
    was taken at mid-step velocities and the step was first order (tests/test_physics.py's springs damped
    0.7 1/s: observed orders 1.02 for verlet, 1.00 for yoshida4, which was 2.1e-3 m off DOP853 after 1 s at dt
    1e-3). Symmetric, it is second order and Yoshida's composition of it fourth
    (test_damping_keeps_the_symmetric_methods_order)."""
    if ti.static(sys.damped):
        fade = decay(0.5 * h * sys.damping)
        v *= fade
        v += 0.5 * h * (sys.force(q, v) + sys.damping * v)  # the undamped accelerations
        q += h * v
        v += 0.5 * h * (sys.force(q, v) + sys.damping * v)
        v *= fade
    else:
        v += 0.5 * h * sys.force(q, v)
        q += h * v
        v += 0.5 * h * sys.force(q, v)
    return q, v


@ti.func
def decay(y):
    """e^−y by its (2, 2) Padé approximant: fourth order, no libm call (whose last bits differ between CPUs),
    and R(−y) = 1 / R(y), so a step of negative length (Yoshida's middle one) undoes one of positive length. Its
    denominator has no real root: the trapezoidal (1, 1) form, (1 − y/2) / (1 + y/2), has one at y = −2, which
    Yoshida's middle step reached at h·c = 1.175, inside the stability limit a heavily damped scene is offered."""
    return (1.0 - y / 2.0 + y * y / 12.0) / (1.0 + y / 2.0 + y * y / 12.0)


@ti.func
def rk2(sys: ti.template(), q, v, h):
    """The explicit midpoint rule: a half step of Euler, then the full step with the midpoint's slopes.
    Two force evaluations per step, second order; between symplectic Euler (1) and rk4 (4) at equal cost."""
    a1 = sys.force(q, v)
    vm = v + 0.5 * h * a1
    return q + h * vm, v + h * sys.force(q + 0.5 * h * v, vm)


@ti.func
def rk4(sys: ti.template(), q, v, h):
    dq, dv = rk4_increment(sys, q, v, h)
    return q + dq, v + dv


@ti.func
def rk4_increment(sys: ti.template(), q, v, h):
    """What one RK4 step adds to (q, v): rk4's own arithmetic, so rk4 gives the same bits, and the
    certificate's shadow adds it with compensated sums (System.advance_group)."""
    a1 = sys.force(q, v)
    q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
    a2 = sys.force(q2, v2)
    q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
    a3 = sys.force(q3, v3)
    q4, v4 = q + h * v3, v + h * a3
    a4 = sys.force(q4, v4)
    return h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4), h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)


@ti.func
def add_compensated(x, dx, carry):
    """x + dx by Kahan's compensated sum: (the new x, the new carry), the carry holding what the rounding of
    the sum lost. Over the 10^5-10^6 steps of a run, plain sums let the state's rounding (half an ulp of the
    angle a step, biased alike in runs at other steps) grow to 1e-11 rad and more, and chaos grows it to the
    tolerance: an RK4 shadow at a quarter of the step then erred as much as the run it checks, and alike
    (render/trust/certify.py). Fast2Sum's carry is exact while |x| ≥ |dx|, which holds but where a velocity
    crosses 0: there it errs by an ulp of the step's change, ~1e-18. Needs IEEE arithmetic (fast_math off,
    runtime.init), or (t − x) − y folds to 0."""
    y = dx - carry
    t = x + y
    return t, (t - x) - y


@ti.func
def column_norm_sqr(m):
    """|column|² of each lane of a lane matrix."""
    return ti.Vector([m[:, lane].norm_sqr() for lane in ti.static(range(m.get_shape()[1]))])


@ti.func
def implicit_midpoint(sys: ti.template(), q, v, h):
    """The midpoint rule in canonical (q, p), solved by fixed-point iteration until every lane moves less
    than sys.tol (at most 100 sweeps). It is symplectic only in canonical coordinates: applied to (θ, ω) of
    a rigid chain its symplecticity defect shrinks only like h³ and energy creeps."""
    p = sys.momenta(q, v)
    q1, p1 = q + h * v, p + h * sys.momentum_rate(q, v, p)
    pscale = sys.p_scale(h)
    for _ in range(100):
        qm, pm = 0.5 * (q + q1), 0.5 * (p + p1)
        vm = sys.velocities(qm, pm)
        qn, pn = q + h * vm, p + h * sys.momentum_rate(qm, vm, pm)
        err = ti.max(column_norm_sqr(qn - q1), column_norm_sqr(pn - p1) * pscale * pscale).max()
        q1, p1 = qn, pn
        if err <= sys.tol * sys.tol:
            break
    return q1, sys.velocities(q1, p1)
