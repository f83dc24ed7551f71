"""Reproduce the paper's primary gaits from its Table 2 weights and Table 3 initial states."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import morris_lecar as ml
from .analysis import Rhythm
from .gaits import classify, phase_errors
from .integrate import DT_ML, Trajectory, simulate_ml

T_END = 500.0  # model time units
T_SETTLE = 250.0  # the analysis uses the second half


@dataclass
class GaitResult:
    gait: str
    trajectory: Trajectory
    rhythm: Rhythm
    classified_as: str

    def summary(self) -> dict:
        r = self.rhythm
        ph = r.phases_deg if r.oscillating else np.full(4, np.nan)
        return {
            "period": r.period if r.oscillating else float("nan"),
            "phases_deg": dict(zip(ml.CELLS[1:], np.round(ph[1:], 3))),
            "errors_deg": np.round(phase_errors(ph, self.gait), 3).tolist(),
            "waveforms_equal": r.all_equal,
            "classified_as": self.classified_as,
        }


def run_preset(gait: str, y0: np.ndarray | None = None, t_end: float = T_END,
               t_settle: float = T_SETTLE, dt: float = DT_ML, weights=None) -> GaitResult:
    """Simulate a Table 2 preset (from Table 3's state unless y0 is given; with
    (w_a, w_b, w_c) = ``weights`` instead of Table 2's when given) and classify it."""
    p = ml.preset(gait)
    w = np.asarray(p.weights if weights is None else weights, dtype=float)
    tr = simulate_ml(p.i_app, p.phi, ml.weight_matrix(w), p.y0 if y0 is None else y0,
                     t_end=t_end, dt=dt, t_record=t_settle)
    name, rhythm = classify(tr.t, tr.x[0])
    return GaitResult(gait, tr, rhythm, name)


def reproduce(gaits=ml.PRIMARY_GAITS, **kw) -> dict[str, GaitResult]:
    return {g: run_preset(g, **kw) for g in gaits}


def table(summaries: dict[str, dict]) -> str:
    """The reproduction as text, from ``GaitResult.summary()`` per gait."""
    from .io import format_table

    rows = [[g, f"{s['period']:.3f}", *(f"{s['phases_deg'][c]:.2f}" for c in ("RF", "LE", "RE")),
             "yes" if s["waveforms_equal"] else "no", s["classified_as"]]
            for g, s in summaries.items()]
    return format_table(rows, ["gait", "period", "RF", "LE", "RE", "same wave", "classified"])
