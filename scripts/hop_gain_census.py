"""Is there a high hop in place anywhere in the hop corner's gains? A random census.

A feasibility measurement for issue 20's hop (apex >= 4 cm at a mean speed >= -0.05 m/s),
not a tuning: the hop corner's gains (``synchronous_coactive``; every other corner as
committed) drawn uniformly from a box, each draw rolled out with the paper's hop preset from
tuning CPG states (seeds 1000-1003; never the tests') for 2 s of settling plus 12 s, on the
model or on a copy of it with another ankle flexor. CMA-ES searches of the same corner
(docs/JOURNAL.md) walk back to a low hop because staying upright is worth more to the tuner's
cost than height; a census has no such gradient and says whether a point that does both exists.

    python scripts/hop_gain_census.py [--n 3000] [--seed 2] [--box base|lean|bal|squat|squat_kav]
        [--flexor 60] [--slope -150] [--base GAINS.json] [--out out/hop_gain_census]

``--box base``: knee_crouch, knee_ext, kp_push, kd_knee, push, pitch_d (0-0.5), kp_knee, k_ax,
k_av, theta0 in the ranges of BOXES below; ``--box lean`` adds the trunk's gains (kp_t, kd_t,
kf_t) and leans the trunk further (pitch_d 0.3-1.0 rad); ``--box bal`` adds the balance
reflex's reference ahead of the feet's centre (x_bal, m; the jump's is 0.05, the ball of the foot);
``--box squat`` also the trunk's lean with the knees' flexion (lean_knee, rad per rad) and its gains,
``--box squat_kav`` the same with k_av held (at --base's value, default the controller's).
``--flexor G``: the ankle flexor's torque at the neutral angle, N m per unit of activation (the
model's ``gainprm="60 -150 0"``;
100 or 140 make co-activation nearer a lock of the ankle); ``--slope S`` its fall with
dorsiflexion, N m/rad per unit (the model's -150; at -60 the flexor still pulls in the hop's
crouch). Writes OUT/census.json (every draw and
its four rows: fell, physical gait, apex m, mean speed m/s, flight, stride CV, stride period s,
every hop criterion passed) and prints the summary:
draws without a fall in the four states, draws named a hop in all four, the highest of those and
its speed, the highest of those that stays within -0.05 m/s, and the correlation of the lowest
apex with the mean speed over the standing draws. About 3.5 minutes per 3000 draws on 2 cores.
"""
from __future__ import annotations

import argparse
import functools
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SEEDS = (1000, 1001, 1002, 1003)
MEASURED_S = 12.0
BASE_BOX = dict(knee_crouch=(-0.9, -0.2), knee_ext=(-0.4, 0.0), kp_push=(1.0, 5.0),
                kd_knee=(0.02, 0.3), push=(0.0, 1.0), pitch_d=(0.0, 0.5), kp_knee=(0.3, 2.0),
                k_ax=(0.0, 20.0), k_av=(0.0, 3.0), theta0=(-0.2, 0.3))
BOXES = {"base": BASE_BOX,
         "lean": {**BASE_BOX, "pitch_d": (0.3, 1.0), "kp_t": (0.5, 6.0), "kd_t": (0.05, 0.8),
                  "kf_t": (-1.0, 1.0)},
         "bal": {**BASE_BOX, "x_bal": (-0.05, 0.15)},
         "squat": {**BASE_BOX, "x_bal": (-0.05, 0.15), "lean_knee": (0.0, 1.5),
                   "kp_t": (1.0, 6.0), "kd_t": (0.05, 0.8)}}
# ... the same without the velocity reflex, held at the committed corner's k_av (the run's
# start-up blends it: scripts/hop_squat_search.py)
BOXES["squat_kav"] = {k: b for k, b in BOXES["squat"].items() if k != "k_av"}
APEX_M, SPEED_MPS = 0.04, -0.05  # issue 20's hop targets


def write_body(out: Path, flexor: float, slope: float = -150.0) -> str:
    body = (ROOT / "models/biped/biped.xml").read_text()
    if 'gainprm="60 -150 0"' not in body:
        sys.exit("hop_gain_census: the model's flexor is not the one this census changes")
    d = out / f"body_flexor_{flexor:g}_{slope:g}"
    d.mkdir(parents=True, exist_ok=True)
    (d / "biped.xml").write_text(body.replace('gainprm="60 -150 0"',
                                              f'gainprm="{flexor:g} {slope:g} 0"'))
    (d / "scene.xml").write_text((ROOT / "models/biped/scene.xml").read_text())
    return str(d / "scene.xml")


@functools.lru_cache(maxsize=4)
def base_params(base: str | None):
    """The gains the drawn hop corner goes into: the file ``base``, or the controller's own
    (read once per process, not once per draw)."""
    from cpgbiped.envs.control.controller import CONTROL, read_gains
    return CONTROL if base is None else read_gains(base)[0]


def one(job):
    """One draw rolled out from each CPG state: job (i, gains, scene[, seeds[, base]]), seeds
    default SEEDS, base (a gains file the hop corner goes into) default the controller's."""
    i, gains, scene = job[:3]
    seeds = job[3] if len(job) > 3 and job[3] is not None else SEEDS
    base = job[4] if len(job) > 4 else None
    import numba
    numba.set_num_threads(1)
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.gaits.validate import measure_recording
    from cpgbiped.envs.simulation.rollout import rollout

    params = base_params(base).with_corner("synchronous_coactive", **gains)
    rows = []
    for s in seeds:
        net = build("ml", "hop", seed=s)
        rec = rollout(net, SETTLE_S + MEASURED_S, params, poses=False, xml_path=scene)
        m = measure_recording(net, "hop", rec, SETTLE_S).summary()
        rows.append([bool(m["fell"]), m["physical_gait"], float(m.get("apex_height_m") or 0.0),
                     float(m["speed_mps"] or 0.0), m.get("flight"), m.get("stride_cv"),
                     m.get("stride_period_s"), bool(m["passed"])])
    return {"i": i, "gains": gains, "rows": rows}


def summary(draws: list) -> dict:
    up = [d for d in draws if not any(r[0] for r in d["rows"])]
    hop4 = [d for d in up if all(r[1] == "hop" for r in d["rows"])]

    def low(d, k):
        return min(r[k] for r in d["rows"])
    best = max(hop4, key=lambda d: low(d, 2), default=None)
    inplace = [d for d in hop4 if low(d, 3) >= SPEED_MPS]
    best_in = max(inplace, key=lambda d: low(d, 2), default=None)
    apex = np.array([low(d, 2) for d in up])
    speed = np.array([np.mean([r[3] for r in d["rows"]]) for d in up])
    return {"draws": len(draws), "no_fall": len(up), "hop_in_all": len(hop4),
            "highest_hop_cm": None if best is None else round(100 * low(best, 2), 2),
            "highest_hop_speed_mps": None if best is None else round(low(best, 3), 3),
            "in_place_hops": len(inplace),
            "highest_in_place_cm": None if best_in is None else round(100 * low(best_in, 2), 2),
            "target_met": sum(low(d, 2) >= APEX_M for d in inplace),
            "passed_in_all": sum(all(r[7] for r in d["rows"]) for d in draws),
            "corr_apex_speed": (round(float(np.corrcoef(apex, speed)[0, 1]), 2)
                                if len(up) > 2 else None)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--box", choices=sorted(BOXES), default="base")
    ap.add_argument("--flexor", type=float, default=60.0)
    ap.add_argument("--slope", type=float, default=-150.0,
                    help="the flexor's torque slope with dorsiflexion, N m/rad per unit (model -150)")
    ap.add_argument("--base", help="gains file the drawn hop corner goes into (default: the "
                    "controller's, envs/control/gains.json)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/hop_gain_census")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = (str(ROOT / "models/biped/scene.xml") if (a.flexor, a.slope) == (60.0, -150.0)
             else write_body(out, a.flexor, a.slope))
    rng = np.random.default_rng(a.seed)
    box = BOXES[a.box]
    jobs = [(i, {k: float(rng.uniform(*b)) for k, b in box.items()}, scene, None, a.base)
            for i in range(a.n)]
    with ProcessPoolExecutor(a.workers) as ex:
        draws = list(ex.map(one, jobs, chunksize=4))
    res = {"command": " ".join(sys.argv), "seeds": SEEDS, "box": box, "flexor": a.flexor,
           "slope": a.slope,
           "summary": summary(draws), "draws": draws}
    (out / "census.json").write_text(json.dumps(res))
    print(json.dumps(res["summary"]))


if __name__ == "__main__":
    main()
