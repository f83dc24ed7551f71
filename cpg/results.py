"""Optimiser result files: their formats and a reader that needs no optimiser (no pymoo).

``<gait>.json`` (format "cpgbiped.optimize/1", written by :func:`cpg.search.optimize_primary`):
``chosen`` {weights, errors_deg, robustness}, ``pareto`` (list of the same), ``paper``,
``settings``, ``i_app`` and ``phi``; ``<gait>_physics.json`` (the same format, ``"kind":
"physics"``, written by :func:`cpgbiped.envs.search.physics_optimize.optimize_physics`) also gives each point
its own ``i_app`` and ``phi`` and its ``objectives``. ``secondary.json`` (format "cpgbiped.secondary/1").
Readers of results (validate --weights, check-pareto, the demo, the dm_control "free" task)
import this module only, so they start without loading pymoo.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import InputError

FORMAT = "cpgbiped.optimize/1"
SECONDARY_FORMAT = "cpgbiped.secondary/1"


def load_result(path: str | Path) -> dict:
    """A primary-gait result file, validated; clear errors for anything else."""
    import json

    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise InputError(f"result file {str(p)!r} does not exist") from None
    except (OSError, ValueError) as e:
        raise InputError(f"result file {str(p)!r} is not readable JSON: {e}") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{str(p)!r} is not a cpgbiped optimiser result (format {FORMAT})")
    try:
        w = np.array(data["chosen"]["weights"], dtype=float)
        pareto = [np.array(q["weights"], dtype=float) for q in data["pareto"]]
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{str(p)!r} lacks chosen/pareto weights") from None
    for v in [w] + pareto:
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise InputError(f"{str(p)!r} holds weights that are not three finite numbers")
    try:
        cell = [float(data["i_app"]), float(data["phi"])]
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{str(p)!r} lacks the network's i_app and phi") from None
    if not all(np.isfinite(cell)):
        raise InputError(f"{str(p)!r} holds an i_app or phi that is not finite")
    # A physical search (``"kind": "physics"``) varies I_app and phi too: each point has its own.
    for q in [data["chosen"]] + list(data["pareto"]):
        for key in ("i_app", "phi"):
            if key in q:
                try:
                    ok = np.isfinite(float(q[key]))
                except (TypeError, ValueError):
                    ok = False
                if not ok:
                    raise InputError(f"{str(p)!r} holds a point whose {key} is not finite")
    return data


def point_cell(data: dict, point: dict) -> tuple[float, float]:
    """(I_app, phi) of a point of a result: its own where it has them, else the file's."""
    return (float(point.get("i_app", data["i_app"])), float(point.get("phi", data["phi"])))
