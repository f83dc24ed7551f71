"""The robustness envelope of a gait, measured as SCONE's perturbation tutorials measure it.

For one network (any kind and preset) and one feedback gain K (:mod:`cpg.feedback`; 0 open
loop), every number from the body, none from the network alone:

- **Pushes.** A horizontal impulse on the torso at a phase of the stride, forwards (+) or
  backwards (-): a constant force held for ``PUSH_S`` = 0.2 s, as in SCONE's perturbed-gait
  tutorial (Tutorial 4c: 100 N for 0.2 s on the pelvis, 20 N s on its 75 kg model; the
  issue's "about 0.27 N s/kg"). ``push_s`` sets another duration, down to one control tick
  (4 ms, ``rollout.PUSH_TICK_S``: a blow of the same impulse, the form of most of the
  controller's tuning conditions and of every envelope measured before 2026-12-04;
  ``scripts/feedback_choice.py`` scores with the held pushes since then). The stride's phase comes from the unperturbed rollout
  with the same K: phase 0 is the first left touchdown at or after ``PUSH_AFTER_S`` (simulation
  time, settling included), the stride period the median of its left touchdown intervals. The
  impulse climbs ``IMPULSE_LADDER_NS`` until the body falls within ``HOLD_S`` of the push's start;
  the envelope at that phase and direction is the largest impulse survived before the first
  fall (0 when the smallest one fells it), in N s and in N s per kg of the body.
- **Friction.** The floor's friction scaled by each of ``FRICTIONS``.
- **Random CPG states.** The network started from random initial states (``RANDOM_SEEDS``).
  Friction and CPG states: ``SECONDS`` measured after the settling window; survived, and the
  physical gait the contacts name.

These are report conditions: the pushes from the Table 3 state at 6 s and later, frictions
0.5/0.7/1.3/2.0 and CPG seeds 20-27 are disjoint from the tuning conditions of the controller's
gains (CPG seeds 1000+, frictions 0.4/0.6/0.8/1.25/1.6, blows at 4.5-6.8 s, and since
2026-12-05 and -06 this command's own held pushes at 6.3-6.8 and 12.3-12.8 s, kept apart by
their CPG states; :mod:`cpgbiped.envs.search.controller_tuning`) and
of the recommended feedback gains (``scripts/feedback_choice.py``: CPG seeds 1000+, pushes at
5.5 s).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cpgbiped.cpg.feedback import pathway
from cpgbiped.cpg.network import Network

from cpgbiped.envs.control.controller import CONTROL, ControlParams
from cpgbiped.envs.gaits.criteria import SETTLE_S
from cpgbiped.envs.gaits.gait_metrics import debounce, edges
from cpgbiped.envs.simulation.rollout import rollout

PUSH_S = 0.2  # s: how long a push's force is held (SCONE Tutorial 4c)
PUSH_PHASES = (0.0, 0.25, 0.5, 0.75)
IMPULSE_LADDER_NS = (2.5, 5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 25.0, 30.0, 40.0)
PUSH_AFTER_S = 6.0  # the push time; --push-after sets another (a settled gait's)
MAX_PUSH_AFTER_S = 120.0
HOLD_S = 5.0
FRICTIONS = (0.5, 0.7, 1.3, 2.0)
RANDOM_SEEDS = tuple(range(20, 28))
SECONDS = 20.0  # measured after settling, for the friction and CPG-state conditions


@dataclass(frozen=True)
class StridePhase:
    """Phase 0 (a left touchdown, s) and the stride period (s) of an unperturbed rollout."""

    t0_s: float
    period_s: float

    def time_at(self, phase: float) -> float:
        return self.t0_s + phase * self.period_s


def stride_phase(network: Network, K: float, after_s: float = PUSH_AFTER_S,
                 form: str | None = None, params: ControlParams = CONTROL) -> StridePhase | None:
    """Where the unperturbed gait's strides lie (None when it falls or never steps)."""
    rec = rollout(network, after_s + 6.0, params, poses=False, feedback=K, feedback_form=form)
    if rec.fell_at is not None or rec.unstable is not None:
        return None
    left = debounce(rec.contact[:, 0], rec.dt)
    td, _ = edges(rec.t, left)
    steady = td[td >= SETTLE_S]
    if len(steady) < 3:
        return None
    later = td[td >= after_s]
    if not len(later):
        return None
    return StridePhase(float(later[0]), float(np.median(np.diff(steady))))


def survives(network: Network, K: float, t_push: float, impulse: float,
             form: str | None = None, push_s: float = PUSH_S,
             params: ControlParams = CONTROL) -> bool:
    rec = rollout(network, t_push + HOLD_S, params, push=(t_push, impulse, push_s),
                  poses=False, feedback=K, feedback_form=form)
    return rec.fell_at is None and rec.unstable is None


def push_envelope(network: Network, K: float, phases=PUSH_PHASES,
                  ladder=IMPULSE_LADDER_NS, after_s: float = PUSH_AFTER_S,
                  form: str | None = None, push_s: float = PUSH_S,
                  params: ControlParams = CONTROL) -> dict:
    """{"stride": {...}, "forward": [impulse per phase], "backward": [...]} (N s survived).
    ``after_s``, ``form``: another push window and feedback form (the gain's choice);
    ``push_s``: how long each push's force is held (s); ``params``: the controller's gains
    (default the committed file's; a candidate's when a rule compares two)."""
    sp = stride_phase(network, K, after_s, form, params)
    if sp is None:
        return {"stride": None, "phases": list(phases), "forward": [0.0] * len(phases),
                "backward": [0.0] * len(phases),
                "note": "the unperturbed gait falls or does not step: no envelope"}
    out = {"stride": {"t0_s": sp.t0_s, "period_s": sp.period_s}, "phases": list(phases),
           "push_s": float(push_s)}
    for name, sign in (("forward", 1.0), ("backward", -1.0)):
        row = []
        for ph in phases:
            best = 0.0
            for imp in ladder:
                if not survives(network, K, sp.time_at(ph), sign * imp, form, push_s, params):
                    break
                best = float(imp)
            row.append(best)
        out[name] = row
    return out


def condition_survival(network: Network, gait: str | None, K: float,
                       form: str | None = None) -> dict:
    """Friction scales and random initial CPG states: survived and the physical gait (``form``:
    the Morris-Lecar feedback pathway, None the recommended one)."""
    from cpgbiped.envs.gaits.validate import validate

    rows = []
    for f in FRICTIONS:
        s = validate(network, gait, SECONDS, friction_scale=f, feedback=K,
                     feedback_form=form).summary()
        rows.append({"condition": f"friction x{f:g}", "fell": bool(s["fell"]),
                     "physical_gait": s["physical_gait"], "speed_mps": s["speed_mps"]})
    for seed in RANDOM_SEEDS:
        net = network.with_state(network.random_state(seed))
        s = validate(net, gait, SECONDS, feedback=K, feedback_form=form).summary()
        rows.append({"condition": f"CPG seed {seed}", "fell": bool(s["fell"]),
                     "physical_gait": s["physical_gait"], "speed_mps": s["speed_mps"]})
    return {"conditions": rows, "survived": sum(not r["fell"] for r in rows),
            "named": sum((not r["fell"]) and r["physical_gait"] == gait for r in rows),
            "total": len(rows)}


def robustness(network: Network, gait: str | None, gains=(0.0,), mass_kg: float | None = None,
               push_s: float = PUSH_S, after_s: float = PUSH_AFTER_S,
               form: str | None = None) -> dict:
    """The envelope and the condition survival for each feedback gain in ``gains``; each push's
    force held for ``push_s`` seconds, the pushes' stride from the first left touchdown at or
    after ``after_s`` (s of simulation, settling included); ``form`` the Morris-Lecar feedback
    pathway of the gains above 0 (None: the recommended one)."""
    if mass_kg is None:
        from cpgbiped.envs.simulation.biped import body_constants

        mass_kg = body_constants()[1]
    res = {"network": network.kind, "preset": network.preset, "gait": gait,
           "mass_kg": mass_kg, "hold_s": HOLD_S, "push_s": float(push_s),
           "push_after_s": float(after_s),
           "ladder_ns": list(IMPULSE_LADDER_NS),
           # the pathway of the gains above 0 (None when only open loop was asked)
           "feedback_form": pathway(network.kind, form) if any(gains) else None,
           "by_gain": []}
    for K in gains:
        f = form if K else None  # open loop, no pathway is used
        env = push_envelope(network, K, push_s=push_s, after_s=after_s, form=f)
        for name in ("forward", "backward"):
            env[f"{name}_min_ns"] = float(min(env[name]))
            env[f"{name}_min_ns_per_kg"] = float(min(env[name])) / mass_kg
        res["by_gain"].append({"feedback_gain": float(K), "push": env,
                               **condition_survival(network, gait, K, f)})
    return res


def table(res: dict) -> str:
    from cpgbiped.cpg.io import format_table

    rows = []
    for g in res["by_gain"]:
        p = g["push"]
        f = lambda xs: " ".join(f"{x:g}" for x in xs)  # noqa: E731
        rows.append([f"{g['feedback_gain']:g}", f(p["forward"]), f(p["backward"]),
                     f"{p['forward_min_ns']:g} ({p['forward_min_ns_per_kg']:.2f})",
                     f"{p['backward_min_ns']:g} ({p['backward_min_ns_per_kg']:.2f})",
                     f"{g['survived']}/{g['total']}", f"{g['named']}/{g['total']}"])
    phases = " ".join(f"{x:g}" for x in PUSH_PHASES)
    return format_table(rows, ["K", f"fwd N s @ {phases}", f"back N s @ {phases}",
                               "fwd min N s (/kg)", "back min N s (/kg)", "conditions survived",
                               "named"])


def envelope_picture(res: dict, path) -> None:
    """Impulse survived against the phase of the push, forwards above and backwards below,
    one line per gain."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cpgbiped.cpg.io import atomic_path

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for g, color in zip(res["by_gain"], ("0.3", "tab:red", "tab:blue", "tab:green")):
        p = g["push"]
        ph = np.array(p["phases"])
        lab = ("open loop (K = 0)" if g["feedback_gain"] == 0 else
               f"feedback K = {g['feedback_gain']:g}"
               + (f" ({res['feedback_form']})" if res.get("feedback_form") else ""))
        ax.plot(ph, p["forward"], "o-", color=color, label=lab)
        ax.plot(ph, -np.array(p["backward"]), "s--", color=color)
    ax.axhline(0, color="k", lw=0.6)
    m = res["mass_kg"]
    ax.set_xlabel("phase of the push in the stride (0: left touchdown)")
    ax.set_ylabel("impulse survived, N s (+ forwards, - backwards)")
    sec = ax.secondary_yaxis("right", functions=(lambda x: x / m, lambda x: x * m))
    sec.set_ylabel("N s / kg")
    ax.set_title(f"{res['network']} {res['preset']}: push envelope (force held "
                 f"{res['push_s']:g} s; fall within {res['hold_s']:g} s)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
