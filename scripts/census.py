"""Every criterion of each named Morris-Lecar preset over many random initial CPG states.

The tests report 13 conditions per gait; the body is chaotic, so a rate measured over more
states says more. Each preset (Table 2 weights) starts from the random CPG state of each seed
in [--first, --first + --n) and is validated for 20 s after settling, as ``cpgbiped validate``
does, with the committed gains or --gains FILE:

    python scripts/census.py walk,run,jump,hop --first 3000 --n 30 [--gains FILE]
                             [--friction F] [--push T I [--push-s S]] [--feedback [K]]
                             [--feedback-form FORM] [-v]

--friction scales the floor's friction, --push gives the torso a horizontal impulse of I N s
at T s (simulation time, settling included), its force held --push-s s (default 0.2, as
``validate`` holds it): the perturbations of the
tests measured over many states instead of one. --feedback closes the loop (the body's sensors
into the CPG, ``cpgbiped validate --feedback``): alone the recommended gain, or K (give the
gaits first: ``census.py walk --feedback``; ``--feedback walk`` reads "walk" as K).

Seeds 3000 and up are neither tuning conditions (1000-1099) nor the tests' (10-19); 3000-3029
were one adoption gate of a hand-set link (scripts/hop_placement.py), re-checked on 2200-2229.
Prints, per gait, how many pass every criterion, how many are named their own gait by the
contact classifier, and the seeds that fell.
"""
import argparse
import os
from concurrent.futures import ProcessPoolExecutor

SECONDS = 20.0  # validate's measured window (after its 2 s of settling)


def one(job):
    """One preset from one random CPG state under one perturbation: (gait, seed, summary,
    failed criteria)."""
    gait, seed, gains, friction, push, feedback, form = job  # form: None, the chosen pathway
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import CONTROL, read_gains
    from cpgbiped.envs.gaits.validate import validate

    params = read_gains(gains)[0] if gains else CONTROL
    s = validate(build("ml", gait, seed=seed), gait, SECONDS, params=params,
                 friction_scale=friction, push=push, feedback=feedback,
                 feedback_form=form).summary()
    return gait, seed, s, s["failures"]


def main() -> None:
    from cpgbiped.envs.experiments.robustness import PUSH_S  # the product's pushes

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("gaits", help="comma-separated presets")
    ap.add_argument("--first", type=int, default=3000)
    ap.add_argument("--n", type=int, default=30)
    ap.add_argument("--gains", default=None, help="a gains file (default: the committed one)")
    ap.add_argument("--friction", type=float, default=1.0, help="floor friction scale")
    ap.add_argument("--push", type=float, nargs=2, default=None, metavar=("T_S", "IMPULSE_NS"),
                    help="a horizontal push on the torso at T_S s of IMPULSE_NS N s (> 0 forwards)")
    ap.add_argument("--push-s", type=float, default=PUSH_S,
                    help="how long the push's force is held, s (default 0.2, SCONE's; 0.004: "
                         "one control tick, a blow)")
    ap.add_argument("--matrix", action="store_true",
                    help="also count the states from which every named preset gives its own "
                         "physical gait (the matrix's diagonal, `cpgbiped matrix --seed S`)")
    ap.add_argument("--feedback", nargs="?", const="recommended", default=None, metavar="K",
                    help="feed the body's sensors back into the CPG: alone the recommended "
                         "gain, or K (default: open loop)")
    ap.add_argument("--feedback-form", default=None, metavar="FORM",
                    help="with --feedback: a Morris-Lecar pathway other than the chosen one "
                         "(one of cpg.feedback.ML_FORMS)")
    ap.add_argument("-v", action="store_true", help="one line per failing rollout")
    a = ap.parse_args()
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.cpg.feedback import RECOMMENDED, check_gain

    try:
        feedback = (0.0 if a.feedback is None else RECOMMENDED["ml"]
                    if a.feedback == "recommended" else check_gain("ml", a.feedback))
    except InputError as e:
        ap.error(str(e))
    gaits = a.gaits.split(",")
    push = (*a.push, a.push_s) if a.push else None
    if push is not None:  # the rollout's own check, before any worker starts
        from cpgbiped.cpg.errors import InputError
        from cpgbiped.envs.gaits.criteria import SETTLE_S
        from cpgbiped.envs.simulation.rollout import check_push

        try:
            check_push(push, SETTLE_S + SECONDS)
        except InputError as e:
            ap.error(str(e))
    if a.feedback_form is not None:
        from cpgbiped.cpg.feedback import ML_FORMS

        if a.feedback_form not in ML_FORMS:
            ap.error(f"--feedback-form: one of {', '.join(ML_FORMS)}, got {a.feedback_form!r}")
    jobs = [(g, s, a.gains, a.friction, push, feedback, a.feedback_form) for g in gaits
            for s in range(a.first, a.first + a.n)]
    with ProcessPoolExecutor(min(2, os.cpu_count() or 1)) as ex:
        res = list(ex.map(one, jobs))
    if feedback:
        print(f"closed loop: feedback gain K = {feedback:g}")
    for g in gaits:
        rows = [r for r in res if r[0] == g]
        fell = [r[1] for r in rows if r[2]["fell_at_s"] is not None]
        named = sum(r[2]["physical_gait"] == g for r in rows)
        ok = sum(not r[3] for r in rows)
        print(f"{g}: passes {ok}/{len(rows)}, named {g} {named}/{len(rows)}, "
              f"fell {len(fell)} {fell}")
        if a.v:
            for _, seed, s, fails in rows:
                if fails:
                    print(f"   seed {seed}: {'; '.join(fails)[:160]}")
    if a.matrix:
        seeds = range(a.first, a.first + a.n)
        full = [sd for sd in seeds
                if all(r[2]["physical_gait"] == r[0] for r in res if r[1] == sd)]
        what = ("the matrix's diagonal 4/4" if len(gaits) == 4 and not a.gains
                and a.friction == 1.0 and not push and not feedback
                else f"{len(gaits)}/{len(gaits)} presets")
        print(f"every preset its own gait ({what}) from {len(full)}/{len(seeds)} states")


if __name__ == "__main__":
    main()
