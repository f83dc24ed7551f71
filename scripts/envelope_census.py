"""The push envelope (``cpgbiped robustness``'s pushes) of a baseline and a candidate gains file,
counted over random initial CPG states that no tuning used: the envelope measurement of an
adoption rule (session 42).

    python scripts/envelope_census.py CANDIDATE.json --first 5940 --n 20 [--gaits walk,run]
                                      [--baseline GAINS.json] [--open-loop] [--json OUT]

For each gait's Morris-Lecar preset (Table 2 weights) started from each CPG seed of
[--first, --first + n), :func:`cpgbiped.envs.experiments.robustness.push_envelope`: pushes held
0.2 s at the four phases of the stride after 6 s, forwards and backwards, the impulse climbing
2.5 ... 40 N s until a fall within 5 s (the envelope: the largest impulse survived below the
first fall); with the network's recommended feedback
(cpg/feedback_gains.json: its pathway and gain), and open loop as well with --open-loop.
Printed per gait, gains and loop: the envelope's minimum over the phases in each direction,
summed over the states, and the number of states whose minimum reaches issue 21's bar,
0.5 N s/kg of the body's mass (10.5 N s on the 21 kg body; the impulse ladder's 10 N s falls
short of it, 12.5 N s reaches it). The two gains files' rollouts run in the same process pool.
Seed banks: scripts/rule_rates.py lists the used ones and refuses the tests' and the
tuning's states (its checks, shared).
"""
import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from rule_rates import check_bank, check_gains_files  # noqa: E402

BAR_NS_PER_KG = 0.5  # issue 21's bar
GAITS = ("walk", "run", "jump", "hop")


def one(job):
    gait, seed, gains, loop = job
    return job, envelope(gait, seed, gains, loop)


def envelope(gait, seed, gains, loop):
    from cpgbiped.cpg.feedback import CHOICE
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import CONTROL, read_gains
    from cpgbiped.envs.experiments.robustness import push_envelope

    params = read_gains(gains)[0] if gains else CONTROL
    form, K = (None, 0.0) if loop == "open" else CHOICE["ml"]  # the recommended pathway, gain
    env = push_envelope(build("ml", gait, seed=seed), K, form=form, params=params)
    return {"forward": env["forward"], "backward": env["backward"]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("candidate")
    ap.add_argument("--baseline", default=None, help="default: the committed gains")
    ap.add_argument("--first", type=int, required=True)
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--gaits", default="walk,run")
    ap.add_argument("--open-loop", action="store_true", help="also measure open loop (K = 0)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    if a.n < 1 or a.workers < 1:
        ap.error("--n and --workers must be positive")
    seeds = range(a.first, a.first + a.n)
    gaits = a.gaits.split(",")
    if not gaits or any(g not in GAITS for g in gaits):
        ap.error(f"--gaits must name some of {', '.join(GAITS)}, got {a.gaits!r}")
    check_bank(ap, a.first, a.n)
    check_gains_files(ap, *(f for f in (a.baseline, a.candidate) if f is not None))
    from cpgbiped.envs.simulation.biped import body_constants

    bar_ns = BAR_NS_PER_KG * body_constants()[1]
    loops = ["feedback"] + (["open"] if a.open_loop else [])
    files = {"baseline": a.baseline, "candidate": a.candidate}
    jobs = [(g, s, f, loop) for g in gaits for loop in loops for s in seeds
            for f in (a.baseline, a.candidate)]
    with ProcessPoolExecutor(a.workers) as pool:
        got = {job: env for job, env in pool.map(one, jobs)}
    out = {"first": a.first, "n": a.n, "bar_ns": bar_ns, "rows": []}
    print(f"{'gait':5} {'loop':8} {'gains':9} {'fwd min sum':>11} {'back min sum':>12} "
          f"{'fwd at bar':>10} {'back at bar':>11}   (bar {bar_ns:g} N s)")
    for g in gaits:
        for loop in loops:
            for name, f in files.items():
                envs = [got[(g, s, f, loop)] for s in seeds]
                fmin = [min(e["forward"]) for e in envs]
                bmin = [min(e["backward"]) for e in envs]
                row = {"gait": g, "loop": loop, "gains": name, "file": f,
                       "forward_min_sum": sum(fmin), "backward_min_sum": sum(bmin),
                       "forward_at_bar": sum(x >= bar_ns for x in fmin),
                       "backward_at_bar": sum(x >= bar_ns for x in bmin),
                       "per_state": {str(s): e for s, e in zip(seeds, envs)}}
                out["rows"].append(row)
                print(f"{g:5} {loop:8} {name:9} {row['forward_min_sum']:11g} "
                      f"{row['backward_min_sum']:12g} {row['forward_at_bar']:10d} "
                      f"{row['backward_at_bar']:11d}")
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
