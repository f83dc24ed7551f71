"""Choose each network's feedback pathway and recommended gain by measurement.

Candidates: the Morris-Lecar forms of cpg.feedback (load into the extensors, load into
extensors and flexors, Taga's gated thigh angle, a touchdown pulse, Taga's angle in
alternating rhythms only), Hopf Tegotae, Matsuoka Taga; each at a few gains K. For each
candidate and each preset of the network (Morris-Lecar: all four; Hopf: walk and run, its jump
falls open loop; Matsuoka: its walk), on **tuning conditions only** (CPG seeds 1000-1003,
pushes in the stride after 5.5 s; the reported envelope of ``cpgbiped robustness`` uses the preset's
own state and pushes after 6 s, and the tests CPG seeds 10-19):
- the unperturbed closed-loop rollout (22 s) must not fall, and the CPG classifier must still
  name from the closed-loop cell outputs the gait it names open loop (the preset's, except
  for the Matsuoka walk, which it names a skip open loop too);
- feedback must not cost the gait: for each preset, the unperturbed closed-loop rollout passes
  every criterion of the preset's gait (envs.gaits.criteria, the 20 s after settling) in at
  least as many seeds as the open-loop rollout does (added 2026-12-04: the push score alone
  chose the load into extensors and flexors at K = 0.03, whose walk then passed in 1 of the 13
  test conditions and its run in none, the walk's duty and the run's Froude number sinking
  just below their bounds);
- score: the sum over the alternating presets (walk and run) and CPG seeds of the smallest
  impulse survived over the four push phases, forwards plus backwards
  (envs.robustness.push_envelope; the jump's and the hop's envelopes are not scored, their
  rows carry 0); admissible only when
  the three conditions above hold for every preset and seed (the Morris-Lecar jump and hop
  since session 40: the walk and the run alone admitted the thigh angle, which costs the hop).
The recommended gain is the best-scoring admissible candidate with K > 0 (the open loop's
score is printed beside it: feedback is recommended only as "the best closed loop", not as
better than open loop unless the numbers say so); when no candidate is admissible, the
smallest gain tried (the Matsuoka walk on the gains of 2026-12-06, which falls open loop in
one tuning seed). Writes cpg/feedback_gains.json (read by
cpg.feedback) with every candidate's numbers and this command.

    python3 scripts/feedback_choice.py [--seeds 1000,1001,1002,1003] [--push-s 0.2] [--workers 2]
                                       [--out cpg/feedback_gains.json]     (about 16 minutes)
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

CANDIDATES = {
    "ml": [("load", k) for k in (0.01, 0.03, 0.1)]
          + [("load_antagonist", k) for k in (0.01, 0.03, 0.1)]
          + [("angle", k) for k in (0.01, 0.03, 0.05, 0.1)]
          + [("reset", k) for k in (0.05, 0.1, 0.2)]
          + [("angle_alternating", k) for k in (0.01, 0.03, 0.05, 0.1)],
    "hopf": [("tegotae", k) for k in (0.5, 1.0, 2.0, 5.0)],
    "matsuoka": [("taga", k) for k in (0.03, 0.1, 0.3)],
}
# Presets whose unperturbed closed-loop rollouts decide admissibility; the push envelopes are
# scored for the alternating ones (SCORED). The Morris-Lecar jump and hop were added in session
# 40 (measured in a session copy in 39): the angle pathway that scored best on the walk and the run cost the hop, which the rule
# could not see. The Hopf network's jump falls open loop (at 6.5 s), so "no fall" cannot be asked
# of its synchronous presets; its and the Matsuoka network's rows are as before.
PRESETS = {"ml": ("walk", "run", "jump", "hop"), "hopf": ("walk", "run"), "matsuoka": ("walk",)}
SCORED = ("walk", "run")
# Tuning-condition CPG states (envs.search.controller_tuning); scores are summed over them.
# One seed (1000) chose the committed gains first; a re-run on later controller gains tied two
# Morris-Lecar candidates there, so the choice is made over four (README "Feedback").
CHOICE_SEEDS = "1000,1001,1002,1003"
CHOICE_PUSH_AFTER_S = 5.5


def evaluate(job):
    kind, preset, form, K, seed, push_s = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.experiments.robustness import push_envelope
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.gaits.validate import measure_recording
    from cpgbiped.envs.simulation.rollout import rollout

    net = build(kind, preset, seed=seed)
    ml_form = form if kind == "ml" else None
    rec = rollout(net, 22.0, poses=False, feedback=K, feedback_form=ml_form)
    s = measure_recording(net, preset, rec, SETTLE_S).summary()  # CPG gait and criteria
    env = (push_envelope(net, K, after_s=CHOICE_PUSH_AFTER_S, form=ml_form, push_s=push_s)
           if preset in SCORED else {"forward": [0.0], "backward": [0.0]})  # not scored
    return {"network": kind, "preset": preset, "form": form, "gain": K, "cpg_seed": seed,
            "fell": rec.fell_at is not None, "cpg_gait": s["cpg_gait"],
            "criteria_passed": bool(s["passed"]),
            "forward_ns": env["forward"], "backward_ns": env["backward"],
            "score": min(env["forward"]) + min(env["backward"])}


def criteria_passes(rows, presets) -> dict:
    """Per preset, in how many of ``rows`` the unperturbed rollout passed its gait's criteria."""
    return {p: sum(r["criteria_passed"] for r in rows if r["preset"] == p) for p in presets}


def main(argv=None) -> int:
    from cpgbiped.envs.experiments.robustness import PUSH_S  # the product's pushes

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seeds", default=CHOICE_SEEDS,
                    help="tuning-condition CPG seeds, comma separated (scores summed over them)")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "cpg"
                                         / "feedback_gains.json"))
    ap.add_argument("--push-s", type=float, default=PUSH_S,
                    help="how long each push's force is held, s (default 0.2, as SCONE's "
                         "perturbed-gait tutorial and `cpgbiped robustness`; 0.004: one "
                         "control tick, a blow, the form of every choice before 2026-12-04)")
    a = ap.parse_args(argv)
    seeds = [int(x) for x in a.seeds.split(",")]
    jobs = []
    for kind, cands in CANDIDATES.items():
        for form, K in [(cands[0][0], 0.0)] + cands:
            for preset in PRESETS[kind]:
                for seed in seeds:
                    jobs.append((kind, preset, form, K, seed, a.push_s))
    t0 = time.time()
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(evaluate, jobs))
    out = {"format": "cpgbiped.feedback_gains/1",
           "command": "python3 scripts/feedback_choice.py"
                      + (f" --seeds {a.seeds}" if a.seeds != CHOICE_SEEDS else "")
                      + (f" --push-s {a.push_s:g}" if a.push_s != PUSH_S else ""),
           "conditions": f"CPG seeds {a.seeds}, pushes in the stride after "
                         f"{CHOICE_PUSH_AFTER_S} s, each held {a.push_s:g} s (tuning conditions)",
           "networks": {}, "candidates": rows}
    for kind in CANDIDATES:
        by = {}
        for r in rows:
            if r["network"] == kind:
                by.setdefault((r["form"] if r["gain"] else "open loop", r["gain"]), []).append(r)
        table = []
        named_open = {(r["preset"], r["cpg_seed"]): r["cpg_gait"]
                      for r in by[("open loop", 0.0)]}
        passed_open = criteria_passes(by[("open loop", 0.0)], PRESETS[kind])
        for (form, K), rs in by.items():
            passed = criteria_passes(rs, PRESETS[kind])
            ok = all(not r["fell"] and r["cpg_gait"] == named_open[(r["preset"], r["cpg_seed"])]
                     for r in rs) and all(passed[p] >= passed_open[p] for p in PRESETS[kind])
            table.append({"form": form, "gain": K, "admissible": ok,
                          "score_ns": sum(r["score"] for r in rs)})
            print(f"{kind:9s} {form:16s} K={K:<5g} admissible={ok!s:5s} score "
                  f"{table[-1]['score_ns']:5.1f} N s  criteria passed in "
                  f"{sum(passed.values())}/{len(rs)}  "
                  + "; ".join(f"{r['preset']}: fwd {r['forward_ns']} back {r['backward_ns']} "
                              f"cpg {r['cpg_gait']}" for r in rs))
        open_loop = next(t for t in table if t["gain"] == 0)
        best = max((t for t in table if t["gain"] > 0 and t["admissible"]),
                   key=lambda t: t["score_ns"], default=None)
        if best is None:  # nothing keeps the gait: the smallest gain tried
            best = min((t for t in table if t["gain"] > 0), key=lambda t: t["gain"])
        out["networks"][kind] = {"form": best["form"], "recommended_gain": best["gain"],
                                 "score_ns": best["score_ns"],
                                 "open_loop_score_ns": open_loop["score_ns"]}
        print(f"-> {kind}: {best['form']} K = {best['gain']:g} (score {best['score_ns']:g} N s; "
              f"open loop {open_loop['score_ns']:g} N s)")
    Path(a.out).write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {a.out} in {time.time() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
