"""Gait transitions in physics: the network's parameters change in mid-run and the body follows.

The network starts as preset A (its Table 3 state, or a random one drawn from a CPG seed) and,
at ``at_s`` (simulation time from the start, settling included), its parameters move to preset
B's: a step (ramp 0) or a linear ramp over ``ramp_s`` seconds (:class:`cpg.integrate.Schedule`). The CPG's state carries across the
change; nothing is reset, and the controller is not told (it never sees a name).

Windows, all measured from the foot contacts (:func:`cpgbiped.envs.gaits.validate.measure_recording`):
- **before**: the last ``BEFORE_CYCLES`` whole CPG cycles of A before the change (fewer,
  ``before_cycles``, when the change comes sooner after the settling): the gait the body is
  in when the change comes, over whole cycles ending at the change, because a duty factor
  over part of a stride is biased by the part. It holds less of the body's start-up than the
  stretch from the settling (the start-up gains hand over with a time constant of 1.5 s;
  at 2.67 s, where the walk's 5 cycles before an 8 s change begin, 17% of them remain).
  ``before_from_settling``: the whole stretch from the end of the settling window to the
  change (what ``before`` was until 2026-12-03);
- **sliding**: ``WINDOW_CYCLES`` CPG cycles of B starting 0, 1, 2, ... cycles after the change
  began, while such a window fits in the rollout;
- **after**: from the first sliding window from which every later one names the same physical
  gait (the gait has settled) to the end. ``cycles_to_switch``: the CPG cycles (of B) from the
  change to the start of that window when the settled gait is B; None when B never settles.

With the closed loop (``feedback`` K > 0; Morris-Lecar) the network is stepped with the body
through the change.

``cpg_extensor_synchrony``: what the network itself does after the change, read from its
activations, never from the body: for each of the first ``SYNC_CYCLES`` CPG cycles of B from
the change, the share of the time in which either leg's extensor activation is at least
``E_ON`` (the controller's stance command) during which both are: 0 when the legs' bursts
alternate (a walk's or a run's network), 1 when they are in phase (a jump's or a hop's). A
body cannot walk within a few cycles of a change while its network drives both legs' stances
together.

``network_alone``: the same change of the same network from the same state, integrated open
loop without a body, named by the CPG classifier over windows of NETWORK_WINDOW_CYCLES CPG
cycles of B that start 0, 1, ... cycles after the change (``cpg.gaits.named_windows``);
``cycles_to_switch`` there is the first window from which every later one names B (None: not
within NETWORK_WINDOWS). When it is above 4, no body driven open loop can pass issue 22's test
(docs/RESULTS.md, "What the network alone allows"); with feedback it is the reference the coupled
system is compared with.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.gaits import named_windows, settled_at
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import PRESETS, build

from cpgbiped.envs.control.controller import CONTROL, ControlParams
from cpgbiped.envs.gaits.criteria import SETTLE_S
from cpgbiped.envs.simulation.rollout import check_seconds, rollout, window
from cpgbiped.envs.gaits.validate import measure_recording

WINDOW_CYCLES = 3  # CPG cycles of the target per sliding window
AFTER_S = 12.0  # s of rollout after the change ends by default, within a family (walk <-> run,
# jump <-> hop)
CROSS_AFTER_S = 30.0  # ... across the families: the network alone takes 100-300 model units
# (8-24 s at 12.3 units/s) to lock to a new pattern (issue 22), and the windows need 3 cycles
IN_FAMILY = frozenset({("walk", "run"), ("run", "walk"), ("jump", "hop"), ("hop", "jump")})
BEFORE_CYCLES = 5  # whole CPG cycles of A before the change (the CPG classifier needs 3 whole
# cycles between its reference's upcrossings; 4 left the jump's unnamed)
SYNC_CYCLES = 8  # CPG cycles of the target after the change with an extensor synchrony
E_ON = CONTROL.e_on  # extensor activation of the controller's stance command
NETWORK_WINDOW_CYCLES = 4  # the CPG classifier needs 3 whole cycles between upcrossings
NETWORK_WINDOWS = 14  # windows of the network alone after the change
KEYS = ("physical_gait", "cpg_gait", "fell", "duty_factor", "lr_phase_lag", "double_support",
        "flight", "stride_period_s", "speed_mps", "froude", "apex_height_m")


def default_seconds(a: str, b: str, at_s: float, ramp_s: float) -> float:
    """The rollout's default length: the change's end plus AFTER_S within a family, plus
    CROSS_AFTER_S across the families."""
    return at_s + ramp_s + (AFTER_S if (a, b) in IN_FAMILY else CROSS_AFTER_S)


def check_transition(kind: str, a: str, b: str, at_s: float, ramp_s: float, seconds: float):
    if kind not in PRESETS:
        raise InputError(f"unknown network {kind!r}: use ml or hopf")
    if kind == "matsuoka":
        raise InputError("the Matsuoka network has one preset: it has no transition")
    for name, g in (("--from", a), ("--to", b)):
        if g not in PRESETS[kind]:
            raise InputError(f"{name}: unknown {kind} gait {g!r}: use {', '.join(PRESETS[kind])}")
    seconds = check_seconds(seconds)
    if not (np.isfinite(ramp_s) and ramp_s >= 0):
        raise InputError(f"--ramp must be a number of seconds >= 0, got {ramp_s}")
    if not (np.isfinite(at_s) and SETTLE_S < at_s and at_s + ramp_s < seconds):
        raise InputError(f"--at {at_s:g} s (plus the ramp {ramp_s:g} s) lies outside the rollout: "
                         f"the change must come after the {SETTLE_S:g} s settling and end "
                         f"before {seconds:g} s")
    return seconds


CONTEXT_S = 2.0  # s of the recording before a window kept for the contacts' debouncing


def window_summary(net, rec, t0, t1, fell_at):
    """Summary of [t0, t1] with the fall counted only when it lies inside. Measured on the
    recording cut to [t0 - CONTEXT_S, t1], so that each window costs its own length, not the
    length of the rollout before it."""
    inside = fell_at is not None and fell_at <= (np.inf if t1 is None else t1)  # fell by its end
    to_end = t1 is None or t1 >= rec.t[-1]  # an unstable rollout counts as fallen at its end
    r = replace(window(rec, t0 - CONTEXT_S, t1), fell_at=fell_at if inside else None,
                unstable=rec.unstable if to_end else None)
    s = measure_recording(net, None, r, t0, t_end=t1).summary()
    return {k: s.get(k) for k in KEYS} | {"start_s": float(t0),
                                          "end_s": float(rec.t[-1] if t1 is None else t1)}


def before_cycles(at_s: float, period_s: float) -> int:
    """Whole CPG cycles of A in the window before a change at ``at_s``: BEFORE_CYCLES, or as
    many as fit between the end of the settling and the change (0: the window is the part of
    a cycle there is)."""
    return int(min(BEFORE_CYCLES, np.floor((at_s - SETTLE_S) / period_s + 1e-9)))


def extensor_synchrony(t_s, activation, at_s: float, period_s: float,
                       n: int = SYNC_CYCLES) -> list:
    """Per cycle k = 0..n-1 of [at_s + k T, at_s + (k + 1) T]: time with both extensors (cells
    LE, RE: columns 2, 3 of ``activation``) at or above E_ON over time with either; None for a
    cycle outside the recording or without any extensor burst."""
    on = np.asarray(activation)[:, 2:4] >= E_ON
    out = []
    for k in range(n):
        w = (t_s >= at_s + k * period_s) & (t_s < at_s + (k + 1) * period_s)
        either = int((on[w, 0] | on[w, 1]).sum())
        if t_s[-1] < at_s + (k + 1) * period_s - 1e-9 or either == 0:
            out.append(None)
        else:
            out.append(float((on[w, 0] & on[w, 1]).sum() / either))
    return out


def network_alone(kind: str, a: str, b: str, at_s: float, ramp_s: float,
                  seed: int | None = None) -> dict:
    """The change without a body (see the module docstring): {"windows": the CPG classifier's
    name per window, "cycles_to_switch": first window from which all later name B, or None}."""
    net, to = build(kind, a, seed=seed), build(kind, b)
    u, T = net.units_per_s, to.period()
    at = at_s * u
    out = net.outputs(at + (NETWORK_WINDOWS + NETWORK_WINDOW_CYCLES + 1) * T, to=to,
                      schedule=Schedule.change(at, ramp_s * u))
    names = named_windows(out.t_model, out.v, at, T, NETWORK_WINDOW_CYCLES, NETWORK_WINDOWS)
    return {"windows": names, "cycles_to_switch": settled_at(names, b)}


def transition(kind: str, a: str, b: str, at_s: float = 8.0, ramp_s: float = 0.0,
               seconds: float = 20.0, feedback: float = 0.0, poses: bool = False,
               seed: int | None = None, params: ControlParams = CONTROL,
               feedback_form: str | None = None):
    """(result dict, recording, the network A, the network B). ``seed``: A starts from the
    random initial CPG state drawn from this seed (None: its Table 3 state); B lends only its
    parameters, so its state is never used. ``params``: the controller's parameters (default
    the committed gains; a candidate's, to measure it as the committed ones are).
    ``feedback_form``: the Morris-Lecar pathway (cpg.feedback.ML_FORMS; None: the recommended
    one), e.g. the tuning conditions' frozen pathway."""
    seconds = check_transition(kind, a, b, at_s, ramp_s, seconds)
    net, to = build(kind, a, seed=seed), build(kind, b)
    rec = rollout(net, seconds, params, to=to, change=Schedule.change(at_s, ramp_s),
                  poses=poses, stop_on_fall=False, feedback=feedback,
                  feedback_form=feedback_form)
    fell_at = rec.fell_at
    T = to.period_s()
    n_before = before_cycles(at_s, net.period_s())
    from_settling = window_summary(net, rec, SETTLE_S, at_s, fell_at)
    before = (window_summary(net, rec, at_s - n_before * net.period_s(), at_s, fell_at)
              if n_before else from_settling)
    slides = []
    k = 0
    while at_s + (k + WINDOW_CYCLES) * T <= rec.t[-1] + 1e-9:
        t0 = at_s + k * T
        slides.append(window_summary(to, rec, t0, t0 + WINDOW_CYCLES * T, fell_at))
        k += 1
    names = [w["physical_gait"] for w in slides]
    settled = settled_at(names, names[-1]) if names else None  # whatever gait it settles in
    start = at_s + (settled if settled is not None else len(slides)) * T
    after = window_summary(to, rec, min(start, float(rec.t[-1]) - T), None, fell_at)
    res = {"network": kind, "from": a, "to": b, "cpg_seed": seed, "at_s": float(at_s),
           "ramp_s": float(ramp_s),
           "seconds": seconds, "feedback_gain": rec.feedback_gain, "cpg_period_to_s": T,
           "before": before, "before_cycles": n_before,
           "before_from_settling": from_settling, "after": after,
           "fell": fell_at is not None,
           "fell_at_s": fell_at,
           "settled_after_cycles": settled,
           "cycles_to_switch": (settled if settled is not None and names[settled] == b
                                and fell_at is None else None),
           "windows": [{"start_s": w["start_s"], "physical_gait": w["physical_gait"]}
                       for w in slides],
           "cpg_extensor_synchrony": extensor_synchrony(rec.t, rec.drive, at_s, T),
           "network_alone": network_alone(kind, a, b, at_s, ramp_s, seed)}
    res["switched"] = bool(res["cycles_to_switch"] is not None
                           and before["physical_gait"] == a and not res["fell"])
    return res, rec, net, to
