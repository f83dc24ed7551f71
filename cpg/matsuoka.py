"""The 12-neuron two-leg Matsuoka network of Dong, Wang, Shen & Zhang (SEEDS.md section B).

Neuron i (time in seconds):
    (tau / k_f) dx_i/dt = -x_i - beta v_i + k_i r + sum_{j != i} w_ij y_j + L e_i(t)
    T dv_i/dt = -v_i + y_i,        y_i = max(x_i, 0)
Neurons 0-5: one leg (0/1 hip extensor/flexor, 2/3 knee, 4/5 ankle), 6-11 the other leg in
the same order. ``W[i, j]`` is the weight from donor j to receiver i.

Noise: e_i are independent standard normal samples, drawn from a seeded generator and held
for one integration step (``dt``, 1 ms by default): band-limited white noise of unit variance
entering the x equation with gain L, as the paper writes it.

What the printed parameters do (measured here, tests/test_matsuoka.py): the network oscillates
robustly (same orbit from random states) but at 0.096 Hz, not the claimed 1 Hz: the adaptation
time constant T = 2.5 s sets the period. Noise-free, the left/right legs are exactly half a
cycle apart; each hip flexor neuron bursts twice per cycle, so the hip pair's net drive
(extensor - flexor) has two humps, while its repetition rate is that of every other pair.

``CALIBRATED`` reaches the paper's claims with two documented changes:
1. tau = 0.0769 s, T = 0.1922 s (T/tau = 2.5 instead of 20.8): 1.000 Hz noise-free, every
   joint pair (ext - flex) repeating at 1 Hz, the legs half a cycle apart. Scaling tau and T
   together (t -> c t) keeps the printed ratio but then the hip pair repeats at 3x the knee.
2. r = 8 with the initial state scaled by r: the network is positively homogeneous
   ((x, v, r) -> (c x, c v, c r) maps solutions to solutions; max(., 0) is homogeneous), so
   the rhythm is the same and only the signal-to-noise ratio changes. With r = 1 the paper's
   L = 1.5 noise is as large as the tonic drive and speeds the rhythm up by 3-10%; with r = 8
   every pair stays within 2% of 1 Hz and the legs within a few degrees of half a cycle.
The paper does not give its noise bandwidth or the signal scale, so this is a calibration
of what it left unstated, not a claim about its simulation.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .errors import InputError
from .integrate import Trajectory, rk4

N_NEURONS = 12
NEURONS = tuple(f"{leg}_{joint}_{role}" for leg in ("L", "R")
                for joint in ("hip", "knee", "ankle") for role in ("ext", "flex"))

# Printed weight matrix (row i = receiver, column j = donor); row 3's OCR extra 0 dropped.
W_PRINTED = np.array([
    [0, -2.5, 1, 1, 1, 1, -1, 0, 0, 0, 0, 0],
    [-2.5, 0, -1, -1, -1, -1, 0, -1, 0, 0, 0, 0],
    [0.1, 0.1, 0, -2.5, 0.2, 0.2, 0, 0, -1, 0, 0, 0],
    [-0.1, -0.1, -2.5, 0, -0.2, -0.2, 0, 0, 0, -1, 0, 0],
    [0.2, 0.2, 0.1, 0.1, 0, -2.5, 0, 0, 0, 0, -1, 0],
    [-0.2, -0.2, -0.1, -0.1, -2.5, 0, 0, 0, 0, 0, 0, -1],
    [-1, 0, 0, 0, 0, 0, 0, -2.5, 1, 1, 1, 1],
    [0, -1, 0, 0, 0, 0, -2.5, 0, -1, -1, -1, -1],
    [0, 0, -1, 0, 0, 0, 0.1, 0.1, 0, -2.5, 0.2, 0.2],
    [0, 0, 0, -1, 0, 0, -0.1, -0.1, -2.5, 0, -0.2, -0.2],
    [0, 0, 0, 0, -1, 0, 0.2, 0.2, 0.1, 0.1, 0, -2.5],
    [0, 0, 0, 0, 0, -1, -0.2, -0.2, -0.1, -0.1, -2.5, 0],
], dtype=float)


@dataclass(frozen=True)
class MatsuokaParams:
    tau: float = 0.12  # rise time constant (s)
    T: float = 2.5  # adaptation time constant (s)
    beta: float = 2.5  # adaptation strength
    r: float = 1.0  # tonic input
    L: float = 1.5  # noise gain
    k_f: float = 1.0  # frequency factor
    k_i: float = 1.0  # input gain

    def __post_init__(self):
        for name, v in self.__dict__.items():
            if not np.isfinite(v):
                raise InputError(f"Matsuoka parameter {name} must be finite, got {v}")
        if self.tau <= 0 or self.T <= 0 or self.k_f <= 0:
            raise InputError("Matsuoka time constants tau, T and k_f must be positive")
        if self.L < 0:
            raise InputError(f"noise gain L must be >= 0, got {self.L}")

    def time_scaled(self, c: float) -> "MatsuokaParams":
        """The same network running c times slower (tau and T times c)."""
        return replace(self, tau=self.tau * c, T=self.T * c)


PRINTED = MatsuokaParams()
CALIBRATED = MatsuokaParams(tau=0.0769, T=0.1922, r=8.0)

X0 = np.array([1.0, -1.0] * 6)  # the paper's initial state, for r = 1
V0 = np.ones(N_NEURONS)
JOINTS = ("L_hip", "L_knee", "L_ankle", "R_hip", "R_knee", "R_ankle")


def initial_state(p: MatsuokaParams) -> np.ndarray:
    """The paper's x0, v0 scaled by the tonic input r (homogeneity), shape (1, 24)."""
    return p.r * np.concatenate([X0, V0])[None]


def joint_drive(y: np.ndarray) -> np.ndarray:
    """Net drive extensor - flexor per joint (..., 6) in ``JOINTS`` order from outputs (..., 12)."""
    return y[..., 0::2] - y[..., 1::2]


def simulate(p: MatsuokaParams = CALIBRATED, t_end: float = 20.0, dt: float = 1e-3,
             t_record: float = 0.0, record_every: int = 1, seed: int = 0,
             W: np.ndarray = W_PRINTED, y0: np.ndarray | None = None) -> Trajectory:
    """Integrate a batch (B from y0, default 1 at the paper's x0, v0); records y (B, T, 12)."""
    W = np.asarray(W, dtype=float)
    if W.shape != (N_NEURONS, N_NEURONS) or not np.all(np.isfinite(W)):
        raise InputError(f"Matsuoka weights must be a finite (12, 12) matrix, got {W.shape}")
    if y0 is None:
        y0 = initial_state(p)
    y0 = np.atleast_2d(np.asarray(y0, dtype=float))
    if y0.shape[1] != 2 * N_NEURONS:
        raise InputError(f"Matsuoka states must have shape (B, 24) = [x x12, v x12], got {y0.shape}")
    n_steps = int(round(t_end / dt)) if dt > 0 else 0
    rng = np.random.default_rng(seed)
    noise = p.L * rng.standard_normal((n_steps + 1, y0.shape[0], N_NEURONS)) if p.L else None
    rate = p.k_f / p.tau

    def f(t, y, s):
        x, v = y[:, :N_NEURONS], y[:, N_NEURONS:]
        out = np.maximum(x, 0.0)
        drive = -x - p.beta * v + p.k_i * p.r + out @ W.T
        if noise is not None:
            drive = drive + noise[s]
        return np.concatenate([rate * drive, (out - v) / p.T], axis=1)

    return rk4(f, y0, t_end, dt, t_record, record_every,
               output=lambda y: np.maximum(y[:, :N_NEURONS], 0.0))


@dataclass
class RhythmReport:
    """What a parameter set does: frequencies (Hz) and left-right phases (deg) per joint."""

    oscillating: bool
    frequency_hz: float
    pair_frequency_hz: np.ndarray  # (6,) repetition rate of each joint's net drive
    lr_phase_deg: np.ndarray  # (3,) hip, knee, ankle: right-leg drive vs left-leg drive


def rhythm_report(p: MatsuokaParams, seconds: float = 40.0, seed: int = 0,
                  settle: float = 10.0) -> RhythmReport:
    """Simulate and measure the claims of the paper (frequency, equal rates, L/R half cycle)."""
    from .analysis import acf_period, analyze

    tr = simulate(p, t_end=settle + seconds, dt=1e-3, t_record=settle, record_every=2, seed=seed)
    drive = joint_drive(tr.x[0])
    order = [1, 0, 2, 4, 3, 5]  # left knee first: its single-hump waveform is the reference
    r = analyze(tr.t, drive[:, order], shape_tol=0.1)
    if not r.oscillating:
        return RhythmReport(False, float("nan"), np.full(6, np.nan), np.full(3, np.nan))
    rates = np.array([1.0 / acf_period(tr.t, drive[:, i]) for i in range(6)])
    lr = np.array([r.pair_phase_deg[1, 4], r.pair_phase_deg[0, 3], r.pair_phase_deg[2, 5]])
    return RhythmReport(True, 1.0 / r.period, rates, lr)
