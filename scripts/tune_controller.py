"""Tune the balance/pattern-formation gains of one gait's controller with pymoo's GA.

The CPG (rhythm, leg timing) stays the paper's Table 2 network; only the controller gains in
``envs.controller.ControlParams`` are searched. Fitness (minimised) follows the acceptance
criteria of the physical gaits (envs.gait_metrics): a fall costs 100 minus the seconds
survived; otherwise the shortfalls from the gait's targets (left-right lag, duty factor,
double support, flight, forward distance) are summed, plus the relative difference between
the stride period and the CPG period / time scale (one stride per CPG cycle: the rhythm must
be the CPG's, not a bounce of the body) and the excess of footfalls per stride over 1 +- 0.08
per foot and the fraction of touchdown intervals shorter than 0.6 stride (a regular gait, no
stutter). Conditions may include other weights (``weights:w_a/w_b/w_c``), with the time scale
rescaled as validate does. Prints the best gains as Python.

    python scripts/tune_controller.py walk [--pop 24] [--gens 15] [--seconds 12]

Without ``--start`` the first population is random over the ranges below; refining a preset
(``--start``) stays in its basin. The present run came from a random population:

    python scripts/tune_controller.py run --pop 60 --gens 50 --seed 11 --min-speed 0.9 \
        --conditions table3,seed:10,seed:11,friction:0.7
"""
from __future__ import annotations

import argparse
import functools
from concurrent.futures import ProcessPoolExecutor

import numpy as np

# Search ranges of the gains, for the alternating (walk, run) and two-legged (jump, hop) patterns.
SPACES = {
    "alternating": dict(
        ankle_gain=(0.03, 1.0), push=(0.0, 1.0), theta0=(0.05, 0.6), c_v=(0.0, 0.4),
        c_d=(0.0, 0.8), kp_t=(1.0, 6.0), kd_t=(0.1, 0.8), knee_swing=(-1.4, -0.3),
        time_scale=(7.0, 16.0), pitch_d=(-0.05, 0.2), kp_sw=(0.5, 4.0), kp_knee=(0.5, 4.0),
        swing_margin=(-0.4, 0.9), knee_stance=(-0.9, -0.02)),
    "two_legged": dict(
        knee_crouch=(-1.0, -0.1), kp_crouch=(0.3, 4.0), knee_stance=(-0.3, 0.0), push=(0.0, 1.0),
        kp_knee=(0.5, 5.0), knee_swing=(-0.8, -0.05), kp_land=(0.3, 4.0), theta0=(-0.2, 0.3),
        c_v=(0.0, 0.5), c_d=(0.0, 1.0), kp_sw=(0.1, 3.0), kd_sw=(0.02, 0.4), kp_t=(0.5, 6.0), kd_t=(0.05, 0.8),
        pitch_d=(-0.1, 0.3), ankle_gain=(0.0, 1.0), k_ax=(0.0, 40.0), k_av=(0.0, 10.0),
        time_scale=(6.0, 30.0), kf_t=(-1.0, 1.0), contact_hold=(0.0, 0.06)),
}


def space(gait: str) -> dict:
    from envs.controller import GAIT_CONTROL

    return SPACES["two_legged" if GAIT_CONTROL[gait].two_legged else "alternating"]


@functools.cache
def cpg_period(gait: str, weights=None) -> float:
    """The CPG period (model units) of the gait's network, Table 2 or other weights, from the
    network alone (cached per process)."""
    from envs.validate import cpg_period as period

    return period(gait, weights)


def period_ratio(gait: str, weights) -> float:
    return cpg_period(gait, weights) / cpg_period(gait)


# Forward speed (m/s) below which the distance term costs, per gait (--min-speed overrides).
MIN_SPEED = {"walk": 0.25, "run": 0.35, "jump": 0.0, "hop": 0.0}


def cost(gait: str, m, seconds: float, time_scale: float, weights=None,
         min_speed: float | None = None) -> float:
    v_min = MIN_SPEED[gait] if min_speed is None else min_speed
    if m.fell:
        return 100.0 - (m.fell_at_s or 0.0)
    # The rhythm must be the CPG's: one stride per CPG cycle.
    expected = cpg_period(gait, weights) / time_scale
    rhythm = 4 * abs(m.stride_period_s - expected) / expected if np.isfinite(m.stride_period_s) else 4
    duty = np.array([m.duty_factor["left"], m.duty_factor["right"]])
    lag = m.lr_phase_lag if np.isfinite(m.lr_phase_lag) else 0.25
    sync = min(lag, 1 - lag)
    d = m.distance_m
    if gait == "walk":
        c = 4 * abs(lag - 0.5) + 4 * np.maximum(0, 0.58 - duty).sum() + \
            4 * max(0, 0.07 - m.double_support) + 8 * m.flight + max(0, v_min * seconds - d)
    elif gait == "run":
        c = 4 * abs(lag - 0.5) + 4 * np.maximum(0, duty - 0.45).sum() + \
            4 * max(0, 0.14 - m.flight) + max(0, v_min * seconds - d)
    elif gait == "jump":
        c = 4 * sync + 4 * max(0, 0.14 - m.flight) + 4 * max(0, 0.5 - duty.mean()) + \
            max(0, v_min * seconds - d) * 0.2
    else:
        c = 4 * sync + 4 * max(0, 0.2 - m.flight) + 4 * max(0, duty.mean() - 0.40) + \
            max(0, v_min * seconds - d) * 0.2
    # One touchdown per foot per stride (a stuttering foot is not a clean gait).
    ff = np.array([m.footfalls_per_stride["left"], m.footfalls_per_stride["right"]])
    regular = 4 * np.maximum(0, np.abs(np.nan_to_num(ff, nan=2.0) - 1) - 0.08).sum()
    # ... and no stutter: touchdown intervals shorter than 0.6 stride are extra footfalls.
    if np.isfinite(m.stride_period_s):
        for td in m.touchdowns.values():
            d = np.diff(td)
            regular += 4 * float(np.mean(d < 0.6 * m.stride_period_s)) if len(d) else 0.0
    return float(c + rhythm + regular + (0 if m.physical_gait == gait else 4.0))


def parse_conditions(text: str) -> list[dict]:
    """"table3,seed:11,friction:0.7,weights:0.1/-0.2/0.3" -> rollout keyword sets."""
    out = []
    for item in text.split(","):
        if item == "table3":
            out.append({})
        elif item.startswith("seed:"):
            out.append({"seed": int(item[5:])})
        elif item.startswith("friction:"):
            out.append({"friction_scale": float(item[9:])})
        elif item.startswith("weights:"):  # weights:w_a/w_b/w_c, e.g. an optimiser result
            out.append({"weights": tuple(float(w) for w in item[8:].split("/"))})
        else:
            raise SystemExit(f"unknown condition {item!r}")
    return out


def evaluate(args):
    """Mean cost over the conditions (each a rollout of ``seconds``)."""
    gait, x, seconds, conditions, min_speed = args
    keys = list(space(gait))
    from envs.biped import rollout
    from dataclasses import replace

    from envs.controller import GAIT_CONTROL, preset_network
    from envs.gait_metrics import measure

    p = replace(GAIT_CONTROL[gait], **dict(zip(keys, map(float, x))))
    costs = []
    for kw in conditions:
        kw, net, q = dict(kw), preset_network(gait), p
        w = kw.pop("weights", None)
        if w is not None:  # as validate does: other weights keep the stride (time scale rescaled)
            from envs.validate import network_for

            net = network_for(gait, w)
            q = replace(p, time_scale=p.time_scale * period_ratio(gait, w))
        r = rollout(net, q, seconds, **kw)
        costs.append(cost(gait, measure(r.t, r.contact, r.com_x, r.fell_at, settle_s=2.0), seconds,
                          q.time_scale, w, min_speed))
    return float(np.mean(costs))


def main(argv=None):
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    ap = argparse.ArgumentParser()
    ap.add_argument("gait")
    ap.add_argument("--pop", type=int, default=24)
    ap.add_argument("--gens", type=int, default=15)
    ap.add_argument("--seconds", type=float, default=12.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--conditions", default="table3",
                    help="comma list of table3, seed:N, friction:F; fitness = mean cost")
    ap.add_argument("--min-speed", type=float, default=None,
                    help="forward speed (m/s) the distance term asks for (default per gait: "
                         + ", ".join(f"{g} {v:g}" for g, v in MIN_SPEED.items()) + ")")
    ap.add_argument("--start", action="store_true",
                    help="seed the first population with the gait's current preset")
    a = ap.parse_args(argv)
    conds = parse_conditions(a.conditions)
    sp = space(a.gait)
    keys = list(sp)
    lo = np.array([sp[k][0] for k in keys])
    hi = np.array([sp[k][1] for k in keys])
    pool = ProcessPoolExecutor(2)

    class Tune(Problem):
        def __init__(self):
            super().__init__(n_var=len(keys), n_obj=1, xl=lo, xu=hi)

        def _evaluate(self, X, out, *args, **kw):
            out["F"] = np.array(list(pool.map(evaluate, [(a.gait, x, a.seconds, conds, a.min_speed)
                                                         for x in X])))

    sampling = None
    if a.start:  # the current preset plus random points around it
        from envs.controller import GAIT_CONTROL

        x0 = np.array([getattr(GAIT_CONTROL[a.gait], k) for k in keys])
        rng = np.random.default_rng(a.seed)
        sampling = np.clip(x0 + 0.1 * (hi - lo) * rng.standard_normal((a.pop, len(keys))), lo, hi)
        sampling[0] = np.clip(x0, lo, hi)
    algo = GA(pop_size=a.pop) if sampling is None else GA(pop_size=a.pop, sampling=sampling)
    res = minimize(Tune(), algo, ("n_gen", a.gens), seed=a.seed, verbose=True)
    print("best cost", float(res.F[0]))
    print("ControlParams(" + ", ".join(f"{k}={v:.4g}" for k, v in zip(keys, res.X)) + ")")


if __name__ == "__main__":
    main()
