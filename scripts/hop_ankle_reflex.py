"""The hop corner's ankle reflex, chosen by a sweep on tuning CPG states: one link of a tuning
chain (set_by_hand, with what was set and why), from START's gains into OUT/ha.

    python scripts/hop_ankle_reflex.py START.json OUT [--sweep]

The paper tells the two-legged jump from the hop by the ankle: in the jump its flexor and
extensor alternate (the ankle rotates, a push-off), in the hop all four cells are in phase (the
co-activation holds the ankle, a spring); the physical classifier splits them at 30 degrees of
stance ankle excursion (envs/gaits/criteria.py). The ankle's balance reflex,
b = k_ax (x_com - x_sup - x_bal) + k_av v_com, adds to one muscle of the pair and so turns the
ankle; on a floor that grips more the hop's ankle turned further (committed gains, tuning states
1000-1019, median stance excursion 24.5 deg on friction x1.0, 30.1 on x2.0: named a hop in 8 of
20 there, a jump in the others). This link lowers the hop corner's position gain k_ax.

--sweep re-runs the choice (about 5 minutes on 2 cores): each value of K_AX_GRID over tuning CPG
states 1000-1039 (neither the tests' Table 3 state and seeds 10-19, nor any rule's states) on
friction x1.0, x2.0 and x0.5 and after +-5 N s held 0.2 s at 6 s (2 s of settling + 20 s); the
value that keeps the most hop rollouts (named a hop, no fall), among those whose unperturbed
passes are at least the start's minus one. Without --sweep the recorded choice (K_AX) is set.

NOT ADOPTED (session 38; not a link of scripts/tune_gains.sh): the rule RULE below, fixed before
the sweep ran, measured on CPG seeds 2800-2899 with

    python scripts/hop_ankle_reflex.py envs/control/gains.json OUT
    python scripts/rule_rates.py OUT/ha/gains.json --first 2800

kept the hop on friction x2.0 in 27 of 30 (14 with the committed gains) and every open-loop
clause, but the hop with feedback passed in 36 of 50 against 45 (falls 2 -> 6; the noise of
that difference about 3.8). A second rule, after sync_land was adopted, with the sweep re-run on
those gains (choice 6.25; `python scripts/hop_ankle_reflex.py envs/control/gains.json OUT
--sweep` exits with the mismatch against K_AX, which records the first choice) and CPG seeds
5000-5099, failed the same way: the hop on x2.0 kept 12 -> 29 of 30, every open-loop clause
met, the hop with feedback falls in 4 of 50 against 0 (out/s38/rule_hop_reflex2.md, quoted in
the journal). The journal (session 38) has the rest.
"""
import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from cpgbiped.envs.search.controller_tuning import set_by_hand

sys.path.insert(0, str(Path(__file__).resolve().parent))
from census import one as census_one  # noqa: E402  (scripts/census.py: one preset, one state)

K_AX = 6.75
K_AX_GRID = (6.0, 6.25, 6.5, 6.75, 7.0)
SEEDS = range(1000, 1040)
CONDITIONS = {"x1.0": {}, "x2.0": {"friction_scale": 2.0}, "x0.5": {"friction_scale": 0.5},
              "+5 N s": {"push": (6.0, 5.0, 0.2)}, "-5 N s": {"push": (6.0, -5.0, 0.2)}}
# The sweep's result (python scripts/hop_ankle_reflex.py START OUT --sweep, session 38, from the
# committed gains of 06faf06, 66 s): hop rollouts kept of 40 on x1.0 / x2.0 / x0.5 / +5 / -5 N s
# (unperturbed passes): start (7.157) 37 / 16 / 40 / 21 / 26 (33), total 140; 6.0: 37 / 38 / 40 /
# 26 / 27 (32), 168; 6.25: 38 / 38 / 40 / 26 / 27 (34), 169; 6.5: 38 / 38 / 40 / 28 / 21 (33), 165;
# 6.75: 39 / 36 / 40 / 32 / 23 (35), 170; 7.0: 37 / 32 / 39 / 24 / 23 (34), 155.
SWEEP = ("kept of 200 (x1.0, x2.0, x0.5, +-5 N s over seeds 1000-1039): 7.157 (start) 140, 6.0 168, "
         "6.25 169, 6.5 165, 6.75 170, 7.0 155; on x2.0 16 -> 36 of 40")
RULE = ("rule (out/s38/rule_hop_reflex.md, fixed before the sweep ran, CPG seeds 2800-2899): "
        "H1 the hop on x2.0 kept over 2800-2829 >= committed + 5, its passes >= committed - 3; "
        "H2 each preset's passes >= committed - 3, falls <= + 3; H3 the 840 perturbation rollouts "
        "kept >= committed's; H4 all four pass from their Table 3 states; H5 with feedback over "
        "2800-2849 each preset's passes >= committed - 2; H6 matrices and cross-family "
        "transitions. Measured: H1 met (x2.0 14 -> 27; passes 84 -> 89), H2 met (walk 100 -> 99, "
        "run 98 -> 97, jump 99 -> 100, hop 84 -> 89; falls 8 -> 9), H3 met (700 -> 718), H4 met, "
        "H5 NOT met (the hop with feedback 45 -> 36, falls 2 -> 6): not adopted")


def _one(job):
    """(passes every criterion, kept: named a hop without a fall) for one tuning state under
    one condition (census.py's rollout, 20 s after settling)."""
    gains, seed, cond = job
    kw = CONDITIONS[cond]
    _, _, s, _ = census_one(("hop", seed, gains, kw.get("friction_scale", 1.0), kw.get("push"),
                             0.0, None))
    return bool(s["passed"]), bool(s["physical_gait"] == "hop" and not s["fell"])


def sweep(start: str, out: Path) -> dict:
    """Every candidate value (and the start's) over SEEDS x CONDITIONS: passes unperturbed and
    rollouts kept per condition; the choice by the module docstring's criterion."""
    from cpgbiped.envs.control.controller import read_gains

    base = read_gains(start)[0].synchronous_coactive.k_ax
    files = {"start": start}
    for v in K_AX_GRID:
        f = out / f"k_ax_{v}.json"
        set_by_hand(start, {"synchronous_coactive.k_ax": v}, f, "sweep candidate")
        files[str(v)] = str(f)
    rows = {}
    with ProcessPoolExecutor(2) as ex:
        for name, f in files.items():
            jobs = [(f, s, c) for c in CONDITIONS for s in SEEDS]
            res = list(ex.map(_one, jobs, chunksize=4))
            kept = {c: sum(k for (p, k), (_, _, cc) in zip(res, jobs) if cc == c) for c in CONDITIONS}
            passes = sum(p for (p, k), (_, _, cc) in zip(res, jobs) if cc == "x1.0")
            rows[name] = {"passes": passes, "kept": kept, "kept_total": sum(kept.values())}
            print(name, rows[name], flush=True)
    ok = [v for v in K_AX_GRID if rows[str(v)]["passes"] >= rows["start"]["passes"] - 1]
    choice = max(ok, key=lambda v: rows[str(v)]["kept_total"]) if ok else None
    return {"start_k_ax": base, "seeds": [SEEDS.start, SEEDS.stop - 1], "rows": rows, "choice": choice}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("start")
    ap.add_argument("out", type=Path)
    ap.add_argument("--sweep", action="store_true")
    a = ap.parse_args()
    d = a.out / "ha"
    d.mkdir(parents=True, exist_ok=True)
    if a.sweep:
        res = sweep(a.start, d)
        (d / "sweep.json").write_text(json.dumps(res, indent=1))
        print("choice", res["choice"])
        if res["choice"] != K_AX:
            sys.exit(f"hop_ankle_reflex: the sweep chose {res['choice']}, the recorded choice is {K_AX}")
    set_by_hand(a.start, {"synchronous_coactive.k_ax": K_AX}, d / "gains.json",
                f"the hop corner's ankle reflex position gain -> {K_AX} (scripts/hop_ankle_reflex.py); "
                f"sweep on tuning states: {SWEEP}; {RULE}")


if __name__ == "__main__":
    main()
