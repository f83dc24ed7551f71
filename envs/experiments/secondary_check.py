"""Secondary gaits in the body: every weight set that ``cpgbiped secondary`` found, through the
one controller.

Each target of a secondary results file (format ``cpg.results.SECONDARY_FORMAT``) is a
Morris-Lecar network: its 12 directed weights, I_app and phi, started from the Table 3 state of
the primary gait it was broken from. It drives the body for ``seconds`` after the settling
window; the CPG classifier names the gait of the cells, the contact classifier (primary
patterns, then the secondary ones of :data:`cpgbiped.envs.gaits.criteria.SECONDARY_PATTERNS`) the gait of the
body. A target is confirmed physically when both name it and the body does not fall.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.morris_lecar import DIRECTED_NAMES

KEYS = ("physical_gait", "cpg_gait", "fell", "fell_at_s", "duty_factor", "lr_phase_lag",
        "flight", "double_support", "stride_period_s", "speed_mps", "footfalls_per_stride")


def load_secondary(path) -> list[dict]:
    """The targets of a secondary results file, each checked before any rollout."""
    from cpgbiped.cpg.results import SECONDARY_SCHEMA, read_json_file

    p = Path(path)
    data = read_json_file(p, SECONDARY_SCHEMA, "cpgbiped secondary results file")
    targets = data["targets"]
    out = []
    for t in targets:  # the schema has checked names, types and phi > 0; finite numbers too
        w = t["directed_weights"]
        out.append({"target": t["target"], "source": t["source"],
                    "weights": [float(w[n]) for n in DIRECTED_NAMES],
                    "i_app": float(t["i_app"]), "phi": float(t["phi"]),
                    "found": bool(t.get("found", False))})
    return out


def _one(args):
    t, seconds = args
    from cpgbiped.cpg.network import build

    from cpgbiped.envs.gaits.validate import validate

    net = build("ml", t["source"], weights=t["weights"], i_app=t["i_app"], phi=t["phi"])
    try:
        net.period()
    except InputError as e:
        return {"source": t["source"], "found_in_network": t["found"], "error": str(e),
                "cpg_gait": "none", "physical_gait": "none", "fell": None, "confirmed": False}
    s = validate(net, None, seconds).summary()
    row = {"source": t["source"], "found_in_network": t["found"], **{k: s[k] for k in KEYS}}
    row["confirmed"] = bool(s["cpg_gait"] == t["target"] == s["physical_gait"] and not s["fell"])
    return row


def check_secondary(path, seconds: float = 20.0, workers: int = 2) -> dict:
    """{"<target> from <source>": {cpg_gait, physical_gait, fell, confirmed, metrics}}."""
    targets = load_secondary(path)
    jobs = [(t, seconds) for t in targets]
    if workers > 1 and len(jobs) > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from cpgbiped.envs.simulation.trials import quiet_worker

        with ProcessPoolExecutor(min(workers, len(jobs)),
                                 mp_context=multiprocessing.get_context("spawn"),
                                 initializer=quiet_worker) as ex:
            rows = list(ex.map(_one, jobs))
    else:
        rows = [_one(j) for j in jobs]
    out = {}
    for t, r in zip(targets, rows):  # a target found twice: the second named by its source
        out[t["target"] if t["target"] not in out else f"{t['target']} from {t['source']}"] = r
    return out


def table(res: dict) -> str:
    from cpgbiped.cpg.io import format_table

    rows = []
    for name, r in res.items():
        f = lambda x: "-" if x is None or not np.isfinite(x) else f"{x:.2f}"  # noqa: E731
        rows.append([name, "yes" if r["found_in_network"] else "no", r["cpg_gait"],
                     r["physical_gait"], "-" if r["fell"] is None else ("yes" if r["fell"] else "no"),
                     f(r.get("lr_phase_lag")), f(r.get("flight")),
                     "CONFIRMED" if r["confirmed"] else "-"])
    return format_table(rows, ["target", "found in network", "cpg", "physical", "fell",
                               "L-R lag", "flight", "in the body"])
