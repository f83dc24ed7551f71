"""How often the tests' single conditions hold when the controller changes by nothing that
matters: the chance that a rule's clause on the tests' conditions (rules J and K, journal
sessions 46 and 47) passes a change that leaves every rate where it is.

    python scripts/condition_coins.py [--rerolls 10] [--eps 1e-6] [--gains FILE] [--json FILE]
    python scripts/condition_coins.py --compare BASE.json CANDIDATE.json

The body is chaotic: a change of the gains far below anything physical still moves every
trajectory after a few seconds, and each single test condition is then a new draw from its own
pass rate. Re-roll r (0 .. --rerolls) adds r x --eps rad to theta0, the placing thigh's
target, at every corner and start-up corner (1e-6 rad moves a foot by under a micrometre); r = 0
is the committed gains (or --gains FILE, whose re-rolls are then its own null). Each re-roll
counts what rule K's third clause counts, with its limits (K3; the baseline, where a limit is
relative, is re-roll 0):

- the 13 test conditions (tests/test_physics.py) of each preset, open loop, every criterion
  (the hop's cadence against the jump's of the same condition): >= 12 of 13 each;
- the same with the recommended feedback: each >= re-roll 0's - 1, and the jump never falls;
- the perturbations (friction x0.5, x2.0, +-5 N s held 0.2 s at 6 s): kept (named its own
  gait, no fall) >= 15 of 16;
- the Morris-Lecar matrix from the Table 3 state and random state 7: 4 of 4 each;
- the in-family transitions at 8 s (tests/test_transition.py's 16 ways): >= 6 of 16;
- the cross-family pairs reached in one of four ways: >= 4 of 8.

(The Hopf matrix and the Matsuoka walk, which rule K also names, are left out: rerolling them
is the same experiment on other networks.) Prints each re-roll's counts and whether the clause
holds, each count's null distribution (min, 5th percentile, median, max over the re-rolls
after 0: where a limit that a rule fixes before it meets a candidate could come from), then
each condition that did not hold in every re-roll with how often it held.

--compare judges a candidate's tests' conditions as distributions (rule L, journal session
48): two --json files, the baseline's and the candidate's re-rolls, each count's mean over
each file's draws, and whether the candidate's is lower by more than two standard errors of
the difference.
"""
import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from tests.test_physics import (CONDITION_IDS, CONDITIONS, PERTURBATION_IDS,  # noqa: E402
                                PERTURBATIONS as _TEST_PERTURBATIONS)
from tests.test_transition import CROSS, IN_FAMILY_CASES  # noqa: E402  (the tests' own ways)

GAITS = ("walk", "run", "jump", "hop")
# the tests' perturbations that issue 20 names: friction x0.5, x2.0, +-5 N s held 0.2 s
PERTURBATIONS = tuple((pid, cond) for pid, cond in zip(PERTURBATION_IDS, _TEST_PERTURBATIONS)
                      if pid in ("friction0.5", "friction2.0", "push+5", "push-5"))
MAX_SHIFT_RAD = 1e-4  # the largest re-roll's shift of theta0: far below anything physical


def params_for(r: int, eps: float, gains: str | None = None):
    from dataclasses import replace

    from cpgbiped.envs.control import control_kernel as kernel
    from cpgbiped.envs.control.controller import CONTROL, read_gains

    p = read_gains(gains)[0] if gains else CONTROL
    if r == 0:
        return p
    for c in kernel.CORNERS:
        p = p.with_corner(c, theta0=p.corner(c).theta0 + r * eps)
    if p.startup is not None:
        p = replace(p, startup=tuple(replace(c, theta0=c.theta0 + r * eps) for c in p.startup))
    return p


def job(task):
    """One rollout or transition of one re-roll: (re-roll, key, outcome)."""
    import numba

    numba.set_num_threads(1)
    from cpgbiped.cpg.feedback import RECOMMENDED
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.experiments.transition import default_seconds, transition
    from cpgbiped.envs.gaits.criteria import WINDOW_S
    from cpgbiped.envs.gaits.validate import validate

    r, eps, gains, kind, args = task
    p = params_for(r, eps, gains)

    def k_of(fb):
        return RECOMMENDED["ml"] if fb else 0.0

    def changed(a, b, ramp, fb):  # the tests' protocol: the change at 8 s
        return transition("ml", a, b, 8.0, ramp, default_seconds(a, b, 8.0, ramp),
                          feedback=k_of(fb), params=p)[0]

    if kind == "validate":
        gait, cid, cond, fb = args
        cond = dict(cond)
        seed = cond.pop("seed", None)
        s = validate(build("ml", gait, seed=seed), gait, WINDOW_S, params=p,
                     feedback=k_of(fb), **cond).summary()
        return r, ("validate", gait, cid, fb), s
    if kind == "in-family":
        res = changed(*args)
        # the transition's own verdict (no fall, A before, B settled), within 4 CPG cycles
        return r, ("in-family", *args), res["switched"] and res["cycles_to_switch"] <= 4
    a, b = args  # cross-family: reached in one of four ways
    reached = any(changed(a, b, ramp, fb)["cycles_to_switch"] is not None
                  for ramp in (0.0, 2.0) for fb in (False, True))
    return r, ("cross", a, b), reached


def tasks(r: int, eps: float, gains: str | None = None) -> list:
    out = []
    for fb in (False, True):
        out += [(r, eps, gains, "validate", (g, cid, cond, fb)) for g in GAITS
                for cid, cond in zip(CONDITION_IDS, CONDITIONS)]
    out += [(r, eps, gains, "validate", (g, pid, cond, False)) for g in GAITS
            for pid, cond in PERTURBATIONS]
    out += [(r, eps, gains, "validate", (g, "state7", {"seed": 7}, False)) for g in GAITS]
    out += [(r, eps, gains, "in-family", (a, b, ramp, k != 0.0))
            for a, b, ramp, k in IN_FAMILY_CASES]
    out += [(r, eps, gains, "cross", pair) for pair in CROSS]
    return out


def outcomes(results: dict) -> dict:
    """Single conditions -> held (bool), from one re-roll's results; ("jump no fall with
    feedback",): the jump stood in all 13 conditions with the feedback."""
    from cpgbiped.envs.gaits.criteria import CRITERIA

    pert = dict(PERTURBATIONS)
    held = {("jump no fall with feedback",): not any(
        s["fell"] for k, s in results.items() if k[0] == "validate" and k[1] == "jump" and k[3]
        and k[2] not in pert and k[2] != "state7")}
    for key, s in results.items():
        if key[0] != "validate":
            held[key] = s
            continue
        _, gait, cid, fb = key
        if cid in pert or cid == "state7":
            held[key] = (not s["fell"]) and s["physical_gait"] == gait
            continue
        ref = CRITERIA[gait].cadence_above
        others = {ref: results[("validate", ref, cid, fb)]} if ref else {}
        held[key] = not CRITERIA[gait].failures(s, others)
        if cid == "table3" and not fb:  # the matrix's Table 3 row: named, no fall
            held[("matrix", gait)] = (not s["fell"]) and s["physical_gait"] == gait
    return held


def clause(held: dict, base: dict | None) -> tuple[dict, bool]:
    """Rule K3's counts and whether every limit holds (base: re-roll 0's counts)."""
    pert = set(dict(PERTURBATIONS))
    n = {}
    for fb in (False, True):
        for g in GAITS:
            n[("conditions", g, fb)] = sum(v for k, v in held.items() if k[0] == "validate"
                                           and k[1] == g and k[3] == fb and k[2] not in pert
                                           and k[2] != "state7")
    n["perturbations"] = sum(v for k, v in held.items() if k[0] == "validate" and k[2] in pert)
    n["matrix table3"] = sum(v for k, v in held.items() if k[0] == "matrix")
    n["matrix state7"] = sum(v for k, v in held.items() if k[0] == "validate"
                             and k[2] == "state7")
    n["in-family"] = sum(v for k, v in held.items() if k[0] == "in-family")
    n["cross"] = sum(v for k, v in held.items() if k[0] == "cross")
    base = base or n
    ok = (all(n[("conditions", g, False)] >= 12 for g in GAITS)
          and all(n[("conditions", g, True)] >= base[("conditions", g, True)] - 1 for g in GAITS)
          and n["perturbations"] >= 15 and n["matrix table3"] == 4 and n["matrix state7"] == 4
          and n["in-family"] >= 6 and n["cross"] >= 4
          and held[("jump no fall with feedback",)])
    return n, ok


def label(name) -> str:
    """A count's printed name: ("conditions", "walk", True) -> "feedback walk"."""
    return (f"{'feedback' if name[2] else 'open loop'} {name[1]}" if isinstance(name, tuple)
            else name)


def compare(base: list[dict], cand: list[dict]) -> list[tuple]:
    """Each count's mean over the baseline's draws and over the candidate's, their difference
    and two standard errors of it, sqrt(s_b^2 / n_b + s_c^2 / n_c) (sample variances), and
    whether the candidate's is lower by more than that (for a count that varies in neither:
    lower at all). base, cand: one {label: count} per draw. -> (label, mean_b, mean_c,
    difference, 2 se, lower)."""
    rows = []
    for name in base[0]:
        b = np.array([d[name] for d in base], float)
        c = np.array([d[name] for d in cand], float)
        two_se = 2.0 * float(np.sqrt(b.var(ddof=1) / len(b) + c.var(ddof=1) / len(c)))
        diff = float(c.mean() - b.mean())
        rows.append((name, float(b.mean()), float(c.mean()), diff, two_se,
                     diff < -two_se if two_se > 0 else diff < 0))
    return rows


def to_json(held: dict, gains: str | None, eps: float) -> dict:
    """What --json writes: every single condition's outcome and each re-roll's counts (by
    label; "jump stands with feedback" 1 or 0). gains: None for the committed file."""

    def counts(h):
        n = {label(k): v for k, v in clause(h, None)[0].items()}
        n["jump stands with feedback"] = int(h[("jump no fall with feedback",)])
        return n

    return {"gains": gains, "eps": eps,
            "held": {str(r): {" ".join(map(str, k)): bool(v) for k, v in held[r].items()}
                     for r in held},
            "counts": {str(r): counts(held[r]) for r in held}}


def _counts_of(path: str) -> tuple[list[dict], dict]:
    """A --json file's counts, one dict per draw, and the file itself; ValueError without
    counts, with fewer than two draws, or with draws that do not count the same things."""
    try:
        d = json.loads(Path(path).read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON ({e})") from None
    if not isinstance(d, dict) or "counts" not in d:
        raise ValueError(f"{path} has no counts (written before --json wrote them)")
    if not isinstance(d["counts"], dict) or not all(
            isinstance(x, dict) and all(type(v) is int for v in x.values())
            for x in d["counts"].values()):
        raise ValueError(f"{path}: counts are not one {{name: integer}} per draw")
    draws = list(d["counts"].values())
    if len(draws) < 2:
        raise ValueError(f"{path} has {len(draws)} draw(s); a standard error needs at least 2")
    if any(set(x) != set(draws[0]) for x in draws):
        raise ValueError(f"{path}'s draws do not count the same things")
    return draws, d


def print_compare(base_path: str, cand_path: str) -> None:
    (base, bd), (cand, cd) = _counts_of(base_path), _counts_of(cand_path)
    kb, kc = set(base[0]), set(cand[0])
    if kb != kc:
        only = [f"{sorted(x - y)} only in {p}"
                for x, y, p in ((kb, kc, base_path), (kc, kb, cand_path)) if x - y]
        raise ValueError("the two files do not count the same things: " + "; ".join(only))

    def gains(d):
        return d.get("gains") or "the committed"

    print(f"each count's mean over {len(base)} draws ({base_path}, gains {gains(bd)}, "
          f"eps {bd.get('eps')}) and {len(cand)} ({cand_path}, gains {gains(cd)}, eps "
          f"{cd.get('eps')}): difference, 2 standard errors")
    if bd.get("eps") != cd.get("eps"):
        print("warning: the two files re-rolled by different eps")
    rows = compare(base, cand)
    for name, mb, mc, d, two_se, lower in rows:
        print(f"  {name:22s} {mb:6.2f} -> {mc:6.2f}  {d:+6.2f}  2 se {two_se:5.2f}"
              + ("  LOWER" if lower else ""))
    print("no count lower by more than 2 se" if not any(r[-1] for r in rows)
          else "lower: " + ", ".join(r[0] for r in rows if r[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rerolls", type=int, default=10, choices=range(1, 101), metavar="1..100")
    ap.add_argument("--eps", type=float, default=1e-6, help="rad per re-roll (default 1e-6)")
    ap.add_argument("--gains", default=None, metavar="FILE",
                    help="re-roll this gains file instead of the committed one")
    ap.add_argument("--json", default=None,
                    help="write every single condition's outcomes and each re-roll's counts")
    ap.add_argument("--compare", nargs=2, metavar=("BASE.json", "CANDIDATE.json"),
                    help="run nothing: compare two --json files' counts over their draws")
    a = ap.parse_args()
    if a.compare:
        try:
            print_compare(*a.compare)
        except (OSError, ValueError) as e:  # json's decode error is a ValueError
            ap.exit(2, f"condition_coins: error: {e}\n")
        return
    if not 0.0 < a.eps * a.rerolls <= MAX_SHIFT_RAD:
        ap.error(f"--eps > 0 and --rerolls x --eps at most {MAX_SHIFT_RAD:g} rad: far below "
                 "anything physical")
    all_tasks = [t for r in range(a.rerolls + 1) for t in tasks(r, a.eps, a.gains)]
    results = {r: {} for r in range(a.rerolls + 1)}
    with ProcessPoolExecutor(2) as ex:
        for r, key, out in ex.map(job, all_tasks, chunksize=4):
            results[r][key] = out
    held = {r: outcomes(results[r]) for r in results}
    base, _ = clause(held[0], None)
    n_ok = 0
    print("re-roll: open loop walk/run/jump/hop | feedback | perturbations | matrix T3/s7 | "
          "in-family | cross | jump no fall fb | K3 holds")
    for r in held:
        n, ok = clause(held[r], base)
        n_ok += ok and r > 0
        print(f"{r:3d}: " + "/".join(str(n[("conditions", g, False)]) for g in GAITS) + " | "
              + "/".join(str(n[("conditions", g, True)]) for g in GAITS)
              + f" | {n['perturbations']} | {n['matrix table3']}/{n['matrix state7']} | "
              f"{n['in-family']} | {n['cross']} | {held[r][('jump no fall with feedback',)]} | "
              f"{'yes' if ok else 'no'}")
    print(f"K3 holds in {n_ok} of {a.rerolls} re-rolls (re-roll 0, the committed gains, is the "
          f"baseline)")
    print("each count: the baseline; over the null re-rolls min / 5th percentile / median / max "
          "(a limit from the null, if a rule fixes one before it meets a candidate)")
    counts = [clause(held[r], base)[0] for r in held if r > 0]
    for name in base:
        null = np.array([c[name] for c in counts])
        print(f"  {label(name):28s} {base[name]:3d}   {null.min():3d} / "
              f"{np.percentile(null, 5):5.1f} / {np.median(null):5.1f} / {null.max():3d}")
    keys = sorted(held[0], key=str)
    print("conditions that did not hold in every re-roll (held in n of "
          f"{a.rerolls + 1}, re-roll 0 included):")
    for k in keys:
        c = sum(held[r][k] for r in held)
        if c < len(held):
            print(f"  {' '.join(str(x) for x in k)}: {c}")
    if a.json:
        Path(a.json).write_text(json.dumps(to_json(held, a.gains, a.eps), indent=1))


if __name__ == "__main__":
    main()
