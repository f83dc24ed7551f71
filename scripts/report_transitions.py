"""The README's transition report: every ordered pair of primary gaits, as a step and as a 2 s
ramp, open loop and with the recommended feedback; the drive sweeps walk<->run and jump<->hop.

    python scripts/report_transitions.py [--out out/report_transitions] [--workers 2]
                                         [--img docs/img]

The change comes at 8 s (after 6 s of the first gait), the rollout ends 12 s after the change
ends. Writes OUT/report.md, OUT/report.json and the sweep pictures (also into --img).
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

GAITS = ("walk", "run", "jump", "hop")
IN_FAMILY = {("walk", "run"), ("run", "walk"), ("jump", "hop"), ("hop", "jump")}


def _one(job):
    a, b, ramp, K = job
    from cpgbiped.envs.experiments.transition import transition

    res, *_ = transition("ml", a, b, 8.0, ramp, 8.0 + ramp + 12.0, K)
    return res


def _sweep(job):
    pair, K = job
    from cpgbiped.envs.experiments.sweep import sweep

    return sweep(pair, 40.0, "ml", K)[0]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/report_transitions")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--img", default=None)
    a = ap.parse_args(argv)
    from cpgbiped.cpg.feedback import RECOMMENDED
    from cpgbiped.cpg.io import ensure_dir, write_text
    from cpgbiped.envs.experiments.sweep import picture

    out = ensure_dir(a.out)
    K = RECOMMENDED["ml"]
    jobs = [(x, y, r, k) for x in GAITS for y in GAITS if x != y for r in (0.0, 2.0)
            for k in (0.0, K)]
    sweeps = [(p, k) for p in ("walk-run", "jump-hop") for k in (0.0, K)]
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(_one, jobs))
        sw = list(ex.map(_sweep, sweeps))
    md = ["### Transitions (Morris-Lecar, change at 8 s)", "",
          "before / after: the physical gait the contacts name before the change and once it "
          "has settled; cycles: CPG cycles from the change until the settled gait is the "
          "target (- never).", "",
          "| from -> to | change | K | before | after | fell | cycles | outcome |",
          "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ok = r["after"]["physical_gait"] == r["to"] and not r["fell"]
        outcome = ("switched" if r["switched"] else
                   "reached the target" if ok else "fell" if r["fell"] else "not reached")
        fam = "" if (r["from"], r["to"]) in IN_FAMILY else " (cross)"
        md.append(f"| {r['from']} -> {r['to']}{fam} | "
                  f"{'step' if r['ramp_s'] == 0 else 'ramp %g s' % r['ramp_s']} | "
                  f"{r['feedback_gain']:g} | {r['before']['physical_gait']} | "
                  f"{r['after']['physical_gait']} | "
                  f"{'%.1f s' % r['fell_at_s'] if r['fell'] else 'no'} | "
                  f"{'-' if r['cycles_to_switch'] is None else r['cycles_to_switch']} | "
                  f"{outcome} |")
    md += ["", "### Drive sweeps (ramps of 40 s)", "",
           "| sweep | K | switch up: drive, speed, Froude | switch down: drive, speed, Froude "
           "| hysteresis (drive) | fell |", "|---|---|---|---|---|---|"]
    img = []
    f = lambda p: "-" if p is None else (  # noqa: E731
        f"{p['drive']:.2f}, {p['speed_mps']:.2f} m/s, {p['froude']:.3f}")
    for (pair, k), res in zip(sweeps, sw):
        hy = res["hysteresis_drive"]
        md.append(f"| {pair} | {k:g} | {f(res['switch_up'])} | {f(res['switch_down'])} | "
                  f"{'-' if hy is None else '%+.2f' % hy} | "
                  f"{'%.1f s' % res['fell_at_s'] if res['fell'] else 'no'} |")
        p = Path(out) / f"sweep_ml_{pair}{'_K%g' % k if k else ''}.png"
        picture(res, p)
        img.append(p)
    text = "\n".join(md) + "\n"
    write_text(Path(out) / "report.md", text)
    (Path(out) / "report.json").write_text(json.dumps({"transitions": rows, "sweeps": sw},
                                                      indent=1, default=float))
    if a.img:
        ensure_dir(a.img)
        for p in img:
            shutil.copy(p, Path(a.img) / p.name)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
