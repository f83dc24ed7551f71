"""Hopf oscillator network with stance/swing asymmetry (Righetti & Ijspeert 2008).

Each oscillator i has state (x_i, y_i), r_i^2 = x_i^2 + y_i^2:
    dx_i/dt = alpha (mu - r_i^2) x_i - omega_i y_i + k * c_x,i
    dy_i/dt = omega_i x_i + alpha (mu - r_i^2) y_i + k * c_y,i
    omega_i = omega_st / (exp(-a y_i) + 1) + omega_sw / (exp(a y_i) + 1)
    omega_st = (1 - beta) / beta * omega_sw
The limit cycle has radius sqrt(mu) and turns counter-clockwise; the upper half (y > 0) runs
at omega_st (stance), the lower at omega_sw (swing), so for large a the fraction of the period
with y > 0 (the duty factor) is beta and the period is pi/omega_st + pi/omega_sw.

Coupling ("rotation", the source's form): c_i = sum_{j != i} R(theta_ij) [x_j, y_j]^T with
R the 2-D rotation matrix. Offsets here are *lags* in cycles, the convention of
:mod:`cpg.analysis` ("cell k lags cell 0 by lag_k"): theta_ij = 2 pi (lag_j - lag_i), so the
coupling pulls oscillator i to the angle of j rotated back by i's extra lag.
``normalised=True`` is the ODE form of the source's normalised variant
X_i <- a_1 X_i + sum_j a_j |X_i| R X_j / |X_j| (a_1 + sum a_j = 1):
c_i = sum_{j != i} (r_i R(theta_ij) X_j / r_j - X_i). Only the neighbour's direction counts and
the term vanishes once the network is phase-locked, so the amplitude stays exactly sqrt(mu);
plain rotation coupling instead inflates it (in-phase lock: r^2 = mu + (N-1) k / alpha).
Time is in seconds when omega is in rad/s.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .integrate import Trajectory, rk4
from .morris_lecar import CELLS


@dataclass(frozen=True)
class HopfParams:
    mu: float = 1.0  # squared amplitude
    alpha: float = 10.0  # convergence rate to the limit cycle (1/s)
    omega_sw: float = 2 * np.pi * 1.5  # swing angular speed (rad/s)
    beta: float = 0.6  # duty factor (fraction of the period in stance, y > 0)
    a: float = 50.0  # steepness of the stance/swing switch
    k: float = 0.5  # coupling gain (1/s)
    normalised: bool = False

    def __post_init__(self):
        for name in ("mu", "alpha", "omega_sw", "a", "k", "beta"):
            v = getattr(self, name)
            if not np.isfinite(v):
                raise InputError(f"Hopf parameter {name} must be finite, got {v}")
        if self.mu <= 0 or self.alpha <= 0 or self.omega_sw <= 0 or self.a <= 0 or self.k < 0:
            raise InputError("Hopf parameters mu, alpha, omega_sw, a must be positive and k >= 0")
        if not 0 < self.beta < 1:
            raise InputError(f"duty factor beta must lie in (0, 1), got {self.beta}")

    @property
    def omega_st(self) -> float:
        return (1.0 - self.beta) / self.beta * self.omega_sw

    @property
    def period(self) -> float:
        """Period (s) of an uncoupled oscillator in the large-a limit."""
        return np.pi / self.omega_st + np.pi / self.omega_sw


# The four primary gaits as lags (cycles) of LF, RF, LE, RE behind LF, from the gait table.
GAIT_LAGS = {
    "walk": (0.0, 0.5, 0.5, 0.0),
    "run": (0.0, 0.5, 0.0, 0.5),
    "jump": (0.0, 0.0, 0.5, 0.5),
    "hop": (0.0, 0.0, 0.0, 0.0),
}


def gait_lags(gait: str) -> np.ndarray:
    try:
        return np.array(GAIT_LAGS[gait])
    except KeyError:
        raise InputError(f"unknown gait {gait!r} for the Hopf network: use "
                         f"{', '.join(GAIT_LAGS)}") from None


def theta_matrix(lags: np.ndarray) -> np.ndarray:
    """theta[i, j] = 2 pi (lag_j - lag_i) (rad) from lags (N,) in cycles."""
    lags = np.asarray(lags, dtype=float)
    if lags.ndim != 1 or not np.all(np.isfinite(lags)):
        raise InputError("phase lags must be a finite 1-D array")
    return 2 * np.pi * (lags[None, :] - lags[:, None])


def rhs(y: np.ndarray, p: HopfParams, theta: np.ndarray) -> np.ndarray:
    """dy/dt for a batch y (B, 2N) laid out [x_1..x_N, y_1..y_N]."""
    n = theta.shape[0]
    x, v = y[:, :n], y[:, n:]
    r2 = x * x + v * v
    om = p.omega_st / (np.exp(-p.a * v) + 1.0) + p.omega_sw / (np.exp(p.a * v) + 1.0)
    g = p.alpha * (p.mu - r2)
    c, s = np.cos(theta), np.sin(theta)
    np.fill_diagonal(c, 0.0)
    np.fill_diagonal(s, 0.0)
    if p.normalised:
        r = np.sqrt(r2) + 1e-12
        xn, vn = x / r, v / r
        m = n - 1
        cx = r * (xn @ c.T - vn @ s.T) - m * x
        cy = r * (xn @ s.T + vn @ c.T) - m * v
    else:
        cx = x @ c.T - v @ s.T  # sum_j cos(theta_ij) x_j - sin(theta_ij) y_j
        cy = x @ s.T + v @ c.T
    return np.concatenate([g * x - om * v + p.k * cx, om * x + g * v + p.k * cy], axis=1)


def simulate(lags, y0: np.ndarray, p: HopfParams = HopfParams(), t_end: float = 20.0,
             dt: float = 1e-3, t_record: float = 0.0, record_every: int = 1,
             noise: float = 0.0, seed: int = 0) -> Trajectory:
    """Integrate a batch of Hopf networks; records y (B, T, N) (the stance/swing coordinate).

    ``noise`` adds white noise of that standard deviation (per sqrt(s)) to every derivative,
    drawn from a seeded generator and held over each step.
    """
    theta = theta_matrix(lags)
    n = theta.shape[0]
    y0 = np.atleast_2d(np.asarray(y0, dtype=float))
    if y0.shape[1] != 2 * n:
        raise InputError(f"Hopf states must have shape (B, {2 * n}), got {y0.shape}")
    if not np.isfinite(noise) or noise < 0:
        raise InputError(f"noise must be a finite non-negative number, got {noise}")
    rng = np.random.default_rng(seed)
    n_steps = int(round(t_end / dt)) if dt > 0 else 0
    eps = noise / np.sqrt(dt) * rng.standard_normal((n_steps + 1,) + y0.shape) if noise else None

    def f(t, y, s):
        d = rhs(y, p, theta)
        return d if eps is None else d + eps[s]

    return rk4(f, y0, t_end, dt, t_record, record_every, output=lambda y: y[:, n:])


def random_states(n_osc: int, batch: int, seed: int = 0) -> np.ndarray:
    """Random initial states (batch, 2 n_osc) in [-1, 1]."""
    return np.random.default_rng(seed).uniform(-1.0, 1.0, (batch, 2 * n_osc))


def primary_gait(gait: str, p: HopfParams = HopfParams(), **kw) -> Trajectory:
    """The four ankle cells (LF, RF, LE, RE) of a primary gait from one random start."""
    return simulate(gait_lags(gait), random_states(len(CELLS), 1, kw.pop("seed", 0)), p, **kw)
