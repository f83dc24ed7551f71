"""Is the hop's height the network's rhythm or the body's? The paper's hop weights over a grid
of (I_app, phi), each driving the body through the committed controller from tuning CPG states.

    python scripts/hop_rhythm_grid.py [--seeds 1000,1001] [--workers 2]
                                      [--out out/hop_rhythm_grid.csv]

I_app (the cells' drive) and phi (their recovery rate) set the period and the burst's share of
it; the weights (Table 2's hop row) keep the four cells in phase. For each point and CPG seed
(tuning conditions: seeds 1000 and up, never the Table 3 state or a test seed): 22 s, the 20 s
after settling measured as ``validate`` measures them (the gait the CPG classifier and the
contacts name, apex of the centre of mass, mean speed, stride period and CV, flight, fall).
Prints one line per point and writes the rows as CSV. About 10 s on 2 cores.
"""
from __future__ import annotations

import argparse
import csv
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

I_APPS = np.linspace(0.20, 0.34, 8)  # Table 2's rows span 0.229-0.290 (hop 0.279)
PHIS = np.linspace(0.15, 0.50, 8)  # Table 2's rows span 0.194-0.394 (hop 0.294)
FIELDS = ("i_app", "phi", "cpg_seed", "fell", "cpg_gait", "physical_gait", "apex_cm",
          "speed_mps", "stride_period_s", "stride_cv", "flight")


def one(job):
    i_app, phi, seed = job
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.gaits.validate import measure_recording
    from cpgbiped.envs.simulation.rollout import rollout

    row = {"i_app": round(float(i_app), 4), "phi": round(float(phi), 4), "cpg_seed": seed}
    try:
        net = build("ml", "hop", i_app=float(i_app), phi=float(phi), seed=seed)
        s = measure_recording(net, "hop", rollout(net, SETTLE_S + 20.0, poses=False),
                              SETTLE_S).summary()
    except InputError:  # the network diverges or does not oscillate
        return {**row, "fell": True, "cpg_gait": "none", "physical_gait": "none"}
    num = lambda x, k=1.0: None if x is None else round(float(x) * k, 4)  # noqa: E731
    return {**row, "fell": bool(s["fell"]), "cpg_gait": s["cpg_gait"],
            "physical_gait": s["physical_gait"], "apex_cm": num(s["apex_height_m"], 100.0),
            "speed_mps": num(s["speed_mps"]), "stride_period_s": num(s["stride_period_s"]),
            "stride_cv": num(s["stride_cv"]), "flight": num(s["flight"])}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1000,1001")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/hop_rhythm_grid.csv")
    a = ap.parse_args(argv)
    seeds = [int(x) for x in a.seeds.split(",")]
    if any(s < 1000 for s in seeds):
        sys.exit("hop_rhythm_grid: tuning CPG seeds start at 1000")
    jobs = [(i, p, s) for i in I_APPS for p in PHIS for s in seeds]
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(one, jobs))
    for r in rows:
        print(f"I_app {r['i_app']:.3f} phi {r['phi']:.3f} seed {r['cpg_seed']}: "
              f"{'fell ' if r['fell'] else ''}CPG {r['cpg_gait']}, contacts {r['physical_gait']}, "
              f"apex {r.get('apex_cm')} cm, {r.get('speed_mps')} m/s, "
              f"stride {r.get('stride_period_s')} s, CV {r.get('stride_cv')}")
    standing = [r for r in rows if not r["fell"] and r["cpg_gait"] == "hop"
                and r["physical_gait"] == "hop" and r.get("apex_cm") is not None]
    if standing:
        best = max(standing, key=lambda r: r["apex_cm"])
        print(f"highest hop both classifiers name a hop, no fall: {best['apex_cm']} cm at I_app "
              f"{best['i_app']}, phi {best['phi']} (seed {best['cpg_seed']}; "
              f"{best['speed_mps']} m/s); {len(standing)} of {len(rows)} rollouts")
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
