"""Secondary gaits that the body performs: ``cpgbiped secondary --physics``.

The network search (:func:`cpgbiped.cpg.search.secondary_search`) finds weight sets whose cells
the CPG classifier names a secondary gait, and keeps the one with the smallest pattern errors;
the body performs few of them (README, "Secondary gaits in the body"). With ``--physics`` the
choice among the network's candidates is made by the body, as ``optimize --physics`` does for
the primary gaits:

1. **Target lags.** The contact rules (:data:`cpgbiped.envs.gaits.criteria.SECONDARY_PATTERNS`)
   tell the hesitation walk, the gallop and the asymmetric hop apart by the left-right lag of
   the touchdowns; the paper's patterns fix which cells share a waveform, not the lag between
   the two waveforms. For these three the network search runs once per target lag of a grid
   over the lags the rule admits (:func:`lag_grid`, ``LAG_STEP`` apart), with a fourth
   objective that pulls the extensors' lag to it. The grid is a sweep of the network's
   extensor lag over the band the contact rule admits for the touchdowns: the body's
   touchdown lag does not follow the extensors' one to one (a hesitation walk chosen at an
   extensor lag of 0.18 steps at 0.41 from 0), which is why the body, not the grid, chooses.
   For the skip and the one-legged hop, whose rules are not lags, the search runs once, as
   without ``--physics``.
2. **Candidates.** Every Pareto point of those searches that the CPG classifier names the
   target from the Table 3 state (the network search's own criterion: it searches from that
   state, as the paper does), with its extensor lag within ``LAG_MATCH`` of the target lag,
   its weights rounded as the results file stores them.
3. **Selection by the body.** Each candidate drives the body from ``states`` random initial
   CPG states, seeds ``SELECTION_SEED`` and up (CPG states the controller's tuning uses too:
   never the Table 3 state, from which ``check-secondary`` then judges the chosen set, nor the
   tests' seeds 10-19 or the census's 3000 and up), for ``SELECTION_SECONDS`` after the
   settling. Score: the states in which both classifiers name the target and the body does not
   fall, less the states in which it falls (since session 40; the confirmations alone before),
   then fewer falls, then the smaller sum of the network's objectives. The best candidate
   is the target's weight set in the results file, with a ``physics`` entry saying how it was
   chosen; a target without candidates keeps the plain search's point.
"""
from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from cpgbiped.cpg import morris_lecar as ml
from cpgbiped.cpg.evaluate import SimSettings
from cpgbiped.cpg.optimize import SECONDARY_TARGETS, RunSettings, SymmetryBreakingProblem

from cpgbiped.envs.gaits.criteria import LAG_AWAY, LAG_TOGETHER, LAG_UNEQUAL

LAG_STEP = 0.03  # cycles between the target lags of one target's grid
SELECTION_SEED = 1000  # first random CPG state of the selection (tuning states, disjoint from tests)
SELECTION_SECONDS = 20.0  # s after settling, as check-secondary
MAX_STATES = 32

# The touchdown lags (circular distance from 0, cycles) each contact rule admits.
LAG_BANDS = {
    "hesitation_walk": (LAG_AWAY, 0.5 - LAG_UNEQUAL),  # >= LAG_AWAY from 0, >= LAG_UNEQUAL from 0.5
    "gallop": (LAG_AWAY, 0.5 - LAG_AWAY),  # >= LAG_AWAY from both
    "asymmetric_hop": (0.0, LAG_TOGETHER),  # feet together
}


def lag_grid(target: str) -> list[float] | None:
    """Target lags (cycles) for ``target``: its band from LAG_BANDS, LAG_STEP apart from the
    band's lower end; None for a target whose contact rule is not a lag."""
    if target not in LAG_BANDS:
        return None
    lo, hi = LAG_BANDS[target]
    return [round(float(x), 3) for x in np.arange(lo, hi + 1e-9, LAG_STEP)]


def selection_seeds(states: int) -> list[int]:
    return list(range(SELECTION_SEED, SELECTION_SEED + int(states)))


def _rollout(args) -> dict:
    target, source, w12, i_app, phi, seed, seconds = args
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.cpg.network import build

    from cpgbiped.envs.gaits.validate import validate

    net = build("ml", source, weights=list(w12), i_app=i_app, phi=phi, seed=seed)
    try:
        net.period()
    except InputError:  # no rhythm from this state: no rollout, not a fall
        return {"cpg_gait": "none", "physical_gait": "none", "fell": None, "confirmed": False,
                "lr_phase_lag": None}
    s = validate(net, None, seconds).summary()
    return {"cpg_gait": s["cpg_gait"], "physical_gait": s["physical_gait"], "fell": s["fell"],
            "confirmed": bool(s["cpg_gait"] == target == s["physical_gait"] and not s["fell"]),
            "lr_phase_lag": s["lr_phase_lag"]}


def _map(fn, jobs, workers: int) -> list:
    if workers > 1 and len(jobs) > 1:
        from cpgbiped.envs.simulation.trials import quiet_worker

        with ProcessPoolExecutor(min(workers, len(jobs)),
                                 mp_context=multiprocessing.get_context("spawn"),
                                 initializer=quiet_worker) as ex:
            return list(ex.map(fn, jobs, chunksize=4))
    return [fn(j) for j in jobs]


def net_rank(confirmed: int, falls: int) -> tuple:
    """The body's part of :func:`score` from counts (smaller is better): the most
    confirmations net of falls, then the fewest falls (scripts/merge_secondary.py --by net
    ranks two files' sets by it too)."""
    return (-(confirmed - falls), falls)


def score(rows: list[dict], objectives) -> tuple:
    """Sort key of one candidate (smaller is better): the most confirmations net of falls
    (each fall counts against one confirmation: a set the body confirms in 12 states and
    falls from in 4 is worth 8, one confirmed in 9 without a fall 9; a state without a rhythm,
    ``fell`` None, is no fall), then the fewest falls, then the smallest sum of the network
    objectives. Until session 40 the confirmations alone came first, and the body chose sets
    that fall often (docs/RESULTS.md, "Secondary gaits in the body")."""
    confirmed = sum(r["confirmed"] for r in rows)
    falls = sum(r["fell"] is True for r in rows)
    return net_rank(confirmed, falls) + (float(np.sum(objectives)),)


def physics_secondary(primary_weights: dict, rs: RunSettings, settings: SimSettings = SimSettings(),
                      states: int = 6, seconds: float = SELECTION_SECONDS, workers: int = 2,
                      evaluator=None, progress=None, targets=SECONDARY_TARGETS,
                      on_target=None, note=None) -> list[dict]:
    """The secondary results (as :func:`cpgbiped.cpg.search.secondary_all`), each target's
    weight set chosen by the body; see the module docstring. ``on_target(entry)`` is called
    as each target is done, ``note(text)`` says what runs now (a progress bar's label)."""
    from cpgbiped.cpg.search import secondary_point, secondary_search

    if not 1 <= int(states) <= MAX_STATES:
        from cpgbiped.cpg.errors import InputError

        raise InputError(f"--states must be in [1, {MAX_STATES}], got {states}")
    seeds = selection_seeds(states)
    n_searches = sum(len(lag_grid(t) or [None]) for t, _, _, _ in targets)
    done = 0
    out = []
    for target, source, keep, paper in targets:
        base = primary_weights[source]
        cands = []
        for lag in lag_grid(target) or [None]:
            done += 1
            if note is not None:
                note(f"{target} from the {source}: network search {done} of {n_searches}")
            plain = secondary_search(target, source, keep, base, rs, settings,
                                     evaluator=evaluator, progress=progress, target_lag=lag,
                                     candidates=True)
            cands += [dict(c, target_lag=lag) for c in plain.pop("candidates")]
        p = ml.preset(source)
        jobs = [(target, source, c["directed_weights"], p.i_app, p.phi, s, seconds)
                for c in cands for s in seeds]
        if note is not None and jobs:
            note(f"{target} from the {source}: the body, {len(cands)} candidates x "
                 f"{len(seeds)} states")
        rows = _map(_rollout, jobs, workers)
        per = [rows[k * len(seeds):(k + 1) * len(seeds)] for k in range(len(cands))]
        if cands:
            k = min(range(len(cands)), key=lambda j: score(per[j], cands[j]["objectives"]))
            c = cands[k]
            problem = SymmetryBreakingProblem(target, source, keep, base, 1.0, settings,
                                              target_lag=c["target_lag"])
            entry = secondary_point(problem, base, c["directed_weights"], c["objectives"], rs,
                                    settings)
            entry["physics"] = {
                "states": seeds, "seconds": seconds, "candidates": len(cands),
                "target_lag": c["target_lag"], "extensor_lag": round(c["extensor_lag"], 4),
                "confirmed_states": int(sum(r["confirmed"] for r in per[k])),
                "falls": int(sum(r["fell"] is True for r in per[k])),
                "physical_gaits": [r["physical_gait"] for r in per[k]],
                "touchdown_lags": [r["lr_phase_lag"] for r in per[k]],
                "confirmed_per_candidate": [int(sum(r["confirmed"] for r in q)) for q in per],
                "falls_per_candidate": [int(sum(r["fell"] is True for r in q)) for q in per]}
        elif lag_grid(target) is None:
            entry = plain  # the plain search's point
            entry["physics"] = {"states": seeds, "seconds": seconds, "candidates": 0}
        else:  # no candidate at any target lag: the plain search's point
            if note is not None:
                note(f"{target} from the {source}: no candidate, the plain network search")
            entry = secondary_search(target, source, keep, base, rs, settings,
                                     evaluator=evaluator, progress=progress)
            entry["physics"] = {"states": seeds, "seconds": seconds, "candidates": 0}
        entry["paper_reached"] = paper
        out.append(entry)
        if on_target is not None:
            on_target(entry)
    return out
