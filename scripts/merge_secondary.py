"""Merge two `cpgbiped secondary --physics` results per target, chosen by the body on unused
random CPG states.

    python scripts/merge_secondary.py A.json B.json --first 5330 --n 30
                                      [--by confirmed|net] [--max-extra-falls F] --out MERGED.json

`cpgbiped secondary --physics` keeps, for each target, the candidate weight set that the body
confirms (both classifiers name the target, no fall) from most of its few selection states;
two runs of it (other controller gains, another number of selection states) can each hold the
better set for a different target. For each (target, source) this keeps A's or B's weight set,
whichever the body confirms from more of the random CPG states [--first, --first + --n)
(`cpgbiped check-secondary`'s count, envs.experiments.secondary_check); a tie goes to fewer
falls, then to A. With --by net, the rule `cpgbiped secondary --physics` itself ranks
candidates by (envs.search.secondary_physics.score): B's set replaces A's when its
confirmations net of falls are more; a tie goes to fewer falls, then to A. With
--max-extra-falls F (--by confirmed only; refused with --by net), B's set must also fall in
no more than F states above A's: confirmations bought with falls are refused.
The Table 3 state is never used to choose. Prints each target's counts and
the sums of A, B and the merge over those states (a rule about replacing a committed file is
the caller's: docs/RESULTS.md "Secondary gaits in the body"). Writes MERGED.json (format
"cpgbiped.secondary/1") with A's command, B's command and this one, and per target which file
it came from and its counts ("merged_from").

Seeds: 3000-3029 are check-secondary's default states, the README's report; choose on states
no rule has used (scripts/rule_rates.py lists the banks).
"""
from __future__ import annotations

import argparse
import copy
import json
import sys
from pathlib import Path


def take_b(a: tuple[int, int], b: tuple[int, int] | None,
           max_extra_falls: int | None = None, by: str = "confirmed") -> bool:
    """Whether B's weight set replaces A's for one target, from (confirmations, falls) over
    the same states. ``by="confirmed"``: more confirmations (with ``max_extra_falls``: and no
    more than that many falls above A's), or as many and fewer falls. ``by="net"``: more
    confirmations minus falls, or as many and fewer falls. A tie or a target B lacks: A."""
    if b is None:
        return False
    if by == "net":
        from cpgbiped.envs.search.secondary_physics import net_rank

        return net_rank(*b) < net_rank(*a)
    more = b[0] > a[0] and (max_extra_falls is None or b[1] <= a[1] + max_extra_falls)
    return more or (b[0] == a[0] and b[1] < a[1])


TESTS_AND_TUNING = ((10, 19), (1000, 1099))  # the tests' random states; the tuning's


def _keys(targets: list[dict]) -> list[tuple]:
    """(source, target, k) of each set in the file's order, k counting the sets of that pair
    (a file may hold one pair twice)."""
    seen, out = {}, []
    for t in targets:
        pair = (t["source"], t["target"])
        seen[pair] = seen.get(pair, 0) + 1
        out.append(pair + (seen[pair],))
    return out


def _counts(path, keys: list[tuple], res: dict) -> dict:
    """{key: (confirmations, falls)}: check_secondary returns one row per set, in the file's
    order, keyed by name (a third set of one target would take the second's name)."""
    if len(keys) != len(res):
        raise SystemExit(f"cpgbiped: error: {path}: a target appears more than twice")
    return {k: (r["random_states"]["confirmed"], r["random_states"]["falls"])
            for k, r in zip(keys, res.values())}


def _fmt(v: tuple[int, int] | None) -> str:
    return "  -" if v is None else f"{v[0]:3d} confirmed, {v[1]:2d} falls"


def main(argv=None) -> int:
    from cpgbiped.envs.experiments.secondary_check import (MAX_STATES, check_secondary,
                                                           load_secondary)

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="secondary results file A (ties go to it)")
    ap.add_argument("b", help="secondary results file B")
    ap.add_argument("--first", type=int, required=True, help="first random CPG state's seed")
    ap.add_argument("--n", type=int, default=30, help="number of random CPG states")
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-extra-falls", type=int, default=None,
                    help="B's set needs more confirmations and at most this many falls above "
                         "A's (default: no bound on its falls)")
    ap.add_argument("--by", choices=("confirmed", "net"), default="confirmed",
                    help="per target, keep the set with more confirmations (default) or more "
                         "confirmations net of falls (the product's selection criterion)")
    ap.add_argument("--out", required=True, help="the merged file")
    args = ap.parse_args(argv)
    last = args.first + args.n - 1
    if args.by == "net" and args.max_extra_falls is not None:
        ap.exit(2, "cpgbiped: error: --max-extra-falls bounds --by confirmed only\n")
    if not 1 <= args.n <= MAX_STATES:
        ap.exit(2, f"cpgbiped: error: --n must be in [1, {MAX_STATES}], got {args.n}\n")
    for lo, hi in TESTS_AND_TUNING:
        if args.first <= hi and last >= lo:
            ap.exit(2, f"cpgbiped: error: seeds {args.first}-{last} overlap the tests' or the "
                       f"tuning's CPG states ({lo}-{hi})\n")
    files = {"A": Path(args.a), "B": Path(args.b)}
    raw = {k: json.loads(p.read_text()) for k, p in files.items()}
    for p in files.values():
        load_secondary(p)  # checked before any rollout
    keys = {k: _keys(raw[k]["targets"]) for k in files}
    counts = {k: _counts(p, keys[k], check_secondary(p, args.seconds, args.workers,
                                                     states=args.n, first=args.first))
              for k, p in files.items()}
    by_b = dict(zip(keys["B"], raw["B"]["targets"]))
    merged = copy.deepcopy(raw["A"])
    merged["targets"] = []
    sums = {"A": [0, 0], "B": [0, 0], "merged": [0, 0]}
    for key, t in list(zip(keys["A"], raw["A"]["targets"])) + [
            (k, None) for k in keys["B"] if k not in keys["A"]]:
        ca = counts["A"].get(key)  # None: a set B alone has
        cb = counts["B"].get(key)
        use_b = ca is None or take_b(ca, cb, args.max_extra_falls, args.by)
        chosen = copy.deepcopy(by_b[key] if use_b else t)
        c, other = (cb, ca) if use_b else (ca, cb)
        chosen["merged_from"] = {"file": str(files["B" if use_b else "A"]),
                                 "seeds": [args.first, last], "confirmed": c[0], "falls": c[1],
                                 "other_confirmed": None if other is None else other[0],
                                 "other_falls": None if other is None else other[1]}
        merged["targets"].append(chosen)
        for k, v in (("A", ca), ("B", cb), ("merged", c)):
            if v is not None:
                sums[k][0] += v[0]
                sums[k][1] += v[1]
        print(f"{key[1]:16s} from {key[0]:5s}: A {_fmt(ca)}; B {_fmt(cb)} -> {'B' if use_b else 'A'}")
    for k, (c, f) in sums.items():
        print(f"{k:6s}: {c} confirmed, {f} falls over seeds {args.first}-{last}")
    bound = "" if args.max_extra_falls is None else f" --max-extra-falls {args.max_extra_falls}"
    bound += " --by net" if args.by == "net" else ""
    merged["command"] = (f"python scripts/merge_secondary.py {args.a} {args.b} --first "
                         f"{args.first} --n {args.n}{bound} (A: {raw['A'].get('command', '?')};"
                         f" B: {raw['B'].get('command', '?')})")
    Path(args.out).write_text(json.dumps(merged, indent=1) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
