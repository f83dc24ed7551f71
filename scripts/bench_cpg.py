"""Benchmark: batched 4-cell Morris-Lecar evaluations vs scipy's solve_ivp, in one run.

Work unit ("evaluation"): integrate one weight set over 500 model time units from a random
state and measure its steady-state phases (second half). The batch is 256 random weight sets
in [-1, 1]^3 with walk's (I_app, phi). solve_ivp (RK45, rtol 1e-8, atol 1e-10: tight enough
to serve as a reference, stopped by the same divergence rule as the kernel) runs on a sample and is extrapolated to the batch. Prints evaluations
per second of both, the ratio (target >= 100x) and the largest phase difference between them
on the sample (target <= 0.5 degree).

    python scripts/bench_cpg.py [--batch 256] [--sample 8]
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

from cpgbiped.cpg import analysis, morris_lecar as ml
from cpgbiped.cpg.integrate import DT_ML, ML_RANGE, simulate_ml

T_END, T_REC = 500.0, 250.0


def phases(t, x):
    r = analysis.analyze(t, x)
    return r.phases_deg if r.oscillating and r.locked.all() else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--batch", type=int, default=256)
    ap.add_argument("--sample", type=int, default=8, help="solve_ivp runs to extrapolate from")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)
    w = rng.uniform(-1, 1, (a.batch, 3))
    W = ml.weight_matrix(w)
    y0 = ml.random_states(a.batch, rng)
    p = ml.preset("walk")

    t0 = time.perf_counter()
    simulate_ml(p.i_app, p.phi, W[:2], y0[:2], t_end=1.0)  # compile / load the kernel cache
    t_compile = time.perf_counter() - t0

    t0 = time.perf_counter()
    tr = simulate_ml(p.i_app, p.phi, W, y0, t_end=T_END, t_record=T_REC, dt=DT_ML)
    fast_ph = [phases(tr.t, tr.x[b]) for b in range(a.batch)]
    t_fast = time.perf_counter() - t0

    def left_range(t, y):  # the kernel's divergence rule, as a terminal event
        return ML_RANGE - np.abs(y).max()

    left_range.terminal = True
    t0 = time.perf_counter()
    ref_ph = []
    for b in range(a.sample):
        f = lambda t, y, b=b: ml.rhs(y[None], np.array([p.i_app]), np.array([p.phi]), W[b:b + 1])[0]  # noqa: E731
        sol = solve_ivp(f, (0, T_END), y0[b], method="RK45", rtol=1e-8, atol=1e-10, t_eval=tr.t,
                        events=left_range)
        ref_ph.append(phases(sol.t, sol.y[4:].T) if sol.status == 0 else None)
    t_ref = (time.perf_counter() - t0) * a.batch / a.sample

    diffs = [analysis.wrap_deg(f - r).max() for f, r in zip(fast_ph, ref_ph)
             if f is not None and r is not None]
    agree = sum((f is None) == (r is None) for f, r in zip(fast_ph, ref_ph))
    print(f"batch {a.batch} weight sets x {T_END:g} model units, RK4 dt={DT_ML} (numba, "
          f"{__import__('numba').get_num_threads()} threads); kernel load {t_compile:.2f} s")
    print(f"  batched RK4 + analysis : {t_fast:8.2f} s  {a.batch / t_fast:9.1f} evaluations/s")
    print(f"  solve_ivp RK45 (extrap.): {t_ref:8.2f} s  {a.batch / t_ref:9.2f} evaluations/s "
          f"(from {a.sample} runs)")
    print(f"  speed-up               : {t_ref / t_fast:8.1f}x  (target >= 100x)")
    print(f"  phase agreement        : max {max(diffs) if diffs else float('nan'):.4f} deg over "
          f"{len(diffs)} oscillating sample sets; oscillation verdict agrees on {agree}/{a.sample}"
          f"  (target <= 0.5 deg)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
