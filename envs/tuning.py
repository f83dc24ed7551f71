"""The fitness of the one controller's parameters, and what the tuner searches.

The blended gains have a value at each corner of the (sigma, kappa) square; each Morris-Lecar
preset's rhythm sits at one corner (walk: alternating, run: alternating and co-active, jump:
synchronous, hop: synchronous and co-active; measured, not assumed: tests/test_controller.py),
so a corner can be tuned on its preset alone, with the shared parameters and the other corners
fixed. A parameter vector is scored by rolling out the chosen presets through the controller
under each condition, and adding per rollout:
- a fall: 5 + 10 x (the fraction of the rollout not survived);
- otherwise: 4 x the criteria shortfall (:meth:`envs.criteria.Criteria.shortfall`, with a
  margin), plus the rhythm term 2 |stride - CPG period| / CPG period (one stride per CPG
  cycle: the rhythm must be the network's, not a bounce of the body), plus 4 x the excess of
  footfalls per stride over 1 +- 0.08 per foot and 4 x the fraction of touchdown intervals
  shorter than 0.6 stride (stutter), plus 1 when the contact-only classifier names another
  gait.
The cost of a condition is the sum over the presets; the fitness is the mean over the
conditions. Lower is better; 0 is every criterion met with the margin to spare.
"""
from __future__ import annotations

from dataclasses import fields, replace

import numpy as np

from cpg.network import build

from .controller import CONTROL, ControlParams, Corner
from .criteria import CRITERIA, SETTLE_S

# Search ranges of the blended gains (units as in envs.controller.Corner).
CORNER_SPACE = dict(
    k_ax=(0.0, 30.0), k_av=(0.0, 8.0), kp_t=(0.5, 6.0), kd_t=(0.05, 0.8),
    pitch_d=(-0.05, 0.3), theta0=(-0.2, 0.5), c_v=(0.0, 0.5), c_d=(0.0, 1.0),
    kp_sw=(0.3, 4.0), kd_sw=(0.02, 0.4), kf_t=(-1.0, 1.0), knee_ext=(-0.9, 0.0),
    knee_crouch=(-1.0, -0.05), knee_swing=(-1.4, -0.2), knee_land=(-0.9, 0.0),
    kp_knee=(0.3, 5.0), kp_push=(0.1, 5.0), kp_air=(0.3, 5.0), kd_knee=(0.02, 0.3),
    push=(0.0, 1.0), swing_rest=(0.0, 1.0),
)
# ... and of the shared parameters ("units_per_s": the Morris-Lecar time unit).
SHARED_SPACE = dict(ankle_gain=(0.05, 1.0), e_on=(0.3, 0.7), w_flex=(0.0, 1.5),
                    w_cross=(0.0, 1.5), contact_hold=(0.0, 0.06), units_per_s=(9.0, 18.0))
CORNER_OF = {"walk": "alternating", "run": "alternating_coactive", "jump": "synchronous",
             "hop": "synchronous_coactive"}
GAITS = tuple(CORNER_OF)
MARGIN = 0.03


def parse_conditions(text: str) -> list[dict]:
    """"table3,seed:11,friction:0.7" -> condition dicts (seed: random initial CPG state)."""
    out = []
    for item in text.split(","):
        if item == "table3":
            out.append({})
        elif item.startswith("seed:"):
            out.append({"seed": int(item[5:])})
        elif item.startswith("friction:"):
            out.append({"friction_scale": float(item[9:])})
        else:
            raise ValueError(f"unknown condition {item!r}: use table3, seed:N or friction:F")
    return out


def params_from(x: dict, base: ControlParams = CONTROL) -> tuple[ControlParams, float | None]:
    """(ControlParams, Morris-Lecar units per second or None) from searched values: keys are
    shared names, "units_per_s", or "<corner>.<gain>"."""
    shared = {f.name for f in fields(ControlParams)}
    p = replace(base, **{k: float(v) for k, v in x.items() if k in shared and "." not in k})
    for k, v in x.items():
        if "." in k:
            corner, gain = k.split(".")
            p = p.with_corner(corner, **{gain: float(v)})
    return p, (float(x["units_per_s"]) if "units_per_s" in x else None)


def space(gait: str | None) -> dict:
    """The search space: one gait's corner ("<corner>.<gain>": range), or the shared
    parameters when gait is None."""
    if gait is None:
        return dict(SHARED_SPACE)
    return {f"{CORNER_OF[gait]}.{k}": r for k, r in CORNER_SPACE.items()}


def rollout_cost(gait: str, s: dict, others: dict, total_s: float) -> float:
    """The cost of one rollout summary (see the module docstring)."""
    if s["fell"]:
        return 5.0 + 10.0 * (1.0 - (s["fell_at_s"] or 0.0) / total_s)
    c = 4.0 * CRITERIA[gait].shortfall(s, others, MARGIN)
    period, stride = s["cpg_period_s"], s["stride_period_s"]
    if period and stride is not None and np.isfinite(stride):
        c += 2.0 * abs(stride - period) / period
        for td in s["touchdowns"].values():
            d = np.diff(td)
            c += 4.0 * float(np.mean(d < 0.6 * stride)) if len(d) else 4.0
    else:
        c += 2.0
    ff = np.array([s["footfalls_per_stride"]["left"], s["footfalls_per_stride"]["right"]],
                  dtype=float)
    c += 4.0 * np.maximum(0.0, np.abs(np.nan_to_num(ff, nan=2.0) - 1.0) - 0.08).sum()
    return float(c + (0.0 if s["physical_gait"] == gait else 1.0))


def _summary(g: str, p: ControlParams, units_per_s: float | None, cond: dict,
             seconds: float) -> dict:
    from .validate import validate

    net = build("ml", g, seed=cond.get("seed"))
    if units_per_s is not None:
        net.units_per_s = units_per_s
    v = validate(net, g, seconds, params=p, friction_scale=cond.get("friction_scale", 1.0))
    s = v.summary()
    s["touchdowns"] = v.metrics.touchdowns
    return s


_REFERENCES: dict = {}


def _reference(g: str, base: ControlParams, cond: dict, seconds: float) -> dict:
    """A gait the scored ones are compared with (run farther than walk, ...), rolled out with
    the base parameters; cached per process (the base does not change during a search)."""
    key = (g, repr(base), tuple(sorted(cond.items())), seconds)
    if key not in _REFERENCES:
        _REFERENCES[key] = _summary(g, base, None, cond, seconds)
    return _REFERENCES[key]


def condition_cost(p: ControlParams, units_per_s: float | None, cond: dict, seconds: float,
                   gaits=GAITS, base: ControlParams = CONTROL) -> tuple[float, dict]:
    """Sum over the gaits of one condition; also the summaries. A gait's comparisons with a
    gait not scored here use that gait's rollout with the base parameters."""
    summaries = {g: _summary(g, p, units_per_s, cond, seconds) for g in gaits}
    others = dict(summaries)
    for g in gaits:
        c = CRITERIA[g]
        for ref in {c.farther_than, c.duty_above, c.duty_below} - {None} - set(gaits):
            others[ref] = _reference(ref, base, cond, seconds)
    total = sum(rollout_cost(g, summaries[g], others, seconds + SETTLE_S) for g in gaits)
    return total, summaries


def fitness(x: dict, conditions: list[dict], seconds: float, gaits=GAITS,
            base: ControlParams = CONTROL) -> float:
    p, units = params_from(x, base)
    return float(np.mean([condition_cost(p, units, c, seconds, gaits, base)[0]
                          for c in conditions]))
