"""Does a flexor that still pulls in dorsiflexion let the hop rise without drifting back?

A body experiment (2026-12-04; not adopted): the ankle flexor's force-length slope
(models/biped/biped.xml, ``gainprm="60 -150 0"``: torque 60 - 150 q N m per unit of activation,
zero at q = 0.4 rad of dorsiflexion) set to -100 or -60 in a copy of the model, and the presets
rolled out with the committed gains ("base") and with a high-hop variant of the hop corner
("high": knee_ext -0.1, kp_knee 1.0, k_av 3, k_ax 0; docs/JOURNAL.md, "Hop"), from tuning CPG
states only (seeds 1000 and up), 20 s after settling:

    python scripts/hop_flexor_slope.py [--slopes -150,-100,-60] [--variants base,high]
                                       [--gaits hop] [--seeds 1000,1001,1002,1003]
                                       [--out out/hop_flexor_slope]

Writes the model copies and gains variants under --out and prints one JSON line per rollout
(fell, physical gait, apex cm, mean speed m/s, flight, failed criteria). About 3 s per 24
rollouts on 2 cores.
"""
from __future__ import annotations

import argparse
import itertools
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HIGH_HOP = {"knee_ext": -0.1, "kp_knee": 1.0, "k_av": 3.0, "k_ax": 0.0}


def write_body(out: Path, slope: int) -> str:
    d = out / f"body_{slope}"
    d.mkdir(parents=True, exist_ok=True)
    body = (ROOT / "models/biped/biped.xml").read_text()
    if 'gainprm="60 -150 0"' not in body:
        sys.exit("hop_flexor_slope: the model's flexor is not the one this experiment changes")
    (d / "biped.xml").write_text(body.replace('gainprm="60 -150 0"', f'gainprm="60 {slope} 0"'))
    (d / "scene.xml").write_text((ROOT / "models/biped/scene.xml").read_text())
    return str(d / "scene.xml")


def write_gains(out: Path, variant: str) -> str:
    g = json.loads((ROOT / "envs/control/gains.json").read_text())
    if variant == "high":
        g["corners"]["synchronous_coactive"].update(HIGH_HOP)
    p = out / f"gains_{variant}.json"
    p.write_text(json.dumps(g))
    return str(p)


def one(job):
    slope, variant, gait, seed, scene, gains = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import read_gains
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.gaits.validate import measure_recording
    from cpgbiped.envs.simulation.rollout import rollout

    net = build("ml", gait, seed=seed)
    rec = rollout(net, SETTLE_S + 20.0, read_gains(gains)[0], xml_path=scene, poses=False)
    s = measure_recording(net, gait, rec, SETTLE_S).summary()
    return {"slope": slope, "variant": variant, "gait": gait, "cpg_seed": seed,
            "fell": bool(s["fell"]), "passed": bool(s["passed"]),
            "physical_gait": s["physical_gait"],
            "apex_cm": round(100 * (s.get("apex_height_m") or 0.0), 2),
            "speed_mps": round(s["speed_mps"] or 0.0, 3), "flight": s["flight"],
            "failures": s["failures"][:3]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--slopes", default="-150,-100,-60")
    ap.add_argument("--variants", default="base,high")
    ap.add_argument("--gaits", default="hop")
    ap.add_argument("--seeds", default="1000,1001,1002,1003")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="out/hop_flexor_slope")
    a = ap.parse_args()
    seeds = [int(x) for x in a.seeds.split(",")]
    if any(s < 1000 for s in seeds):
        sys.exit("hop_flexor_slope: tuning CPG seeds start at 1000")
    out = Path(a.out)
    scenes = {int(s): write_body(out, int(s)) for s in a.slopes.split(",")}
    gains = {v: write_gains(out, v) for v in a.variants.split(",")}
    jobs = [(s, v, g, seed, scenes[s], gains[v]) for s, v, g, seed in itertools.product(
        scenes, gains, a.gaits.split(","), seeds)]
    with ProcessPoolExecutor(a.workers) as ex:
        for row in ex.map(one, jobs):
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
