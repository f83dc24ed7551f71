"""Phase response of the coupled CPG and body to a push, against the phase of the push.

For one network and one feedback gain K: a horizontal push of ``impulse`` N s on the torso,
struck in one 4 ms control tick (``rollout.PUSH_TICK_S``: a phase response curve probes with a
brief perturbation, so that the phase it hits is one phase; the envelope's pushes are held
0.2 s), at each phase of the stride (phase 0: a left touchdown of the unperturbed rollout after
``envs.robustness.PUSH_AFTER_S``; :func:`cpgbiped.envs.experiments.robustness.stride_phase`), and the unperturbed
rollout beside it (the body may fall: the rollouts go on, the network keeps running).

- **CPG phase shift** dphi (cycles, in (-1/2, 1/2], > 0 advanced): the onsets of the left
  extensor's bursts (activation crossing 1/2 upwards) from ``SKIP_CYCLES`` to
  ``SKIP_CYCLES + MEASURE_CYCLES`` CPG cycles after the push, against the nearest onsets of the
  unperturbed rollout: dphi = -mean(t_pushed - t_unperturbed) / T_cpg. Open loop the network
  never hears the body, so dphi is exactly 0; with feedback the push reaches the network.
- **Re-lock** (CPG cycles): the body-to-CPG phase psi_k of each left touchdown (its delay after
  the last left-extensor onset, in cycles) settles back within ``LOCK_TOL`` of its value before
  the push; the count is the CPG cycles from the push to the first touchdown from which every
  later one stays within the tolerance: 0 when no touchdown left it (the push did not unlock
  them), None when the last ones are still out of it or the body fell.
"""
from __future__ import annotations

import numpy as np

from cpgbiped.cpg.network import Network

from cpgbiped.envs.gaits.gait_metrics import debounce, edges
from cpgbiped.envs.experiments.robustness import stride_phase
from cpgbiped.envs.simulation.rollout import PUSH_TICK_S, rollout

PHASES = tuple(np.round(np.arange(10) / 10, 2))
IMPULSE_NS = 5.0
SKIP_CYCLES, MEASURE_CYCLES = 4, 3
WINDOW_CYCLES = 9  # rollout length after the push, CPG cycles
LOCK_TOL = 0.05  # cycles


def _wrap(x):
    return (np.asarray(x, float) + 0.5) % 1.0 - 0.5


def onsets(t: np.ndarray, act: np.ndarray) -> np.ndarray:
    """Times where an activation crosses 1/2 upwards (linear interpolation)."""
    up = np.nonzero((act[:-1] < 0.5) & (act[1:] >= 0.5))[0]
    f = (0.5 - act[up]) / (act[up + 1] - act[up])
    return t[up] + f * (t[up + 1] - t[up])


def _psi(rec):
    """(touchdown times, their phase after the last left-extensor onset, in cycles)."""
    on = onsets(rec.t, rec.drive[:, 2])
    td, _ = edges(rec.t, debounce(rec.contact[:, 0], rec.dt))
    if len(on) < 3:
        return td, np.full(len(td), np.nan)
    T = float(np.median(np.diff(on)))
    k = np.searchsorted(on, td) - 1
    psi = np.where(k >= 0, (td - on[np.clip(k, 0, None)]) / T, np.nan)
    return td, psi


def phase_response(network: Network, K: float, phases=PHASES, impulse: float = IMPULSE_NS) -> dict:
    """dphi and re-lock cycles per push phase (see the module docstring)."""
    sp = stride_phase(network, K)
    if sp is None:
        return {"feedback_gain": float(K), "phases": list(map(float, phases)), "dphi": None,
                "relock_cycles": None, "note": "the unperturbed gait falls or does not step"}
    T_cpg_s = network.period_s()
    t_last = sp.time_at(max(phases))
    total = t_last + WINDOW_CYCLES * T_cpg_s
    ref = rollout(network, total, poses=False, feedback=K, stop_on_fall=False)
    on_ref = onsets(ref.t, ref.drive[:, 2])
    td_ref, psi_ref = _psi(ref)
    dphi, relock, fell = [], [], []
    for ph in phases:
        tp = sp.time_at(float(ph))
        rec = rollout(network, tp + WINDOW_CYCLES * T_cpg_s, push=(tp, impulse, PUSH_TICK_S),
                      poses=False,
                      feedback=K, stop_on_fall=False)
        fell.append(rec.fell_at is not None)
        on = onsets(rec.t, rec.drive[:, 2])
        lo, hi = tp + SKIP_CYCLES * T_cpg_s, tp + (SKIP_CYCLES + MEASURE_CYCLES) * T_cpg_s
        sel = on[(on >= lo) & (on < hi)]
        if len(sel) and len(on_ref):
            near = on_ref[np.argmin(np.abs(on_ref[None, :] - sel[:, None]), axis=1)]
            dphi.append(float(_wrap(-np.mean(sel - near) / T_cpg_s)))
        else:
            dphi.append(float("nan"))
        before = psi_ref[(td_ref < tp) & (td_ref >= tp - 3 * sp.period_s)]
        psi0 = float(np.nanmean(before)) if len(before) else float("nan")
        td, psi = _psi(rec)
        after = td > tp
        relock.append(_relock(td[after], psi[after], psi0, tp, T_cpg_s)
                      if rec.fell_at is None else None)
    return {"feedback_gain": float(K), "impulse_ns": float(impulse),
            "phases": list(map(float, phases)), "stride_period_s": sp.period_s,
            "cpg_period_s": T_cpg_s, "dphi": dphi, "relock_cycles": relock, "fell": fell}


def _relock(td, psi, psi0, tp, T) -> float | None:
    if not np.isfinite(psi0) or not len(td):
        return None
    ok = np.abs(_wrap(psi - psi0)) < LOCK_TOL
    if not ok[-1]:
        return None
    bad = np.nonzero(~ok)[0]
    if not len(bad):
        return 0.0
    return float(round((td[bad[-1] + 1] - tp) / T, 2))


def picture(results: list[dict], title: str, path) -> None:
    """dphi against the phase of the push (top) and re-lock cycles (bottom), one line per K."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cpgbiped.cpg.io import atomic_path

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 5.2), sharex=True)
    for r, color in zip(results, ("0.3", "tab:red", "tab:blue")):
        if r["dphi"] is None:
            continue
        lab = "open loop (K = 0)" if r["feedback_gain"] == 0 else f"feedback K = {r['feedback_gain']:g}"
        a1.plot(r["phases"], r["dphi"], "o-", color=color, label=lab)
        y = [np.nan if x is None else x for x in r["relock_cycles"]]
        a2.plot(r["phases"], y, "o-", color=color, label=lab)
        fell = [p for p, f in zip(r["phases"], r.get("fell", [])) if f]
        unlocked = [p for p, x, f in zip(r["phases"], r["relock_cycles"], r.get("fell", []))
                    if x is None and not f]
        a2.plot(fell, [-0.6] * len(fell), "x", color=color, ms=9,
                label="fell" if fell else None)
        a2.plot(unlocked, [-0.6] * len(unlocked), "^", color=color, mfc="none", ms=8,
                label="not re-locked in the window" if unlocked else None)
    a1.axhline(0, color="k", lw=0.6)
    a1.set_ylabel("CPG phase shift (cycles, + advanced)")
    a2.set_ylabel("cycles to re-lock body and CPG")
    a2.legend(fontsize=7)
    a2.set_xlabel("phase of the push in the stride (0: left touchdown)")
    a1.set_title(title, fontsize=10)
    a1.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
