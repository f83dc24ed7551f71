"""The walk corner's landing searched for a softer heel strike at the same speed: CMA-ES on
tuning states only.

The committed walk lands on its toes with the knee flexed 47 degrees, and its heel slaps down
50 ms later at about 4 body weights (a human walk peaks at 1.1-1.3; docs/RESULTS.md, "The vertical ground
forces"). A straighter landing knee alone lowers the peak but slows the walk to Fr 0.06, and a
slower walk slaps less whatever slows it (docs/JOURNAL.md, session 36). This searches ten gains
of the walk's corner (``corners.alternating``: the landing knee and its stiffness in the air,
the stance knee's crouch, stiffness and push, the landing's yield, the trailing leg's push-off,
the early swing's toe lift, and the foot placement's offset and speed gain, which hold the
speed) with pymoo's CMA-ES (seeded), in the box LO-HI. Score of a candidate (lower is better),
per walk rollout of 2 s + 20 s from CPG seeds STATES, averaged:

- a fall: 12;
- otherwise PEAK_WEIGHT times the median over stances of each foot's largest vertical ground
  force, in body weights (``validate``'s ``peak_vertical_grf_bw``),
  + 5 per 0.01 of Froude number below FR_MIN (the speed held),
  + 3 if the walk fails any of its criteria (envs/gaits/criteria.py),
  + DUTY_COST (``--duty-cost``) per unit of the smaller duty factor below DUTY_MIN
    (``--duty-min``; a margin over the walk pattern's 0.55),
  + CROUCH_COST per degree of the stance knee's flexion (the median over stances after 4 s of
    its mean at 0.3-0.7 of the stance) beyond KNEE_MID_DEG, the committed walk's (a softer
    landing bought with a crouched walk is not the walk asked for).

The other gaits are not scored: the walk's corner reaches them only through the features'
blend in their first seconds, and whether that costs them is the adoption rule's question.

    python scripts/walk_landing_search.py --start GAINS.json [--guard] [--duty-min D --duty-cost W]
        [--out out/walk_landing]

Writes OUT/gains.json (the start file with the corner's gains replaced, as a link of a tuning
chain: set_by_hand's provenance entry, naming this script) and OUT/history.jsonl (every
candidate's score and medians). About 5 minutes on 2 cores.

What it found (2026-12-06, session 37; docs/JOURNAL.md), from the committed gains: score
8.70 -> 4.80; over the 12 search states the walk's median peak 4.05 -> 2.08 body weights at Fr
0.113, double support 0.146, stance knee 30.7 degrees (27 before); over the held-out tuning
states 1012-1047 peak 2.07, Fr 0.113, the walk passing in 35 of 36 (one fall), the run 36, the
jump 35, the hop 32. It still lands on its toes (the foot 18.5 degrees toes-down at touchdown,
the knee flexed 56 degrees against 47): the landing yields, it does not turn into a heel strike.
Put to a rule fixed before it met any other state (journal, session 37): over unused CPG states
2600-2699 the walk's peak 4.05 -> 2.07 at Fr 0.114 (L1 met) and the perturbations kept 697 ->
712 of 840, but the hop passes in 81 against 86 (committed - 3 asked) and the walk in 96
against 99, its falls 0 -> 3: not adopted. Earlier settings of the same search (seed 42, the
peak weighted 1, the duty's margin 200 per unit, 30 and 50 generations) found peaks of 2.52 and
2.65 with the knee at 31 and 27 degrees. With ``--guard`` (15 minutes): score 9.88 -> 6.38, the
walk's peak 4.05 -> 2.05 at Fr 0.119 over its 20 states, double support 0.139 -> 0.123; put to a
second rule over CPG states 2700-2799: peak 2.05 at Fr 0.119, but the walk passes in 91 against
97 (duty at the 0.55 edge) and the hop in 85 against 93: not adopted. With ``--guard --duty-min
0.57 --duty-cost 400`` (9 minutes): score 11.87 -> 11.80, peak 3.15 at Fr 0.120, double support
0.131: with the duty held, the search finds no softer landing; it was put to no rule.
"""
from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from cpgbiped.envs.gaits.criteria import SETTLE_S

# the other presets' guard: walk_startup_search's (this folder is on sys.path when a script runs)
from walk_startup_search import GUARD_S, GUARD_SEEDS as GUARD_STATES, guard_terms

NAMES = ("knee_land", "theta0", "c_v", "push", "push_off", "kp_air", "knee_crouch", "toe_up",
         "kp_knee", "land_yield")
LO = np.array([-1.3, 0.0, 0.2, 0.0, 0.0, 0.15, -0.8, 0.0, 0.3, 0.0])
HI = np.array([-0.4, 0.35, 0.6, 0.3, 0.4, 1.0, -0.2, 0.8, 2.0, 1.0])
CORNER = "alternating"
STATES = tuple(range(1000, 1012))  # tuning CPG states
# --guard: more walk states, and the other presets' criteria and falls in the score (their
# first seconds blend the walk's corner), with scripts/walk_startup_search.py's guard
# (GUARD_STATES 1000-1007, 2 s + GUARD_S = 12 s each)
GUARD_WALK_STATES = tuple(range(1000, 1020))
MEASURED_S = 20.0
FR_MIN = 0.10
DUTY_MIN, DUTY_COST = 0.565, 100.0
PEAK_WEIGHT = 2.0
KNEE_MID_DEG, CROUCH_COST = 27.0, 0.1
FALL_COST = 12.0
POP, GENS, SIGMA, SEED = 10, 40, 0.15, 43
NOTE = ("the walk corner's landing found by python scripts/walk_landing_search.py --start "
        "{start} --out {out} (pymoo CMA-ES, seed %d, pop %d, %d generations, sigma %g in the box "
        "of the script; tuning CPG states %d-%d, the walk over %g s + %g s: the median peak "
        "vertical force per foot, Fr below %g, the criteria, the duty below %g and the stance "
        "knee's flexion beyond %g degrees scored): score {start_score:.3f} -> {score:.3f}, "
        "{info}. " % (SEED, POP, GENS, SIGMA, STATES[0], STATES[-1], SETTLE_S, MEASURED_S,
                      FR_MIN, DUTY_MIN, KNEE_MID_DEG))


def knee_mid_deg(rec) -> float | None:
    """The stance knee's flexion (degrees, > 0 flexed): the median over stances after 4 s of its
    mean over 0.3-0.7 of the stance."""
    from cpgbiped.envs.gaits.gait_metrics import stances

    full, _ = stances(rec.contact, rec.dt)
    mids = [np.degrees(-rec.joints[a + int(0.3 * (b - a)):a + int(0.7 * (b - a)) + 1,
                                   3 * i + 1].mean())
            for i, a, b in full if rec.t[a] >= 4.0 and b - a > 10]
    return float(np.median(mids)) if mids else None


def one(job) -> tuple:
    """(cost, summary) of one walk rollout: job = (params, CPG seed, (duty margin, its cost))."""
    params, seed, (duty_min, duty_cost) = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.validate import measure_recording
    from cpgbiped.envs.simulation.rollout import rollout

    net = build("ml", "walk", seed=seed)
    rec = rollout(net, SETTLE_S + MEASURED_S, params, poses=False)
    s = measure_recording(net, "walk", rec, SETTLE_S).summary()
    s = {k: s[k] for k in ("fell", "passed", "froude", "peak_vertical_grf_bw",
                           "peak_vertical_grf_at", "duty_factor", "double_support")}
    if s["fell"]:
        return FALL_COST, s
    s["knee_mid_deg"] = knee = knee_mid_deg(rec)
    cost = (PEAK_WEIGHT * s["peak_vertical_grf_bw"] + 5.0 * max(0.0, FR_MIN - s["froude"]) / 0.01
            + (0.0 if s["passed"] else 3.0)
            + duty_cost * max(0.0, duty_min - min(s["duty_factor"].values()))
            + CROUCH_COST * max(0.0, (90.0 if knee is None else knee) - KNEE_MID_DEG))
    return float(cost), s


def params_of(base, x):
    return base.with_corner(CORNER, **{n: float(v) for n, v in zip(NAMES, x)})


def evaluate(ex, base, X, guard: bool = False, duty=(DUTY_MIN, DUTY_COST)) -> list:
    """[(score, walk rows)] per candidate; with ``guard`` the walk over GUARD_WALK_STATES and
    the mean over the run, jump and hop from GUARD_STATES of 10 per fall and 3 per rollout that
    fails its criteria added."""
    states = GUARD_WALK_STATES if guard else STATES
    jobs = [(params_of(base, x), sd, duty) for x in X for sd in states]
    res = list(ex.map(one, jobs, chunksize=4))
    n = len(states)
    out = [(float(np.mean([c for c, _ in res[i * n:(i + 1) * n]])), res[i * n:(i + 1) * n])
           for i in range(len(X))]
    if guard:
        gj = [(params_of(base, x), g, sd) for x in X for g in ("run", "jump", "hop")
              for sd in GUARD_STATES]
        gr = list(ex.map(guard_terms, gj, chunksize=4))
        m = 3 * len(GUARD_STATES)
        out = [(f + float(np.mean([10.0 * fell + 3.0 * (not ok)
                                   for fell, ok in gr[i * m:(i + 1) * m]])), rows)
               for i, (f, rows) in enumerate(out)]
    return out


def medians(rows) -> dict:
    ss = [s for _, s in rows if not s["fell"]]

    def med(k):
        v = [s[k] for s in ss if s.get(k) is not None]
        return round(float(np.median(v)), 4) if v else None
    return {"stood": len(ss), "passed": sum(s["passed"] for _, s in rows), "froude": med("froude"),
            "peak_bw": med("peak_vertical_grf_bw"), "peak_at": med("peak_vertical_grf_at"),
            "double_support": med("double_support"), "knee_mid_deg": med("knee_mid_deg")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", required=True, help="gains file to start from")
    ap.add_argument("--guard", action="store_true",
                    help="score the walk over more tuning states and the run, jump and hop's "
                         "criteria and falls beside it")
    ap.add_argument("--duty-min", type=float, default=DUTY_MIN,
                    help="the duty margin below which the score grows (default %(default)s)")
    ap.add_argument("--duty-cost", type=float, default=DUTY_COST,
                    help="the score per unit of duty below the margin (default %(default)s)")
    ap.add_argument("--out", default="out/walk_landing")
    a = ap.parse_args()
    if not (0.5 <= a.duty_min <= 0.7 and 0.0 <= a.duty_cost <= 1000.0):
        ap.error("--duty-min must be in [0.5, 0.7] and --duty-cost in [0, 1000]")
    duty = (a.duty_min, a.duty_cost)
    from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.problem import Problem
    from pymoo.core.termination import NoTermination
    from pymoo.problems.static import StaticProblem

    from cpgbiped.envs.control.controller import read_gains
    from cpgbiped.envs.search.controller_tuning import set_by_hand

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    base, _ = read_gains(a.start)
    x0 = np.array([getattr(base.corner(CORNER), n) for n in NAMES])
    problem = Problem(n_var=len(NAMES), n_obj=1, xl=0.0, xu=1.0)
    alg = CMAES(x0=np.clip((x0 - LO) / (HI - LO), 0.0, 1.0), sigma=SIGMA, popsize=POP,
                restarts=0, seed=SEED)
    alg.setup(problem, termination=NoTermination())
    with ProcessPoolExecutor(2) as ex, open(out / "history.jsonl", "w") as log:
        f0, r0 = evaluate(ex, base, [x0], a.guard, duty)[0]
        best = (f0, x0, r0)
        print(f"start: {f0:.3f} {medians(r0)}", flush=True)
        for gen in range(GENS):
            pop = alg.ask()
            X = LO + np.clip(pop.get("X"), 0.0, 1.0) * (HI - LO)
            res = evaluate(ex, base, X, a.guard, duty)
            Evaluator().eval(StaticProblem(problem, F=np.array([[f] for f, _ in res])), pop)
            alg.tell(infills=pop)
            for x, (f, rows) in zip(X, res):
                log.write(json.dumps({"gen": gen, "score": f, "x": dict(zip(NAMES, x.tolist())),
                                      **medians(rows)}) + "\n")
                if f < best[0]:
                    best = (f, x, rows)
            log.flush()
            print(f"generation {gen}: best so far {best[0]:.3f} {medians(best[2])}", flush=True)
    f, x, rows = best
    info = ", ".join(f"{k} {v}" for k, v in medians(rows).items())
    note = NOTE.format(start=a.start, out=a.out, start_score=f0, score=f, info=info)
    if duty != (DUTY_MIN, DUTY_COST):
        note += "The duty's margin %g, %g per unit below it. " % duty
    if a.guard:
        note += ("With --guard: the walk from %d-%d, the run, jump and hop from %d-%d over %g s + "
                 "%g s, 10 per fall and 3 per failed criteria. " % (
                     GUARD_WALK_STATES[0], GUARD_WALK_STATES[-1], GUARD_STATES[0],
                     GUARD_STATES[-1], SETTLE_S, GUARD_S))
    set_by_hand(a.start, {f"{CORNER}.{n}": float(v) for n, v in zip(NAMES, x)},
                out / "gains.json", note)
    print(f"wrote {out / 'gains.json'}: {dict(zip(NAMES, np.round(x, 4).tolist()))}")


if __name__ == "__main__":
    main()
