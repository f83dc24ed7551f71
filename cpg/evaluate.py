"""Batched evaluation of weight sets against a gait: the objectives the optimiser minimises.

Primary gaits (SEEDS.md eq. 6-9): z_k = wrapped |phase(LF, cell_k) - target_k| in degrees
(0..180) for k = RF, LE, RE, measured on the steady state of one integration from a fixed
initial state. Secondary gaits (two waveforms): from the gait table, for every pair of cells
with the same waveform label the phase error against 0 or 180 degrees and the waveform
distance, and for every pair with different labels how far they are from being distinct.

A set that diverges, does not oscillate, or does not lock all four cells to one rhythm gets
the worst objectives (180 degrees) and a positive constraint value, with the reason kept.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import morris_lecar as ml
from .analysis import analyze, wrap_deg
from .gaits import Gait, classify_rhythm, gait as gait_entry
from .integrate import Trajectory, simulate_ml

WORST_DEG = 180.0
SHAPE_TOL = 0.05  # waveform distance below which two cells carry the same waveform
DISTINCT = 0.10  # distance above which two waveforms count as clearly different


@dataclass(frozen=True)
class SimSettings:
    """How one evaluation integrates (model time units)."""

    t_end: float = 400.0
    t_settle: float = 250.0
    dt: float = 0.025
    record_every: int = 4


@dataclass
class Evaluation:
    """Per-member results of a batch: objectives F (B, n_obj), constraint G (B,), reasons."""

    F: np.ndarray
    G: np.ndarray
    reasons: list[str]
    classified: list[str]
    phases_deg: np.ndarray  # (B, 4) vs LF, NaN where undefined


def simulate_batch(i_app, phi, W, y0, s: SimSettings) -> Trajectory:
    return simulate_ml(i_app, phi, W, y0, t_end=s.t_end, dt=s.dt, t_record=s.t_settle,
                       record_every=s.record_every)


def _pattern_objectives(r, g: Gait) -> tuple[np.ndarray, float]:
    """(z (3,), constraint) of an analysed rhythm against a gait pattern."""
    if g.primary:
        z = wrap_deg(r.phases_deg[1:] - g.target_phases_deg)
        return z, float(r.shape_distance.max() - SHAPE_TOL)
    phase_err, same_dist, diff_gap = 0.0, 0.0, 0.0
    for i in range(4):
        for j in range(i + 1, 4):
            (li, si), (lj, sj) = g.pattern[i], g.pattern[j]
            if li == lj:
                phase_err = max(phase_err, float(wrap_deg(r.pair_phase_deg[i, j] - 360 * (sj - si))))
                same_dist = max(same_dist, float(r.shape_distance[i, j]))
            else:
                diff_gap = max(diff_gap, DISTINCT - float(r.shape_distance[i, j]))
    # Distances are scaled so that 0.01 of waveform distance weighs like 1.8 degrees.
    return np.array([phase_err, 180.0 * same_dist, 180.0 * max(diff_gap, 0.0)]), 0.0


LOCK_TOL_DEG = 2.0


def lock_time(t: np.ndarray, x: np.ndarray, g: Gait, period: float, t_end: float) -> float:
    """Model time after which the rhythm stays locked to the gait: the start of the first
    window (four periods long, stepped by one period) from which every later window has all
    objectives below ``LOCK_TOL_DEG``. ``t_end`` when it never locks."""
    if not np.isfinite(period) or period <= 0:
        return t_end
    starts = np.arange(t[0], t[-1] - 4 * period, period)
    ok = []
    for a in starts:
        sel = (t >= a) & (t < a + 4 * period)
        r = analyze(t[sel], x[sel], shape_tol=SHAPE_TOL, min_cycles=2)
        ok.append(bool(r.oscillating and r.locked.all()
                       and _pattern_objectives(r, g)[0].max() < LOCK_TOL_DEG))
    ok = np.array(ok, dtype=bool)
    if len(ok) == 0 or not ok[-1]:
        return t_end
    bad = np.nonzero(~ok)[0]
    return float(starts[bad[-1] + 1]) if len(bad) else float(starts[0])


def evaluate(gait: str, i_app, phi, W: np.ndarray, y0: np.ndarray,
             s: SimSettings = SimSettings(), with_lock_time: bool = False) -> Evaluation:
    """Objectives of directed weight matrices W (B, 4, 4) for a gait, one start state each.

    ``with_lock_time`` records from t = 0 and adds a fourth column: the time to lock (model
    units, :func:`lock_time`; ``t_end`` for a failed set)."""
    g = gait_entry(gait)
    if with_lock_time:
        tr_full = simulate_ml(i_app, phi, W, y0, t_end=s.t_end, dt=s.dt, t_record=0.0,
                              record_every=s.record_every)
        keep = tr_full.t >= s.t_settle
        tr = Trajectory(tr_full.t[keep], tr_full.x[:, keep], tr_full.final, tr_full.diverged,
                        tr_full.t_diverged)
    else:
        tr = simulate_batch(i_app, phi, W, y0, s)
    B = tr.x.shape[0]
    F = np.full((B, 3), WORST_DEG)
    G = np.ones(B)
    reasons, names = [], []
    phases = np.full((B, 4), np.nan)
    for b in range(B):
        if tr.diverged[b]:
            reasons.append(f"diverged at t={tr.t_diverged[b]:.1f}")
            names.append("none")
            continue
        r = analyze(tr.t, tr.x[b], shape_tol=SHAPE_TOL)
        names.append(classify_rhythm(r))
        if not r.oscillating:
            reasons.append(f"no oscillation: {r.reason}")
            continue
        if not r.locked.all():
            reasons.append("cells not locked to one rhythm")
            continue
        phases[b] = r.phases_deg
        F[b], G[b] = _pattern_objectives(r, g)
        reasons.append("ok" if G[b] <= 0 else "unequal waveforms")
    if with_lock_time:
        lock = np.full((B, 1), s.t_end)
        for b in range(B):
            if reasons[b] == "ok":
                lock[b, 0] = lock_time(tr_full.t, tr_full.x[b], g,
                                       analyze(tr.t, tr.x[b]).period, s.t_end)
        F = np.concatenate([F, lock], axis=1)
    return Evaluation(F, G, reasons, names, phases)


def reached(ev: Evaluation, gait: str, tol_deg: float = LOCK_TOL_DEG) -> np.ndarray:
    """Per member: the classifier names the gait and every phase objective is below tol_deg."""
    name = gait_entry(gait).name
    return np.array([c == name for c in ev.classified]) & (ev.F[:, :3].max(axis=1) < tol_deg)


def with_robustness(ev_fn, gait: str, i_app, phi, W: np.ndarray, y0: np.ndarray,
                    s: SimSettings, n_states: int, seed: int = 7, **kw) -> Evaluation:
    """``ev_fn`` (``evaluate`` or a Dask evaluator) plus a last column 1 - robustness: the
    fraction of ``n_states`` fixed random initial states that reach the gait, all in one batch."""
    B = W.shape[0]
    starts = np.vstack([np.broadcast_to(y0, (1, 8)), ml.random_states(n_states, seed)])
    n = len(starts)
    ev = ev_fn(gait, i_app, phi, np.repeat(W, n, axis=0), np.tile(starts, (B, 1)), s, **kw)
    frac = reached(ev, gait).reshape(B, n)[:, 1:].mean(axis=1)
    main = np.arange(B) * n
    return Evaluation(np.concatenate([ev.F[main], 1.0 - frac[:, None]], axis=1), ev.G[main],
                      [ev.reasons[k] for k in main], [ev.classified[k] for k in main],
                      ev.phases_deg[main])


def robustness(gait: str, i_app, phi, W: np.ndarray, n_states: int = 50, seed: int = 1,
               tol_deg: float = 2.0, s: SimSettings = SimSettings(t_end=800.0, t_settle=550.0)
               ) -> np.ndarray:
    """Fraction (P,) of ``n_states`` random initial states from which each of P weight
    matrices (P, 4, 4) reaches the gait: classifier names it and every objective < tol_deg."""
    W = np.asarray(W, dtype=float).reshape(-1, 4, 4)
    P = W.shape[0]
    y0 = ml.random_states(n_states, seed)
    Wb = np.repeat(W, n_states, axis=0)
    yb = np.tile(y0, (P, 1))
    ev = evaluate(gait, i_app, phi, Wb, yb, s)
    return reached(ev, gait, tol_deg).reshape(P, n_states).mean(axis=1)
