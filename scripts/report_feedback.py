"""The README's feedback report: open loop (K = 0) against each network's recommended gain.

    python scripts/report_feedback.py [--out out/report_feedback] [--workers 2] [--img docs/img]

1. The four Morris-Lecar presets over the 13 test conditions (tests/test_physics.py: Table 3
   state, CPG seeds 10-19, friction x0.7 and x1.3), K = 0 and the recommended K: criteria
   passed, falls, the gait the contacts name, the gait the CPG classifier names from the
   (closed-loop) cell outputs.
2. The push envelope (envs.robustness) of the walk and the run, Morris-Lecar and Hopf.
3. The phase response (envs.phase_response) of the Morris-Lecar and Hopf walks, and of the
   Hopf run at a larger gain.
Writes OUT/report.md, OUT/report.json and the pictures (also into --img when given).
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.test_physics import CONDITION_IDS, CONDITIONS  # noqa: E402


def _condition(job):
    gait, cid, cond, K = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.criteria import WINDOW_S
    from cpgbiped.envs.gaits.validate import validate

    cond = dict(cond)
    seed = cond.pop("seed", None)
    s = validate(build("ml", gait, seed=seed), gait, WINDOW_S, feedback=K, **cond).summary()
    return {"gait": gait, "condition": cid, "K": K, "passed": s["passed"], "fell": s["fell"],
            "physical_gait": s["physical_gait"], "cpg_gait": s["cpg_gait"],
            "failures": s["failures"]}


def _robust(job):
    kind, preset, K = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.experiments.robustness import robustness

    return robustness(build(kind, preset), preset, [0.0, K])


def _prc(job):
    kind, preset, K, impulse = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.experiments.phase_response import phase_response

    net = build(kind, preset)
    return [phase_response(net, k, impulse=impulse) for k in (0.0, K)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/report_feedback")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--img", default=None, help="also copy the pictures here (docs/img)")
    a = ap.parse_args(argv)
    from cpgbiped.cpg.feedback import CHOICE, RECOMMENDED
    from cpgbiped.cpg.io import ensure_dir, write_text
    from cpgbiped.envs.gaits.criteria import CRITERIA
    from cpgbiped.envs.experiments.phase_response import picture
    from cpgbiped.envs.experiments.robustness import envelope_picture, table

    out = ensure_dir(a.out)
    K_ml, K_hopf = RECOMMENDED["ml"], RECOMMENDED["hopf"]
    cond_jobs = [(g, cid, c, K) for g in CRITERIA for K in (0.0, K_ml)
                 for cid, c in zip(CONDITION_IDS, CONDITIONS)]
    rob_jobs = [("ml", "walk", K_ml), ("ml", "run", K_ml), ("hopf", "walk", K_hopf),
                ("hopf", "run", K_hopf)]
    prc_jobs = [("ml", "walk", K_ml, 5.0), ("hopf", "walk", K_hopf, 5.0),
                ("hopf", "run", 3.0, 10.0), ("ml", "walk", 0.05, 10.0)]
    with ProcessPoolExecutor(a.workers) as ex:
        conds = list(ex.map(_condition, cond_jobs))
        robs = list(ex.map(_robust, rob_jobs))
        prcs = list(ex.map(_prc, prc_jobs))
    md = ["## Feedback into the CPG: open loop against the recommended gain", "",
          "Chosen pathways and gains (cpg/feedback_gains.json, scripts/feedback_choice.py): "
          + ", ".join(f"{k} {f} K = {g:g}" for k, (f, g) in CHOICE.items()) + ".", "",
          "### Morris-Lecar presets over the 13 test conditions", "",
          "| preset | K | criteria passed | fell | contacts name the preset | CPG names the preset |",
          "|---|---|---|---|---|---|"]
    for g in CRITERIA:
        for K in (0.0, K_ml):
            rs = [r for r in conds if r["gait"] == g and r["K"] == K]
            md.append(f"| {g} | {K:g} | {sum(r['passed'] for r in rs)}/13 | "
                      f"{sum(r['fell'] for r in rs)}/13 | "
                      f"{sum(r['physical_gait'] == g for r in rs)}/13 | "
                      f"{sum(r['cpg_gait'] == g for r in rs)}/13 |")
    md += ["", "### Push envelopes (impulse survived, N s, at stride phases 0, 0.25, 0.5, 0.75)", ""]
    img = []
    for (kind, preset, _), res in zip(rob_jobs, robs):
        md += [f"**{kind} {preset}**", "", "```", table(res), "```", ""]
        p = Path(out) / f"robustness_{kind}_{preset}.png"
        envelope_picture(res, p)
        img.append(p)
    md += ["### Phase response", ""]
    for (kind, preset, K, imp), res in zip(prc_jobs, prcs):
        p = Path(out) / f"phase_response_{kind}_{preset}_K{K:g}.png"
        picture(res, f"{kind} {preset}: {imp:g} N s push forwards", p)
        img.append(p)
        for r in res:
            if r["dphi"] is None:
                md.append(f"- {kind} {preset}, K = {r['feedback_gain']:g}: {r.get('note')}")
                continue
            d = [x for x in r["dphi"] if x == x]
            md.append(f"- {kind} {preset}, {imp:g} N s, K = {r['feedback_gain']:g}: CPG phase "
                      f"shift {min(d):+.3f} to {max(d):+.3f} cycles over the push phases; "
                      f"re-lock cycles " + ", ".join("-" if x is None else f"{x:g}"
                                                     for x in r["relock_cycles"]))
    text = "\n".join(md) + "\n"
    write_text(Path(out) / "report.md", text)
    (Path(out) / "report.json").write_text(json.dumps(
        {"conditions": conds, "robustness": robs, "phase_response": prcs}, indent=1))
    if a.img:
        ensure_dir(a.img)
        for p in img:
            shutil.copy(p, Path(a.img) / p.name)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
