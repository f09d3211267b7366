"""The step limit: a bound on the fastest rate of the linearised dynamics over every state the run can reach.

A conservative system keeps its energy (damping only lowers it), and the energy watchdog stops a run whose
energy drifts by more than integrator.max_drift, so every state of the run lies in the set
{E(q, v) ≤ E_max·(1 + max_drift)}, E_max the largest initial energy of the scene. For a chain of rigid links this bound is
the largest spectral radius of the Jacobian of (θ, ω) ↦ (ω, θ'') over that set, without damping (the step
limit adds the damping rate: integrators.timestep). It is found by sampling: angles everywhere
(random, plus every aligned and folded configuration), and velocities on the energy shell along random
directions and along M(θ)'s eigenvectors (the soft mode is the "whip" of a heavy lower bob). The Jacobian is
taken by central differences of render/reference.py's independent model; the largest radius found, times
MARGIN for the gaps between samples, is the bound. A step h is stable for a method when h·bound stays below
the method's limit (integrators.STABILITY).
"""
import dataclasses
import itertools
import math

import numpy as np

from . import reference
from .system import DEFAULT_MAX_DRIFT

MARGIN = 1.25  # over the largest sampled radius: covers what falls between the samples
SAMPLES = 1024  # random configurations
DIRECTIONS = 4  # random velocity directions per configuration, besides M(θ)'s eigenvectors


def chain_rate(scene, q0: np.ndarray, v0: np.ndarray) -> float:
    """Bound (rad/s) on |eigenvalues| of the linearised chain over every state with E ≤ max E(q0, v0)."""
    p = dataclasses.replace(reference.params(scene), damping=0.0)  # timestep adds the damping rate
    n = len(p.lengths)
    e_max = float(np.max(reference.energy(p, q0, v0))) * (1 + (scene.integrator.max_drift or DEFAULT_MAX_DRIFT))
    rng = np.random.default_rng(0)  # the same bound for the same scene, every run
    corners = np.array(list(itertools.product((0.0, math.pi), repeat=n)))
    th = np.concatenate([corners, rng.uniform(-math.pi, math.pi, (SAMPLES, n))])
    rest = np.zeros_like(th)
    room = e_max - reference.energy(p, th, rest)  # kinetic energy left at each configuration
    th = th[room >= 0]
    room = room[room >= 0]
    mass = reference.chain_mass(th, p)
    dirs = [np.linalg.eigh(mass)[1][:, :, k] for k in range(n)]  # the soft and the stiff modes
    dirs += [rng.normal(size=th.shape) for _ in range(DIRECTIONS)]
    states_q, states_v = [], []
    for u in dirs:  # undamped, the Jacobian at −v has the negated spectrum of that at v: one sign is enough
        kin = 0.5 * np.einsum("ni,nij,nj->n", u, mass, u)
        states_q.append(th)
        states_v.append(u * np.sqrt(room / kin)[:, None])
    return MARGIN * spectral_radius(p, np.concatenate(states_q), np.concatenate(states_v))


def spectral_radius(p, q: np.ndarray, v: np.ndarray) -> float:
    """Largest |eigenvalue| of d(q, v)/dt's Jacobian over the states (N, D), by central differences."""
    n, d = q.shape
    jac = np.zeros((n, 2 * d, 2 * d))
    jac[:, :d, d:] = np.eye(d)
    for k in range(d):
        step = np.zeros(d)
        step[k] = 1e-6
        jac[:, d:, k] = (reference.accel(p, q + step, v) - reference.accel(p, q - step, v)) / 2e-6
        scale = 1e-6 * max(1.0, float(np.abs(v).max()))
        step[k] = scale
        jac[:, d:, d + k] = (reference.accel(p, q, v + step) - reference.accel(p, q, v - step)) / (2 * scale)
    return float(np.abs(np.linalg.eigvals(jac)).max())
