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


# ------------------------------------------------------------------ compiled single network
try:
    import numba

    @numba.njit(cache=True, inline="always")
    def _rhs4(y, dy, mu, alpha, om_st, om_sw, a, k, normalised, C, S):
        n = 4
        for i in range(n):
            x, v = y[i], y[n + i]
            r2 = x * x + v * v
            om = om_st / (np.exp(-a * v) + 1.0) + om_sw / (np.exp(a * v) + 1.0)
            g = alpha * (mu - r2)
            cx = 0.0
            cy = 0.0
            if normalised:
                ri = np.sqrt(r2) + 1e-12
                for j in range(n):
                    if j != i:
                        rj = np.sqrt(y[j] * y[j] + y[n + j] * y[n + j]) + 1e-12
                        xn, vn = y[j] / rj, y[n + j] / rj
                        cx += ri * (C[i, j] * xn - S[i, j] * vn) - x
                        cy += ri * (S[i, j] * xn + C[i, j] * vn) - v
            else:
                for j in range(n):
                    if j != i:
                        cx += C[i, j] * y[j] - S[i, j] * y[n + j]
                        cy += S[i, j] * y[j] + C[i, j] * y[n + j]
            dy[i] = g * x - om * v + k * cx
            dy[n + i] = om * x + g * v + k * cy

    @numba.njit(cache=True)
    def _kernel(y0, mu, alpha, a, k, normalised, beta_a, omsw_a, theta_a, beta_b, omsw_b,
                theta_b, knot_t, knot_alpha, dt, n_steps, rec_start, rec_every, bound, out, final):
        """RK4 of one 4-oscillator network; parameters blended along the knots (model time);
        returns the step of divergence (0 = none)."""
        y = y0.copy()
        k1 = np.empty(8)
        k2 = np.empty(8)
        k3 = np.empty(8)
        k4 = np.empty(8)
        tmp = np.empty(8)
        C = np.empty((4, 4))
        S = np.empty((4, 4))
        last = -1.0
        om_st = 0.0
        om_sw = 0.0
        r = 0
        n_rec = out.shape[0]
        K = knot_t.shape[0]
        for s in range(n_steps + 1):
            if r < n_rec and s == rec_start + r * rec_every:
                for i in range(4):
                    out[r, i] = y[4 + i]
                r += 1
            if s == n_steps:
                break
            t = s * dt
            al = 0.0
            if K > 0:
                if t <= knot_t[0]:
                    al = knot_alpha[0]
                elif t >= knot_t[K - 1]:
                    al = knot_alpha[K - 1]
                else:
                    for q in range(1, K):
                        if t < knot_t[q]:
                            al = knot_alpha[q - 1] + (knot_alpha[q] - knot_alpha[q - 1]) * (
                                t - knot_t[q - 1]) / (knot_t[q] - knot_t[q - 1])
                            break
            if al != last:
                beta = beta_a + al * (beta_b - beta_a)
                om_sw = omsw_a + al * (omsw_b - omsw_a)
                om_st = (1.0 - beta) / beta * om_sw
                for i in range(4):
                    for j in range(4):
                        th = theta_a[i, j] + al * (theta_b[i, j] - theta_a[i, j])
                        C[i, j] = np.cos(th)
                        S[i, j] = np.sin(th)
                last = al
            _rhs4(y, k1, mu, alpha, om_st, om_sw, a, k, normalised, C, S)
            for q in range(8):
                tmp[q] = y[q] + 0.5 * dt * k1[q]
            _rhs4(tmp, k2, mu, alpha, om_st, om_sw, a, k, normalised, C, S)
            for q in range(8):
                tmp[q] = y[q] + 0.5 * dt * k2[q]
            _rhs4(tmp, k3, mu, alpha, om_st, om_sw, a, k, normalised, C, S)
            for q in range(8):
                tmp[q] = y[q] + dt * k3[q]
            _rhs4(tmp, k4, mu, alpha, om_st, om_sw, a, k, normalised, C, S)
            for q in range(8):
                y[q] += dt / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])
                if not (abs(y[q]) < bound):
                    for rr in range(r, n_rec):
                        for i in range(4):
                            out[rr, i] = np.nan
                    final[:] = np.nan
                    return s + 1
        final[:] = y
        return 0

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - numba is a pinned dependency
    HAVE_NUMBA = False


def simulate_one(lags, y0, p: HopfParams, t_end: float, dt: float = 1e-3, t_record: float = 0.0,
                 record_every: int = 1, to: tuple | None = None, knots=None) -> Trajectory:
    """One 4-oscillator network (compiled): like :func:`simulate` without noise, records y
    (1, T, 4). ``to`` = (lags_b, params_b) and ``knots`` = (t (K,), alpha (K,)) in seconds blend
    the lags (hence theta), beta and omega_sw from this network's to ``to``'s."""
    from .integrate import BLOWUP, _check_timing

    n_steps, rec_start = _check_timing(t_end, dt, t_record, record_every)
    theta_a = theta_matrix(lags)
    y0 = np.asarray(y0, dtype=float).ravel()
    if y0.shape != (8,) or not np.all(np.isfinite(y0)):
        raise InputError("a Hopf state of four oscillators is 8 finite numbers")
    if to is None:
        theta_b, pb = theta_a, p
        kt = ka = np.empty(0)
    else:
        theta_b, pb = theta_matrix(to[0]), to[1]
        for name in ("mu", "alpha", "a", "k", "normalised"):
            if getattr(pb, name) != getattr(p, name):
                raise InputError(f"Hopf parameter {name} cannot change in mid-run")
        kt, ka = (np.asarray(x, dtype=float) for x in knots)
    rec = np.arange(rec_start, n_steps + 1, int(record_every))
    out = np.empty((len(rec), 4))
    final = np.empty(8)
    div = _kernel(y0, p.mu, p.alpha, p.a, p.k, p.normalised, p.beta, p.omega_sw, theta_a,
                  pb.beta, pb.omega_sw, theta_b, kt, ka, float(dt), n_steps, rec_start,
                  int(record_every), BLOWUP, out, final)
    diverged = np.array([div > 0])
    return Trajectory(rec * dt, out[None], final[None], diverged,
                      np.where(diverged, div * dt, np.nan))
