"""Benchmark: physical rollouts per second, the throughput a physics-in-the-loop search gets.

A batch of 64 different Morris-Lecar weight sets (the walk's, each weight moved by up to
+-0.15, drawn from --seed), each driving the biped through the one controller for 20 s of
simulated time (settling included; a rollout that falls keeps going, so that every one costs
20 s), the contact metrics measured. Three sides, measured in this run, alternately:

- serial: one rollout at a time in this process (``envs.trials.SerialRunner``);
- product: the runner ``optimize --physics`` uses (``envs.trials.PoolRunner``, one spawned
  process per core, started and warmed before the clock);
- limit: plain ``mujoco.mj_step`` with zero control, the same number of steps per rollout,
  spread over the same number of processes the same way.

Target: product >= 0.8 x limit (issue 14). Prints rollouts/s and the ratios.

    python scripts/bench_rollouts.py [--batch 64] [--seconds 20] [--rounds 3]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np


def _plain(args) -> int:
    """``n_rollouts`` rollouts of plain mj_step (zero control), ``steps`` steps each."""
    n_rollouts, steps = args
    import mujoco

    from cpgbiped.envs.simulation.biped import load_model
    from cpgbiped.models import BIPED_SCENE

    m = load_model(BIPED_SCENE)
    for _ in range(n_rollouts):
        d = mujoco.MjData(m)
        mujoco.mj_step(m, d, nstep=steps)
    return n_rollouts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--seconds", type=float, default=20.0, help="simulated s per rollout")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--serial", type=int, default=16,
                    help="rollouts timed for the serial side (default 16 of the batch)")
    ap.add_argument("--workers", type=int, default=os.cpu_count())
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args(argv)

    from cpgbiped.cpg import morris_lecar as ml
    from cpgbiped.envs.simulation.biped import load_model
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.simulation.trials import PoolRunner, SerialRunner, Trial, chunks
    from cpgbiped.models import BIPED_SCENE

    p = ml.preset("walk")
    rng = np.random.default_rng(a.seed)
    W = np.asarray(p.weights) + rng.uniform(-0.15, 0.15, (a.batch, 3))
    trials = [Trial("walk", tuple(map(float, w)), p.i_app, p.phi) for w in W]
    steady = a.seconds - SETTLE_S
    steps = int(round(a.seconds / load_model(BIPED_SCENE).opt.timestep))

    serial = SerialRunner(steady, stop_on_fall=False)
    serial(trials[:1])  # compile, load
    pool = PoolRunner(steady, stop_on_fall=False, workers=a.workers)
    pool.warm_up()
    jobs = [(s.stop - s.start, steps) for s in chunks(a.batch, pool.workers)]
    list(pool.pool.map(_plain, jobs[:pool.workers]))  # the plain side's imports, in each worker

    def timed(f):
        t0 = time.perf_counter()
        f()
        return time.perf_counter() - t0

    rows = {"serial": [], "product": [], "limit": []}
    for r in range(a.rounds):
        rows["product"].append(a.batch / timed(lambda: pool(trials)))
        rows["limit"].append(a.batch / timed(lambda: list(pool.pool.map(_plain, jobs))))
        rows["serial"].append(a.serial / timed(lambda: serial(trials[:a.serial])))
    pool.close()
    ratio = np.median(np.array(rows["product"]) / np.array(rows["limit"]))
    print(f"physical rollouts, {a.seconds:g} s simulated ({steps} steps) each, batch {a.batch}, "
          f"{pool.workers} processes, {a.rounds} alternating rounds (best shown):")
    print(f"   serial, one process          : {max(rows['serial']):6.2f} rollouts/s")
    print(f"   product (PoolRunner)         : {max(rows['product']):6.2f} rollouts/s")
    print(f"   limit (plain mj_step, zero u): {max(rows['limit']):6.2f} rollouts/s")
    print(f"   product / serial             : {max(rows['product']) / max(rows['serial']):6.2f}")
    print(f"   product / limit (median)     : {ratio:6.2f}   (target >= 0.8)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
