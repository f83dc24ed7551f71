"""Physical validation of a gait: one rollout, contact metrics, and both verdicts.

``cpg_gait`` is what :func:`cpg.gaits.classify` names from the four CPG outputs recorded
during the rollout; ``physical_gait`` is what :mod:`envs.gait_metrics` names from the foot
contacts alone. A gait is physically real when the two agree and the body did not fall.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from cpg import morris_lecar as ml
from cpg.errors import InputError
from cpg.gaits import classify

from .biped import Recording, rollout
from .controller import GAIT_CONTROL
from .gait_metrics import GaitMetrics, measure

SETTLE_S = 2.0


@dataclass
class Validation:
    gait: str
    recording: Recording
    metrics: GaitMetrics
    cpg_gait: str

    def summary(self) -> dict:
        m = self.metrics
        return {
            "gait": self.gait, "fell": m.fell, "fell_at_s": m.fell_at_s,
            "unstable": self.recording.unstable,
            "duty_factor": m.duty_factor, "lr_phase_lag": m.lr_phase_lag,
            "double_support": m.double_support, "flight": m.flight,
            "stride_period_s": m.stride_period_s, "distance_m": m.distance_m,
            "speed_mps": m.speed_mps, "footfalls_per_stride": m.footfalls_per_stride,
            "physical_gait": m.physical_gait, "cpg_gait": self.cpg_gait,
            "passed": bool(not m.fell and m.physical_gait == self.gait == self.cpg_gait),
        }


def network_for(gait: str, weights=None):
    """(I_app, phi, W, y0): Table 2 for the gait, with optional (w_a, w_b, w_c) instead."""
    if gait not in GAIT_CONTROL:
        raise InputError(f"unknown gait {gait!r}: physical gaits are {', '.join(GAIT_CONTROL)}")
    p = ml.preset(gait)
    w = np.array(p.weights if weights is None else weights, dtype=float)
    if w.shape != (3,):
        raise InputError(f"weights must be three numbers (w_a, w_b, w_c), got shape {w.shape}")
    return p.i_app, p.phi, ml.weight_matrix(w), p.y0


def cpg_period(gait: str, weights=None) -> float:
    """Period (model units) of the gait's network, Table 2 or with (w_a, w_b, w_c) instead."""
    from cpg.reproduce import run_preset

    network_for(gait, weights)  # checks the gait and the weights' shape
    res = run_preset(gait, weights=weights)
    period = float("nan") if res.trajectory.diverged[0] else res.rhythm.period
    if not (np.isfinite(period) and period > 0):
        raise InputError(f"the {gait} network with weights {weights} does not oscillate")
    return float(period)


def control_for(gait: str, weights=None):
    """The gait's controller preset. With other weights the time scale is rescaled so that one
    CPG cycle lasts as long in seconds as with the paper's weights: the gains were tuned for
    that stride, and the network's rhythm (phases, waveforms, one stride per cycle) is kept."""
    p = GAIT_CONTROL[gait]
    if weights is None or np.allclose(np.asarray(weights, dtype=float), ml.preset(gait).weights):
        return p
    return replace(p, time_scale=p.time_scale * cpg_period(gait, weights) / cpg_period(gait))


def validate(gait: str, weights=None, seconds: float = 20.0, seed: int | None = None,
             friction_scale: float = 1.0, push: tuple[float, float] | None = None,
             settle_s: float = SETTLE_S, record_qpos: bool = False) -> Validation:
    """Roll out ``seconds`` after ``settle_s`` of settling and measure the gait."""
    if not (np.isfinite(seconds) and seconds > 0):
        raise InputError(f"seconds must be a positive number, got {seconds}")
    rec = rollout(network_for(gait, weights), control_for(gait, weights), seconds + settle_s,
                  seed=seed, friction_scale=friction_scale, push=push, record_qpos=record_qpos,
                  stop_on_fall=not record_qpos)
    fell_at = rec.fell_at if rec.unstable is None else (rec.t[-1] if len(rec.t) else 0.0)
    m = measure(rec.t, rec.contact, rec.com_x, fell_at, settle_s=settle_s)
    steady = rec.t >= settle_s
    cpg_name = classify(rec.t[steady], rec.cpg_v[steady])[0] if steady.sum() > 16 else "none"
    return Validation(gait, rec, m, cpg_name)


def metrics_table(summaries: dict[str, dict]) -> str:
    """Physical metrics and verdicts as text, from ``Validation.summary()`` per rollout."""
    from cpg.io import format_table

    rows = []
    for name, s in summaries.items():
        d = s["duty_factor"]
        rows.append([name, "yes" if s["fell"] else "no", f"{d['left']:.2f}/{d['right']:.2f}",
                     f"{s['lr_phase_lag']:.2f}", f"{s['double_support']:.2f}", f"{s['flight']:.2f}",
                     f"{s['stride_period_s']:.2f}", f"{s['distance_m']:.2f}",
                     s["physical_gait"], s["cpg_gait"], "PASS" if s["passed"] else "fail"])
    return format_table(rows, ["rollout", "fell", "duty L/R", "L-R lag", "double", "flight",
                               "stride s", "dist m", "physical", "cpg", "verdict"])
