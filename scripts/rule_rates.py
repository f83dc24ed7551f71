"""A candidate gains file against a baseline, counted over CPG states no tuning used: the
measurements of an adoption rule on rates (journal, sessions 35, 37, 38).

    python scripts/rule_rates.py CANDIDATE.json --first 2900 [--baseline GAINS.json]
                                 [--n 100] [--n-perturbed 30] [--n-feedback 50] [--json OUT]

The body is chaotic: one test condition is a coin, so a change of the gains is judged by rates
over many random initial CPG states (seeds [--first, --first + n)), each preset (Table 2
weights) validated for 20 s after 2 s of settling, as ``cpgbiped validate`` does. Counted, for
the baseline (default: the committed gains) and the candidate, in the same run:

- passes of every criterion and falls, per preset, over n states, open loop;
- the perturbation rollouts kept (named their own gait by the contacts, no fall) per preset
  and kind over the first --n-perturbed states: unperturbed, friction x0.5 and x2.0, and at
  6 s +-5 N s held 0.2 s (SCONE's) or as a one-tick blow (7 kinds x 4 presets);
- passes with the body's feedback into the CPG (the recommended gain) over the first
  --n-feedback states;
- each preset from its Table 3 state, open loop: passes;
- below the table, the states each preset's passes were re-dealt in (lost and gained in the
  same state, open loop and with feedback), which equal totals hide.

Beside each difference, its sampling noise: the standard deviation of a difference of two
binomial counts over the same number of states, sqrt(n p1 (1 - p1) + n p2 (1 - p2)) with the
observed rates (the two gains' rollouts are not independent draws, so this is a scale for the
tolerances a rule should fix beforehand, not a test). A rule fixes its clauses and its seed
bank before the candidate meets these states; this script only counts.

Seed banks used so far (do not reuse them for a new rule): 10-19 the tests' random states;
1000-1099 tuning; 2000-2099, 2100-2147, 2200-2349, 2350-2379, 2400-2419, 2450-2479 and
2500-2999, 5000-5099, 5100-5199 and 5250-5419 earlier rules (2800-2899, 2900-2999 and
5000-5099 in session 38, 5100-5199 in session 39, 5250-5329 in session 40: the gated feedback's
adoption, 5330-5419: the secondary sets' merges and re-selection); 3000-3099, 4000-4099 and 5200-5249 censuses,
transitions and secondary checks (5200-5249: the feedback forms, session 39; 5420-5519: the
walk's start with the gated feedback, session 40); 5520-5579 the secondary sets' merge by net
confirmations (session 41); 5580-5759 the run corner's margin re-search (rule R5, session 41);
5760-5779 the push envelopes of the committed gains and of a run corner re-searched with the
backward pushes (scripts/envelope_census.py, session 42); 5780-5909 rule G, the graded
feedback (session 43: the presets 5780-5879, the transitions 5880-5909); 5910-6039 rule H, the
trunk's posture followed at a rate (session 44: the transitions 5910-5939, the presets
5940-6039), 6040-6169 rule H', the same opened over the start-up (the transitions 6040-6069, the
presets 6070-6169); 6170-6269 and 6270-6369 rules J and J', the hop's start-up corner (session
46); 6370-6469 rule K, the jump's capture response (session 47); 6470-6599 rule L, the same
response judged with the tests' conditions as distributions (session 48: the presets
6470-6569, the transitions 6570-6599); 6600-6729 rule M, the hop's start-up corner of rule J'
judged the same way (the presets 6600-6699, the transitions 6700-6729); 6730-6859 rule N, the
feedback faded in over the start-up (session 49: the presets with feedback 6730-6829; 6830-6859
declared, not run), 6860-6989 rule O, the run's start-up corner (the presets 6860-6959;
6960-6989 declared, not run), 6990-7119 rule P, the run's start-up corner searched (the presets
6990-7089; 7090-7119 declared, not run); 7120-7249 rule Q, the run corner's stance knee (the
presets 7120-7219, the transitions 7220-7249; session 50); 7250-7379 rule S, the hop corner's
balance reflex (the presets 7250-7349, the transitions 7350-7379), 7380-7509 rule T, the same
with positive force feedback (the presets 7380-7479, the transitions 7480-7509; session 51);
7510-7629 rule U, the touchdown pulse as the recommended feedback (the presets 7510-7589, the
envelopes 7590-7599, the transitions 7600-7629), 7630-7769 rule V, the gated angle at K = 0.02
(the presets 7630-7709, the envelopes 7710-7719, the transitions 7720-7749, the Matsuoka walk
7750-7769; session 52).
Unused: 7770 and up.
The tests' and the tuning's states are refused; a bank an earlier rule used is counted with a
note (re-counting that rule is what it is for then).
"""
import argparse
import json
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from census import one as census_one  # noqa: E402  (scripts/census.py: one preset, one state)

GAITS = ("walk", "run", "jump", "hop")
PERTURBATIONS = {"unperturbed": {}, "friction x0.5": {"friction_scale": 0.5},
                 "friction x2.0": {"friction_scale": 2.0},
                 "push +5": {"push": (6.0, 5.0, 0.2)}, "push -5": {"push": (6.0, -5.0, 0.2)},
                 "blow +5": {"push": (6.0, 5.0, 0.004)}, "blow -5": {"push": (6.0, -5.0, 0.004)}}
# (first, last) CPG seeds of the banks earlier rules, censuses and checks used (docstring)
USED_BANKS = ((2000, 2099), (2100, 2147), (2200, 2349), (2350, 2379), (2400, 2419), (2450, 2479),
              (2500, 2999), (3000, 3099), (4000, 4099), (5000, 5099), (5100, 5199),
              (5200, 5249), (5250, 5329), (5330, 5419), (5420, 5519), (5520, 5579),
              (5580, 5759), (5760, 5779), (5780, 5909), (5910, 6039), (6040, 6169),
              (6170, 6369), (6370, 6469), (6470, 6599), (6600, 6729), (6730, 6859),
              (6860, 6989), (6990, 7119), (7120, 7249), (7250, 7379),
              (7380, 7509), (7510, 7629), (7630, 7769))


def one(job):
    """One preset from one state (None: its Table 3 state) under one condition (census.py's
    rollout, 20 s after settling)."""
    gains, gait, seed, kind, feedback = job
    kw = PERTURBATIONS[kind]
    _, _, s, _ = census_one((gait, seed, gains, kw.get("friction_scale", 1.0), kw.get("push"),
                             feedback, None))
    return {"gait": gait, "seed": seed, "kind": kind, "feedback": feedback,
            "passed": bool(s["passed"]), "fell": bool(s["fell"]),
            "kept": bool(s["physical_gait"] == gait and not s["fell"])}


def jobs(gains, first, n, n_perturbed, n_feedback, k_feedback):
    out = [(gains, g, s, "unperturbed", 0.0) for g in GAITS for s in range(first, first + n)]
    out += [(gains, g, s, k, 0.0) for g in GAITS for s in range(first, first + n_perturbed)
            for k in PERTURBATIONS if k != "unperturbed"]
    out += [(gains, g, s, "unperturbed", k_feedback) for g in GAITS
            for s in range(first, first + n_feedback)]
    out += [(gains, g, None, "unperturbed", 0.0) for g in GAITS]
    return out


def counts(rows, first, n_perturbed):
    """The rule's counts from one gains file's rows."""
    ol = [r for r in rows if r["feedback"] == 0 and r["seed"] is not None]
    plain = [r for r in ol if r["kind"] == "unperturbed"]
    pert = [r for r in ol if r["kind"] != "unperturbed" or r["seed"] < first + n_perturbed]
    fb = [r for r in rows if r["feedback"] > 0]
    t3 = [r for r in rows if r["seed"] is None]
    c = {}
    for g in GAITS:
        c[f"passes {g}"] = sum(r["passed"] for r in plain if r["gait"] == g)
        c[f"falls {g}"] = sum(r["fell"] for r in plain if r["gait"] == g)
    for g in GAITS:
        for k in PERTURBATIONS:
            c[f"kept {g} {k}"] = sum(r["kept"] for r in pert if r["gait"] == g and r["kind"] == k)
        c[f"kept {g}"] = sum(r["kept"] for r in pert if r["gait"] == g)
    c["kept all"] = sum(r["kept"] for r in pert)
    for g in GAITS:
        c[f"feedback passes {g}"] = sum(r["passed"] for r in fb if r["gait"] == g)
        c[f"feedback falls {g}"] = sum(r["fell"] for r in fb if r["gait"] == g)
    for g in GAITS:
        c[f"Table 3 passes {g}"] = sum(r["passed"] for r in t3 if r["gait"] == g)
    return c


def churn(base_rows, cand_rows) -> dict:
    """Which states a candidate re-deals, beside the totals that hide it (journal, session 49,
    rule P: a start-up corner that left the hop's passes at 88 -> 90 of 100 lost 5 states and
    gained 7): per preset, over its unperturbed rows of random states, open loop and with
    feedback, (passes lost, passes gained): states where the baseline passes and the
    candidate does not, and the reverse."""
    def passed(rows):
        return {(r["gait"], r["seed"], r["feedback"] > 0): r["passed"] for r in rows
                if r["kind"] == "unperturbed" and r["seed"] is not None}
    pb, pc = passed(base_rows), passed(cand_rows)
    out = {}
    for g in GAITS:
        for fb, label in ((False, "open loop"), (True, "feedback")):
            keys = [k for k in pb if k[0] == g and k[2] == fb and k in pc]
            out[f"{label} {g}"] = (sum(pb[k] and not pc[k] for k in keys),
                                   sum(pc[k] and not pb[k] for k in keys))
    return out


def sizes(n, n_perturbed, n_feedback):
    """How many rollouts each count is over."""
    s = {}
    for g in GAITS:
        s[f"passes {g}"] = s[f"falls {g}"] = n
        for k in PERTURBATIONS:
            s[f"kept {g} {k}"] = n_perturbed
        s[f"kept {g}"] = n_perturbed * len(PERTURBATIONS)
        s[f"feedback passes {g}"] = s[f"feedback falls {g}"] = n_feedback
        s[f"Table 3 passes {g}"] = 1
    s["kept all"] = n_perturbed * len(PERTURBATIONS) * len(GAITS)
    return s


def noise(a, b, n):
    """Standard deviation of b - a for two binomial counts over n draws each."""
    if n <= 1:
        return 0.0
    p, q = a / n, b / n
    return math.sqrt(n * p * (1 - p) + n * q * (1 - q))


def check_bank(ap: argparse.ArgumentParser, first: int, n: int) -> None:
    """Refuse (a usage error) a seed bank that overlaps the tests' or the tuning's states; note
    on stderr the banks of :data:`USED_BANKS` it overlaps."""
    if 10 <= first + n - 1 and first <= 19 or first < 1100 and first + n > 1000:
        ap.error("the states overlap the tests' (10-19) or the tuning's (1000-1099)")
    used = [(lo, hi) for lo, hi in USED_BANKS if first <= hi and first + n - 1 >= lo]
    if used:
        print("note: CPG seeds " + ", ".join(f"{lo}-{hi}" for lo, hi in used) + " are listed "
              "as used (by an earlier rule or census, or by the rule being measured, which "
              "lists its bank when it is declared): fine for that rule, not for a new one",
              file=sys.stderr)


def check_gains_files(ap: argparse.ArgumentParser, *files: str) -> None:
    """Refuse (a usage error) a gains file that cannot be read, before any rollout starts."""
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.envs.control.controller import read_gains

    for gains in files:
        try:
            read_gains(gains)
        except (InputError, OSError) as e:
            ap.error(f"{gains}: {e}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("candidate", help="the candidate gains file")
    ap.add_argument("--baseline", default=None,
                    help="the baseline gains file (default: the committed gains)")
    ap.add_argument("--first", type=int, required=True, help="the rule's first CPG seed")
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--n-perturbed", type=int, default=30)
    ap.add_argument("--n-feedback", type=int, default=50)
    ap.add_argument("--json", default=None, help="write every rollout's row here")
    a = ap.parse_args()
    if not (a.n >= a.n_perturbed >= 0 and a.n >= a.n_feedback >= 0 and a.n > 0):
        ap.error("--n must be positive and at least --n-perturbed and --n-feedback")
    check_bank(ap, a.first, a.n)
    from cpgbiped.cpg.feedback import RECOMMENDED
    from cpgbiped.envs.control.controller import GAINS_FILE

    a.baseline = str(a.baseline or GAINS_FILE)
    check_gains_files(ap, a.baseline, a.candidate)

    k_fb = RECOMMENDED["ml"]
    rows = {}
    with ProcessPoolExecutor(2) as ex:
        for name, gains in (("baseline", a.baseline), ("candidate", a.candidate)):
            rows[name] = list(ex.map(one, jobs(gains, a.first, a.n, a.n_perturbed, a.n_feedback,
                                               k_fb), chunksize=8))
    cb = counts(rows["baseline"], a.first, a.n_perturbed)
    cc = counts(rows["candidate"], a.first, a.n_perturbed)
    sz = sizes(a.n, a.n_perturbed, a.n_feedback)
    print(f"CPG seeds {a.first}-{a.first + a.n - 1} (perturbed: the first {a.n_perturbed}, "
          f"feedback K = {k_fb}: the first {a.n_feedback}); baseline {a.baseline}, "
          f"candidate {a.candidate}")
    print(f"{'count':34s} {'of':>5s} {'baseline':>9s} {'candidate':>10s} {'diff':>6s} {'noise sd':>9s}")
    for key in cb:
        print(f"{key:34s} {sz[key]:5d} {cb[key]:9d} {cc[key]:10d} {cc[key] - cb[key]:+6d} "
              f"{noise(cb[key], cc[key], sz[key]):9.1f}")
    moved = churn(rows["baseline"], rows["candidate"])
    print("states re-dealt, passes lost / gained in the same state: "
          + ", ".join(f"{k} {lost}/{won}" for k, (lost, won) in moved.items()))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"first": a.first, "n": a.n, "n_perturbed": a.n_perturbed,
                       "n_feedback": a.n_feedback, "feedback_gain": k_fb,
                       "baseline": a.baseline, "candidate": a.candidate,
                       "counts": {"baseline": cb, "candidate": cc},
                       "churn": {k: list(v) for k, v in moved.items()}, "rows": rows}, f)


if __name__ == "__main__":
    main()
