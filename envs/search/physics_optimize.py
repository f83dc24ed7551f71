"""``cpgbiped optimize --physics``: run the physical NSGA-II and write its results, atomically.

Files in the output folder (all replaced at once when the run succeeds):
- ``<gait>_physics.json`` (format "cpgbiped.optimize/1", ``"kind": "physics"``, the format
  ``check-pareto`` reads): ``chosen``, ``pareto`` (each point: weights, i_app, phi, its
  objectives and its unperturbed rollout's metrics), ``paper`` (the Table 2 row scored the
  same way), ``front`` (the end-to-end spread of the Pareto set), ``settings``, the
  ``perturbations`` every point met, and the top-level ``i_app``/``phi`` of the chosen point;
- ``<gait>_physics_population.csv`` and ``<gait>_physics_pareto.csv``;
- ``<gait>_physics_pareto.png``: the three 2-D projections of the objectives.

The Pareto set is taken over every point evaluated during the search (the final population
alone crowds into one region). The chosen point is a feasible Pareto point that passes every
criterion of its gait, as ``validate`` judges it, when any does (the objectives do not score
every criterion: a hop's stride regularity, for one), then the most robust (fewest failed
perturbation trials), then the one closest to the Froude target, then the cheapest. A
checkpoint beside the folder lets an interrupted run resume (the same command again); a run
that ends removes it.
"""
from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.io import write_json
from cpgbiped.cpg.optimize import RunSettings, run
from cpgbiped.cpg.outdir import run_checkpointed
from cpgbiped.cpg.results import FORMAT
from cpgbiped.cpg.search import plot_front, write_csv

from cpgbiped.envs.search.physics_search import (FROUDE_TARGET, I_APP_BOUNDS, OBJECTIVES, PHI_BOUNDS, VARIABLES,
                             WEIGHT_BOUNDS, PhysicsGaitProblem, PhysicsSettings, check_gait,
                             initial_population, paper_point, trial_failed)

METRICS = ("froude", "speed_mps", "cost_of_transport", "work_per_stride_J", "duty", "flight",
           "stride_period_s", "apex_height_m", "physical_gait", "cpg_gait", "fell",
           "passes_criteria")


def checkpoint_name(gait: str) -> str:
    return f"{gait}_physics.checkpoint.pkl"


def _point(gait, x, f, g, results) -> dict:
    base = results[0].as_dict()
    # Full precision: the body is chaotic enough that weights rounded to 1e-6 walk differently
    # (measured: a chosen run that did not fall in the search fell at 11.7 s once rounded).
    return {"weights": [float(v) for v in x[:3]], "i_app": float(x[3]), "phi": float(x[4]),
            "objectives": {n: round(float(v), 6) for n, v in zip(OBJECTIVES, f)},
            "constraint": round(float(g), 6), "feasible": bool(g <= 0),
            "metrics": {k: base[k] for k in METRICS},
            "perturbation_failures": [trial_failed(gait, r) for r in results[1:]]}


def choose(points: list[dict]) -> int:
    """Index of the chosen point among feasible points: one whose unperturbed rollout passes
    every criterion of its gait (``metrics.passes_criteria``; any point when none does), then
    the fewest failed perturbation trials, then the smallest Froude error, then the smallest
    cost. The search's objectives score speed, cost and survival, not every criterion (a hop's
    stride regularity, for one): a point can be on the front and fail ``validate``."""
    def key(k):
        p = points[k]
        fails = not p.get("metrics", {}).get("passes_criteria")  # missing or None: not known
        return (fails, *(p["objectives"][n] for n in ("failed_fraction", "froude_error", "cost")))
    return min(range(len(points)), key=key)


def spread(values) -> float:
    """End-to-end relative spread of positive values: max / min - 1 (NaN for fewer than 2)."""
    v = np.asarray([x for x in values if x is not None and np.isfinite(x) and x > 0], float)
    return float(v.max() / v.min() - 1.0) if len(v) >= 2 else float("nan")


def optimize_physics(gait: str, rs: RunSettings, out: str | Path, settings: PhysicsSettings,
                     runner, progress=None, stop_after: int | None = None) -> dict:
    """Run the physical NSGA-II for ``gait``; write its files into ``out`` (see the module
    docstring). ``runner`` rolls out lists of trials (:mod:`cpgbiped.envs.simulation.trials`); the caller closes
    it. ``stop_after``: stop after that many generations of this call (tests of resuming)."""
    check_gait(gait)
    return run_checkpointed(out, checkpoint_name(gait), lambda rd, ckpt: _optimize(
        rd, ckpt, gait, rs, settings, runner, progress, stop_after))


def _optimize(rd, ckpt, gait, rs, settings, runner, progress, stop_after) -> dict:
    t0 = time.perf_counter()
    problem = PhysicsGaitProblem(gait, settings, rs.seed, runner)
    res = run(problem, rs, checkpoint=ckpt, on_generation=progress, stop_after=stop_after,
              sampling=initial_population(gait, rs.pop, rs.seed))
    # The Pareto set over every point the search evaluated, and the paper's row, rolled out
    # again for their metrics (every rollout is deterministic: the objectives come out as the
    # search saw them).
    X_opt, _ = problem.pareto_set()
    X_all = np.vstack([X_opt, paper_point(gait)[None], res.X])
    F_all, G_all, trials = problem.evaluate_points(X_all)
    n = len(X_opt)
    points = [_point(gait, X_all[k], F_all[k], G_all[k], trials[k]) for k in range(n)]
    paper = _point(gait, X_all[n], F_all[n], G_all[n], trials[n])
    pop = slice(n + 1, None)
    if not points:
        raise InputError(f"no feasible point for {gait}: all {len(problem.archive_X)} points "
                         f"evaluated fall or make another gait (by the contacts or the CPG "
                         f"classifier, which needs 3 CPG cycles in the window); raise --pop, "
                         f"--gens or --seconds")
    k = choose(points)
    front = {
        "n_points": n, "n_evaluated": int(len(problem.archive_X)),
        "froude_spread": spread(p["metrics"]["froude"] for p in points),
        "cost_spread": spread(p["objectives"]["cost"] for p in points),
        "froude_range": [min(p["metrics"]["froude"] for p in points),
                         max(p["metrics"]["froude"] for p in points)],
        "cost_range": [min(p["objectives"]["cost"] for p in points),
                       max(p["objectives"]["cost"] for p in points)],
    }
    result = {
        "format": FORMAT, "kind": "physics", "gait": gait,
        "i_app": points[k]["i_app"], "phi": points[k]["phi"],
        "variables": list(VARIABLES), "objectives": list(OBJECTIVES),
        "bounds": {"weights": list(WEIGHT_BOUNDS), "i_app": list(I_APP_BOUNDS),
                   "phi": list(PHI_BOUNDS)},
        "settings": {"pop": rs.pop, "gens": rs.gens, "seed": rs.seed,
                     "physics": asdict(settings)},
        "froude_target": settings.froude,
        "perturbations": problem.conditions,
        "chosen": points[k], "pareto": points, "paper": paper, "front": front,
        "n_generations": res.n_gen, "resumed_from_generation": res.resumed_from,
        "wall_s": round(time.perf_counter() - t0, 3),
    }
    head = [*VARIABLES, *OBJECTIVES, "constraint", "froude", "speed_mps", "cost_of_transport",
            "duty", "flight", "physical_gait", "cpg_gait", "fell", "passes_criteria"]
    rows = lambda X, F, G, T: [  # noqa: E731
        [*np.round(x, 6), *np.round(f, 6), round(float(g), 6),
         *[t[0].as_dict()[c] for c in head[len(VARIABLES) + len(OBJECTIVES) + 1:]]]
        for x, f, g, t in zip(X, F, G, T)]
    write_csv(rd.path(f"{gait}_physics_population.csv"), head,
         rows(X_all[pop], F_all[pop], G_all[pop], trials[pop]))
    write_csv(rd.path(f"{gait}_physics_pareto.csv"), head,
         rows(X_all[:n], F_all[:n], G_all[:n], trials[:n]))
    plot_front(rd.path(f"{gait}_physics_pareto.png"), F_all[pop], F_all[:n],
               f"{gait} in physics: NSGA-II pop {rs.pop}, {res.n_gen} generations, seed "
               f"{rs.seed}, Fr* {settings.froude:g}", OBJECTIVES, symlog=False)
    write_json(rd.path(f"{gait}_physics.json"), result)
    return result


def default_settings(gait: str, froude: float | None = None, seconds: float | None = None,
                     n_trials: int | None = None, feedback: float = 0.0) -> PhysicsSettings:
    """The settings of a run, each left as None taking its default (:class:`PhysicsSettings`;
    the Froude target from :data:`FROUDE_TARGET`)."""
    check_gait(gait)
    d = PhysicsSettings(FROUDE_TARGET[gait])
    return PhysicsSettings(d.froude if froude is None else float(froude),
                           d.seconds if seconds is None else float(seconds),
                           n_trials=d.n_trials if n_trials is None else int(n_trials),
                           feedback=float(feedback))
