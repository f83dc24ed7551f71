"""The body at fixed drives between two presets: what a drive sweep passes through, held.

The network's parameters sit at p_a + d (p_b - p_a) from the start (the sweep's drive d held,
``cpgbiped sweep`` ramps it), the body is validated for 20 s after settling as ``cpgbiped
validate`` does, and each drive prints the physical gait, the speed, the body's stride period
and length, and the network's own cycle (``cpg_period_s`` of the sweep's windows: upcrossings of
the left extensor's activation through the stance command, read from the CPG's signals):

    python scripts/fixed_drive.py walk run [--network ml|hopf] [--drives 0,0.2,...] [--seed S ...]
                                  [--feedback K] [--set CORNER.GAIN=VALUE ...]
                                  [--copy FROM=TO]

--seed: random CPG states (default: the Table 3 state); several seeds print one row each.
--set: the committed gains with gains changed, named as the tuning chain's hand-set links name
them (envs.search.controller_tuning.hand_values: ``alternating.theta0=0.1``, a corner's;
``startup.alternating.theta0=0.1``, a start-up corner's; ``ankle_gain=0.35``, a shared one): a
probe, never written anywhere. --copy alternating=alternating_coactive: every gain of corner TO
(and of its start-up corner) set to corner FROM's, before --set. Session 45 measured with it why
the walk slows as the sweep's drive rises (docs/RESULTS.md, "Why the walk slows as the drive rises").
"""
import argparse
from concurrent.futures import ProcessPoolExecutor

SECONDS = 20.0


def one(job):
    kind, a, b, d, seed, K, params = job
    import numpy as np

    from cpgbiped.cpg.integrate import Schedule
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.experiments.sweep import cycle_period
    from cpgbiped.envs.gaits.validate import validate

    v = validate(build(kind, a, seed=seed), None, SECONDS, to=build(kind, b),
                 change=Schedule((0.0,), (d,)), params=params, feedback=K)
    s, rec = v.summary(), v.recording
    T_cpg = cycle_period(rec.t, rec.drive[:, 2], s["settle_s"], float(rec.t[-1]))
    return (d, seed, s["physical_gait"], s["fell_at_s"], s["speed_mps"], s["stride_period_s"],
            s["stride_length_m"], T_cpg, float(np.mean(list(s["duty_factor"].values()))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--network", default="ml", choices=("ml", "hopf"))
    ap.add_argument("--drives", default="0,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1")
    ap.add_argument("--seed", type=int, nargs="*", default=[None])
    ap.add_argument("--feedback", type=float, default=0.0, metavar="K")
    ap.add_argument("--set", nargs="*", default=[], metavar="CORNER.GAIN=VALUE")
    ap.add_argument("--copy", default=None, metavar="FROM=TO")
    args = ap.parse_args()
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.cpg.network import PRESETS
    from cpgbiped.envs.control import control_kernel as kernel
    from cpgbiped.envs.control.controller import CONTROL
    from cpgbiped.envs.search.controller_tuning import hand_values

    for p in (args.a, args.b):
        if p not in PRESETS[args.network]:
            ap.error(f"unknown {args.network} preset {p!r}: use {', '.join(PRESETS[args.network])}")
    try:
        drives = [float(x) for x in args.drives.split(",")]
    except ValueError:
        ap.error(f"--drives: comma-separated numbers, got {args.drives!r}")
    if not all(0.0 <= d <= 1.0 for d in drives):
        ap.error(f"--drives must lie in [0, 1], got {args.drives!r}")
    if not args.seed:
        ap.error("--seed needs at least one CPG seed (leave it out for the Table 3 state)")
    values = {}
    copy = tuple(args.copy.split("=")) if args.copy else None
    if copy:
        if len(copy) != 2 or any(c not in kernel.CORNERS for c in copy):
            ap.error(f"--copy FROM=TO, both corners of {', '.join(kernel.CORNERS)}")
        src, dst = copy
        for g in kernel.BLENDED:
            values[f"{dst}.{g}"] = getattr(CONTROL.corner(src), g)
            values[f"startup.{dst}.{g}"] = getattr(CONTROL.startup[kernel.CORNERS.index(src)], g)
    for kv in args.set:
        key, _, value = kv.partition("=")
        try:
            values[key] = float(value)
        except ValueError:
            ap.error(f"--set {kv!r}: a gain's name = a number")
    try:
        params = hand_values(CONTROL, values)
    except InputError as e:
        ap.error(str(e))
    if args.network != "ml" and args.feedback:
        ap.error("the closed loop through a parameter change is the Morris-Lecar network's")
    jobs = [(args.network, args.a, args.b, d, s, args.feedback, params)
            for d in drives for s in args.seed]
    with ProcessPoolExecutor(2) as ex:
        rows = list(ex.map(one, jobs))
    print(f"{args.network} {args.a} -> {args.b}, fixed drives, {SECONDS:g} s after settling, K = {args.feedback:g}"
          + (f", {' '.join(args.set)}" if args.set else "")
          + (f", corner {copy[1]} := {copy[0]}" if copy else ""))
    print("   d  seed  physical  fell   speed m/s  stride s  stride m  CPG cycle s  duty")
    for d, seed, gait, fell, v, T, L, Tc, duty in rows:
        f = "-" if fell is None else f"{fell:.1f}"
        print(f"{d:4.2f}  {str(seed):>4s}  {gait:8s}  {f:>5s}  {v:9.2f}  {T:8.3f}  {L:8.2f}  "
              f"{'-' if Tc is None else f'{Tc:.3f}':>11s}  {duty:4.2f}")


if __name__ == "__main__":
    main()
