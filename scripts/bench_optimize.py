"""Benchmark: NSGA-II for all four primary gaits at the default budget, in one run.

Prints the wall seconds of the full search (pop 40, 25 generations per gait, batched
evaluation, result files included; target < 60 s on 2 cores) and, for comparison, the same
number of evaluations done with one scipy solve_ivp (RK45, rtol 1e-8) per individual,
extrapolated from a measured sample of random weight sets over the same 400 model units.

    python scripts/bench_optimize.py [--sample 6]
"""
from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np
from scipy.integrate import solve_ivp

from cpgbiped.cpg import morris_lecar as ml
from cpgbiped.cpg.evaluate import SimSettings
from cpgbiped.cpg.integrate import ML_RANGE
from cpgbiped.cpg.optimize import RunSettings
from cpgbiped.cpg.search import optimize_primary


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sample", type=int, default=6)
    a = ap.parse_args(argv)
    rs, sim = RunSettings(), SimSettings()
    with tempfile.TemporaryDirectory() as d:
        optimize_primary("hop", RunSettings(pop=4, gens=1), d)  # load the compiled kernel
        t0 = time.perf_counter()
        for g in ml.PRIMARY_GAITS:
            optimize_primary(g, rs, d)
        wall = time.perf_counter() - t0
    n_evals = 4 * rs.pop * rs.gens

    def left_range(t, y):
        return ML_RANGE - np.abs(y).max()

    left_range.terminal = True
    rng = np.random.default_rng(0)
    p = ml.preset("walk")
    t0 = time.perf_counter()
    for _ in range(a.sample):
        W = ml.weight_matrix(rng.uniform(-1, 1, 3))[None]
        f = lambda t, y: ml.rhs(y[None], np.array([p.i_app]), np.array([p.phi]), W)[0]  # noqa: E731
        solve_ivp(f, (0, sim.t_end), p.y0, method="RK45", rtol=1e-8, atol=1e-10, events=left_range)
    per = (time.perf_counter() - t0) / a.sample
    print(f"NSGA-II, 4 primary gaits x pop {rs.pop} x {rs.gens} generations "
          f"({n_evals} evaluations + robustness checks), {sim.t_end:g} model units each")
    print(f"  batched (this package)        : {wall:8.1f} s   (target < 60 s on 2 cores)")
    print(f"  one solve_ivp per individual  : {per * n_evals:8.1f} s   "
          f"(extrapolated: {per:.2f} s x {n_evals}, from {a.sample} random weight sets)")
    print(f"  ratio                         : {per * n_evals / wall:8.1f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
