"""Period, phase and waveform analysis of a set of rhythmic signals.

Works on any signals sampled on a uniform time grid: CPG outputs, joint angles, muscle
activations. The first signal is the reference (LF for the 4-cell network).

Method, for signals x (T, N) on times t (T,):
1. Upward crossings of the reference through its mid level (halfway between its 5th and 95th
   percentiles), with hysteresis (+-15% of the range) so noise cannot add crossings; crossing
   times are linearly interpolated. K >= ``min_cycles`` full cycles are required.
2. Period = (last crossing - first crossing) / K, in the units of t.
3. Phase of signal k relative to signal i: the difference of the arguments of their first
   Fourier coefficients over exactly those K cycles, in degrees in [0, 360). A signal that
   is a copy of the reference delayed by d has phase 360 d / period exactly (shift theorem).
   "Phase of k vs LF = 90" means k lags LF by a quarter cycle.
4. Mean cycle: each signal folded over the K cycles and averaged (M points per cycle), which
   averages noise away. Two signals have the same waveform when, after shifting one by their
   phase difference, the RMS of the difference of their mean cycles is below ``shape_tol``
   times the larger peak-to-peak range.
A signal oscillates at the common rhythm when its range is at least ``min_rel_range`` of the
reference's and its own period (crossings, or the autocorrelation for waveforms with several
humps per cycle) is within ``period_tol`` of the reference's.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

CYCLE_POINTS = 128


@dataclass
class Rhythm:
    """The analysis of N signals. Angles in degrees; period in the units of the time axis."""

    oscillating: bool
    reason: str = ""
    period: float = float("nan")
    n_cycles: int = 0
    phases_deg: np.ndarray = field(default_factory=lambda: np.full(0, np.nan))
    pair_phase_deg: np.ndarray = field(default_factory=lambda: np.full((0, 0), np.nan))
    locked: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    shape_distance: np.ndarray = field(default_factory=lambda: np.full((0, 0), np.nan))
    waveform_equal: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), bool))
    amplitude: np.ndarray = field(default_factory=lambda: np.full(0, np.nan))
    mean_cycle: np.ndarray = field(default_factory=lambda: np.full((0, 0), np.nan))

    @property
    def all_equal(self) -> bool:
        """All signals share one waveform (up to a time shift)."""
        return bool(self.oscillating and self.waveform_equal.all())


def wrap_deg(d):
    """Absolute angular distance in [0, 180] of angle differences in degrees."""
    d = np.mod(np.asarray(d, dtype=float), 360.0)
    return np.minimum(d, 360.0 - d)


def upward_crossings(t: np.ndarray, x: np.ndarray, hysteresis: float = 0.15) -> np.ndarray:
    """Interpolated times at which x rises through its mid level (with hysteresis)."""
    lo_p, hi_p = np.percentile(x, [5.0, 95.0])
    rng = hi_p - lo_p
    if not rng > 0:
        return np.empty(0)
    mid = 0.5 * (lo_p + hi_p)
    lo, hi = mid - hysteresis * rng, mid + hysteresis * rng
    state = np.where(x > hi, 1, np.where(x < lo, -1, 0))
    idx = np.arange(len(x))
    nz = np.where(state != 0, idx, -1)
    last = np.maximum.accumulate(nz)
    filled = np.where(last >= 0, state[np.maximum(last, 0)], 0)
    ks = np.nonzero((filled[1:] == 1) & (filled[:-1] == -1))[0] + 1
    if len(ks) == 0:
        return np.empty(0)
    below = np.maximum.accumulate(np.where(x < mid, idx, -1))
    j = below[ks - 1]
    j = j[j >= 0]
    x0, x1 = x[j], x[j + 1]
    frac = (mid - x0) / (x1 - x0)
    return t[j] + frac * (t[j + 1] - t[j])


def acf_period(t: np.ndarray, x: np.ndarray, min_peak: float = 0.3) -> float:
    """Repetition period of x from its autocorrelation (robust to noise and multi-hump waves).

    The period is the lag of the highest autocorrelation peak, except that a shorter lag
    whose peak is within 10% of it wins (a periodic signal also peaks at 2T, 3T, ...).
    Parabolic interpolation refines the lag. NaN when no peak reaches ``min_peak``.
    """
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    f = np.fft.rfft(x, 2 * n)
    ac = np.fft.irfft(f * np.conj(f))[: n // 2]
    if not ac[0] > 0:
        return float("nan")
    ac = ac / ac[0]
    k = np.nonzero((ac[1:-1] > ac[:-2]) & (ac[1:-1] >= ac[2:]) & (ac[1:-1] > min_peak))[0] + 1
    if len(k) == 0:
        return float("nan")
    best = k[np.argmax(ac[k])]
    k0 = k[ac[k] >= 0.9 * ac[best]][0]
    a, b, c = ac[k0 - 1], ac[k0], ac[k0 + 1]
    den = a - 2 * b + c
    shift = 0.5 * (a - c) / den if den != 0 else 0.0
    return float((k0 + shift) * (t[1] - t[0]))


def _fold(t: np.ndarray, x: np.ndarray, t0: float, period: float, k: int) -> np.ndarray:
    """Mean cycle (M, N) of signals x (T, N) over k cycles starting at t0."""
    grid = t0 + period * (np.arange(k)[:, None] + np.arange(CYCLE_POINTS)[None, :] / CYCLE_POINTS)
    grid = grid.ravel()
    folded = np.stack([np.interp(grid, t, x[:, n]) for n in range(x.shape[1])], axis=1)
    return folded.reshape(k, CYCLE_POINTS, x.shape[1]).mean(axis=0)


def _shift_cycle(c: np.ndarray, frac: float) -> np.ndarray:
    """Mean cycle c (M,) advanced by a fraction ``frac`` of a cycle (band-limited shift)."""
    f = np.fft.rfftfreq(len(c), d=1.0 / len(c))
    return np.fft.irfft(np.fft.rfft(c) * np.exp(2j * np.pi * f * frac), n=len(c))


def analyze(t: np.ndarray, x: np.ndarray, *, shape_tol: float = 0.05, min_cycles: int = 3,
            period_tol: float = 0.05, min_rel_range: float = 0.02,
            decay_tol: float = 0.2) -> Rhythm:
    """Analyse signals x (T, N) sampled at uniform times t (T,); signal 0 is the reference."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or t.ndim != 1 or x.shape[0] != t.shape[0]:
        raise InputError(f"signals must have shape (T, N) matching times (T,), got {x.shape} "
                         f"and {t.shape}")
    if x.shape[0] < 8:
        raise InputError(f"need at least 8 samples, got {x.shape[0]}")
    n = x.shape[1]
    if not np.all(np.isfinite(x)) or not np.all(np.isfinite(t)):
        return Rhythm(False, "non-finite values (diverged)")
    ranges = np.ptp(x, axis=0)
    scale = max(float(np.max(np.abs(x))), 1e-12)
    if ranges[0] <= 1e-6 * scale or ranges[0] < 1e-9:
        return Rhythm(False, "reference signal is constant")
    cross = upward_crossings(t, x[:, 0])
    k = len(cross) - 1
    if k < min_cycles:
        return Rhythm(False, f"fewer than {min_cycles} cycles of the reference in the window")
    t0, t1 = cross[0], cross[-1]
    period = (t1 - t0) / k
    # A decaying oscillation (approach to a fixed point) is no rhythm.
    edges = np.searchsorted(t, cross)
    cyc = np.maximum.reduceat(x[:, 0], edges[:-1]) - np.minimum.reduceat(x[:, 0], edges[:-1])
    half = max(1, k // 2)
    if np.mean(cyc[-half:]) < (1.0 - decay_tol) * np.mean(cyc[:half]):
        return Rhythm(False, "oscillation decays (approaching a fixed point)", period, k)
    sel = (t >= t0) & (t <= t1)
    ts, xs = t[sel], x[sel]
    w = np.exp(-2j * np.pi * (ts - t0) / period)
    coef = np.trapezoid((xs - xs.mean(axis=0)) * w[:, None], ts, axis=0)
    ang = np.degrees(np.angle(coef))
    pair = np.mod(ang[:, None] - ang[None, :], 360.0)  # pair[i, j]: phase of j vs i
    pair[pair > 360.0 - 1e-9] = 0.0
    locked = ranges >= min_rel_range * ranges[0]
    for i in range(1, n):
        if locked[i]:
            c = upward_crossings(t, x[:, i])
            p_i = (c[-1] - c[0]) / (len(c) - 1) if len(c) > 1 else np.nan
            if not abs(p_i - period) <= period_tol * period:  # multi-hump or noisy: use the ACF
                p_i = acf_period(t, x[:, i])
            if not abs(p_i - period) <= period_tol * period:
                locked[i] = False
    cycle = _fold(t, x, t0, period, k)
    amp = np.ptp(cycle, axis=0)
    dist = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            shifted = _shift_cycle(cycle[:, j], pair[i, j] / 360.0)
            d = np.sqrt(np.mean((cycle[:, i] - shifted) ** 2)) / max(amp[i], amp[j], 1e-12)
            dist[i, j] = dist[j, i] = d
    equal = (dist < shape_tol) & locked[:, None] & locked[None, :]
    phases = pair[0].copy()
    phases[~locked] = np.nan
    pair[~locked, :] = np.nan
    pair[:, ~locked] = np.nan
    return Rhythm(True, "", float(period), k, phases, pair, locked, dist, equal, amp, cycle)

