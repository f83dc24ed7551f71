"""Choose the start-up gains' hand-over time constant tau_s on selection states disjoint from
the tests' and the README's.

For each candidate tau_s, the gains are --live's corners with --startup-from's corners as
start-up gains (envs.search.controller_tuning.set_startup). The walk preset is validated from
the random CPG states of seeds 2000-2099 and the jump preset from 2000-2049 (20 s after
settling, as ``cpgbiped validate``); seeds 2000-2099 are neither the tuning conditions'
(1000-1099), the tests' (10-19) nor the census's (3000 and up). The rule, fixed before any
result was seen: score = walk passes + jump named jump - 3 x (walk falls + jump falls) (a
fall is worse than a miss); the highest score wins, the smaller tau_s on a tie. Writes
--out (JSON: the candidates' counts and scores, the choice, this command).

    python scripts/select_startup_tau.py --live out/tune_chain/j2/gains.json \\
        --startup-from out/tune_chain/w4/gains.json --out envs/control/startup_selection.json

Without --startup-from, the start-up corners are --live's own (gains that already have start-up
gains: tau_s re-chosen after later links moved the corners, the end of scripts/tune_gains.sh).
"""
import argparse
import json
import os
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from census import one  # noqa: E402  (gait, seed, summary, failures) of one validated rollout

CANDIDATES = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0)
WALK_SEEDS = range(2000, 2100)
JUMP_SEEDS = range(2000, 2050)


def own_startup_corners(live: str, out: Path) -> str:
    """A gains file (at ``out``) whose corners are ``live``'s start-up corners."""
    d = json.loads(Path(live).read_text())
    if "startup" not in d:
        sys.exit(f"select_startup_tau: {live} has no start-up gains; give --startup-from")
    d["corners"] = d["startup"]["corners"]
    out.write_text(json.dumps(d))
    return str(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--live", required=True, help="gains whose corners the body runs on")
    ap.add_argument("--startup-from", help="gains whose corners start it (default: --live's "
                    "own start-up corners)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--candidates", default=",".join(map(str, CANDIDATES)))
    ap.add_argument("--apply", help="also write --live's gains with the chosen tau_s here "
                    "(a link of scripts/tune_gains.sh)")
    ap.add_argument("--note", default="", help="why, for --apply's provenance entry")
    a = ap.parse_args()
    from cpgbiped.envs.search.controller_tuning import set_startup

    rows = []
    with tempfile.TemporaryDirectory() as tmp, ProcessPoolExecutor(min(2, os.cpu_count() or 1)) as ex:
        startup_from = a.startup_from or own_startup_corners(a.live, Path(tmp) / "startup.json")
        for tau in (float(x) for x in a.candidates.split(",")):
            g = str(Path(tmp) / f"gains_{tau:g}.json")
            set_startup(a.live, startup_from, tau, g, "candidate")
            jobs = ([("walk", s, g, 1.0, None, 0.0, None) for s in WALK_SEEDS]
                    + [("jump", s, g, 1.0, None, 0.0, None) for s in JUMP_SEEDS])
            res = list(ex.map(one, jobs))
            walk = [r for r in res if r[0] == "walk"]
            jump = [r for r in res if r[0] == "jump"]
            fell = lambda rows: sum(r[2]["fell_at_s"] is not None for r in rows)  # noqa: E731
            row = {"tau_s": tau, "walk_passes": sum(not r[3] for r in walk),
                   "walk_falls": fell(walk),
                   "jump_named": sum(r[2]["physical_gait"] == "jump" for r in jump),
                   "jump_falls": fell(jump), "n_walk": len(walk), "n_jump": len(jump)}
            row["score"] = (row["walk_passes"] + row["jump_named"]
                            - 3 * (row["walk_falls"] + row["jump_falls"]))
            rows.append(row)
            print(json.dumps(row), flush=True)
    best = max(rows, key=lambda r: (r["score"], -r["tau_s"]))
    out = {"rule": "score = walk passes + jump named - 3 (walk falls + jump falls); highest "
                   "wins, smaller tau_s on a tie",
           "walk_seeds": [WALK_SEEDS.start, WALK_SEEDS.stop - 1],
           "jump_seeds": [JUMP_SEEDS.start, JUMP_SEEDS.stop - 1],
           "command": "python scripts/select_startup_tau.py " + " ".join(sys.argv[1:]),
           "candidates": rows, "tau_s": best["tau_s"]}
    Path(a.out).write_text(json.dumps(out, indent=1) + "\n")
    print(f"select_startup_tau: tau_s = {best['tau_s']:g} (score {best['score']})")
    if a.apply:
        if not a.startup_from:
            sys.exit("select_startup_tau: --apply needs --startup-from (its provenance names it)")
        set_startup(a.live, a.startup_from, best["tau_s"], a.apply, a.note)


if __name__ == "__main__":
    main()
