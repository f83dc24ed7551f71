"""Tune the one controller with pymoo's GA: one corner of the blended gains, or the shared ones.

    python scripts/tune_controller.py --gait run [--pop 60] [--gens 50] [--seconds 10] \
        [--seed 1] [--conditions table3,seed:10,friction:0.7] [--start]
    python scripts/tune_controller.py --shared [--gaits walk,run,jump,hop] ...

``--gait G`` searches the gains of the corner G's Morris-Lecar preset sits at, scored on G
alone (envs.tuning); ``--shared`` searches the shared parameters (ankle gain, swing wiring,
the Morris-Lecar time unit), scored on ``--gaits``. Everything else stays as in
envs.controller.CONTROL. The fitness (envs.tuning.fitness) comes from the acceptance criteria
in envs/criteria.py, averaged over ``--conditions``. Without ``--start`` the first population is
random over the ranges; with it, the present values plus points around them. Prints the best
values, ready to paste into envs/controller.py.
"""
from __future__ import annotations

import argparse
import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def _fitness(args):
    from envs.tuning import fitness

    x, conds, seconds, gaits = args
    return fitness(x, conds, seconds, gaits)


def current(key: str) -> float:
    from cpg.network import ML_UNITS_PER_S
    from envs.controller import CONTROL

    if key == "units_per_s":
        return ML_UNITS_PER_S
    if "." in key:
        corner, gain = key.split(".")
        return getattr(CONTROL.corner(corner), gain)
    return getattr(CONTROL, key)


def main(argv=None):
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    from envs.tuning import GAITS, parse_conditions, space

    ap = argparse.ArgumentParser()
    who = ap.add_mutually_exclusive_group(required=True)
    who.add_argument("--gait", choices=GAITS, help="tune the corner of this gait's preset")
    who.add_argument("--shared", action="store_true", help="tune the shared parameters")
    ap.add_argument("--gaits", default=",".join(GAITS), help="with --shared: scored gaits")
    ap.add_argument("--pop", type=int, default=60)
    ap.add_argument("--gens", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--conditions", default="table3,seed:1,seed:2,friction:0.7")
    ap.add_argument("--start", action="store_true")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    conds = parse_conditions(a.conditions)
    sp = space(None if a.shared else a.gait)
    gaits = tuple(a.gaits.split(",")) if a.shared else (a.gait,)
    keys = list(sp)
    lo = np.array([sp[k][0] for k in keys])
    hi = np.array([sp[k][1] for k in keys])
    pool = ProcessPoolExecutor(a.workers, mp_context=multiprocessing.get_context("spawn"))

    class Tune(Problem):
        def __init__(self):
            super().__init__(n_var=len(keys), n_obj=1, xl=lo, xu=hi)

        def _evaluate(self, X, out, *args, **kw):
            jobs = [(dict(zip(keys, map(float, x))), conds, a.seconds, gaits) for x in X]
            out["F"] = np.array(list(pool.map(_fitness, jobs)))

    kw = {}
    if a.start:
        x0 = np.array([current(k) for k in keys])
        rng = np.random.default_rng(a.seed)
        sampling = np.clip(x0 + 0.08 * (hi - lo) * rng.standard_normal((a.pop, len(keys))), lo, hi)
        sampling[0] = np.clip(x0, lo, hi)
        kw["sampling"] = sampling
    res = minimize(Tune(), GA(pop_size=a.pop, **kw), ("n_gen", a.gens), seed=a.seed, verbose=True)
    print("best cost", float(res.F[0]))
    print(", ".join(f"{k}={v!r}" for k, v in zip(keys, res.X.tolist())))


if __name__ == "__main__":
    main()
