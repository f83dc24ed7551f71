"""A drive sweep: one scalar drive d in [0, 1] moves every parameter of the network linearly from
preset A (d = 0) to preset B (d = 1), slowly up, held, then down, in one rollout.

Schedule (simulation time, settling included): d = 0 until ``START_S``, a linear ramp to 1 over
``ramp_s``, held for ``HOLD_S``, a linear ramp back to 0 over ``ramp_s``, then 0 for ``TAIL_S``.
The physical gait is named from the contacts in sliding windows of ``WINDOW_S`` every
``STEP_S``; each window carries the mean drive over it. The switch up is the first window on the
way up from which ``PERSIST`` windows in a row name B; the switch down the first window on the
way down from which ``PERSIST`` in a row do not (windows in which or after which the body
fell never count as a switch). Hysteresis: the drive at the switch up minus
the drive at the switch down (> 0: the gait holds on to B below the drive that brought it).

Each window also carries the body's stride: ``stride_period_s``, the median interval between
touchdowns of a foot (:mod:`cpgbiped.envs.gaits.gait_metrics`), and ``stride_length_m`` =
|speed| x stride period; and the network's own cycle, ``cpg_period_s``: the median interval
between upcrossings of E_ON (the controller's stance command) by the left extensor's
activation, read from the CPG's signals, never from the body: with T_cpg that median,
T_cpg = median(diff(t_k)), t_k the times at which a_LE(t) rises through E_ON. Speed = stride
length / stride period, so the picture's middle panel says which of the two a change of speed
came from, and whether the body's strides keep the network's cycle (docs/RESULTS.md, "Why the walk slows
as the drive rises").
"""
from __future__ import annotations

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import build

from cpgbiped.envs.simulation.rollout import rollout
from cpgbiped.envs.experiments.transition import E_ON, window_summary

PAIRS = {"walk-run": ("walk", "run"), "jump-hop": ("jump", "hop")}
START_S, HOLD_S, TAIL_S = 4.0, 4.0, 4.0
WINDOW_S, STEP_S = 3.0, 0.5
PERSIST = 3
G = 9.81


def schedule(ramp_s: float) -> Schedule:
    t1 = START_S + ramp_s
    t2 = t1 + HOLD_S
    return Schedule((START_S, t1, t2, t2 + ramp_s), (0.0, 1.0, 1.0, 0.0))


def check_pair(pair: str) -> tuple[str, str]:
    if pair not in PAIRS:
        raise InputError(f"unknown sweep {pair!r}: use {', '.join(PAIRS)}")
    return PAIRS[pair]


def sweep(pair: str, ramp_s: float = 40.0, kind: str = "ml", feedback: float = 0.0,
          poses: bool = False):
    """(result dict, recording)."""
    a, b = check_pair(pair)
    if not (np.isfinite(ramp_s) and 5.0 <= ramp_s <= 200.0):
        raise InputError(f"--ramp-seconds must be in [5, 200] s, got {ramp_s}")
    if kind not in ("ml", "hopf"):
        raise InputError(f"a drive sweep needs a network with presets A and B: ml or hopf, "
                         f"got {kind!r}")
    sch = schedule(ramp_s)
    total = sch.t[-1] + TAIL_S
    net, to = build(kind, a), build(kind, b)
    rec = rollout(net, total, to=to, change=sch, poses=poses, stop_on_fall=False,
                  feedback=feedback)
    from cpgbiped.envs.simulation.biped import body_constants

    leg = body_constants()[0]
    t_top = sch.t[1] + HOLD_S / 2  # the middle of the hold: up before, down after
    windows = []
    t0 = START_S - WINDOW_S
    while t0 + WINDOW_S <= rec.t[-1] + 1e-9:
        w = window_summary(net, rec, t0, t0 + WINDOW_S, rec.fell_at)
        tt = np.linspace(t0, t0 + WINDOW_S, 31)
        w["drive"] = float(sch.at(tt).mean())
        w["leg"] = "up" if t0 + WINDOW_S / 2 <= t_top else "down"
        v = w["speed_mps"]
        ok = v is not None and np.isfinite(v)
        w["froude"] = float(v * v / (G * leg)) if ok else None
        T = w["stride_period_s"]
        w["stride_period_s"] = T = float(T) if T is not None and np.isfinite(T) else None
        w["stride_length_m"] = float(abs(v) * T) if ok and T is not None else None
        w["cpg_period_s"] = cycle_period(rec.t, rec.drive[:, 2], t0, t0 + WINDOW_S)
        windows.append(w)
        t0 += STEP_S
    up = [w for w in windows if w["leg"] == "up"]
    down = [w for w in windows if w["leg"] == "down"]
    sw_up = _first_run(up, lambda w: w["physical_gait"] == b and not w["fell"])
    sw_down = _first_run(down, lambda w: w["physical_gait"] != b and not w["fell"])
    res = {"pair": pair, "network": kind, "from": a, "to": b, "ramp_s": ramp_s,
           "feedback_gain": rec.feedback_gain, "fell": rec.fell_at is not None,
           "fell_at_s": rec.fell_at, "switch_up": _point(sw_up), "switch_down": _point(sw_down),
           "windows": [{k: w[k] for k in ("start_s", "drive", "leg", "physical_gait",
                                          "speed_mps", "froude", "stride_period_s",
                                          "stride_length_m", "cpg_period_s")}
                       for w in windows]}
    if sw_up is not None and sw_down is not None:
        res["hysteresis_drive"] = sw_up["drive"] - sw_down["drive"]
    else:
        res["hysteresis_drive"] = None
    return res, rec


def cycle_period(t_s, activation, t0: float, t1: float) -> float | None:
    """T = median over k of (t_{k+1} - t_k) (s), t_k the times in [t0, t1] at which
    ``activation`` (one cell's, in [0, 1], sampled at ``t_s``) rises through E_ON: a_{i-1} < E_ON
    <= a_i, t_k = t_s[i]. None with fewer than two upcrossings there."""
    t_s, a = np.asarray(t_s, float), np.asarray(activation, float)
    up = t_s[1:][(a[1:] >= E_ON) & (a[:-1] < E_ON)]
    up = up[(up >= t0) & (up <= t1)]
    return float(np.median(np.diff(up))) if len(up) >= 2 else None


def _first_run(ws, pred):
    for i in range(len(ws) - PERSIST + 1):
        if all(pred(w) for w in ws[i:i + PERSIST]):
            return ws[i]
    return None


def _point(w):
    if w is None:
        return None
    return {"time_s": w["start_s"] + WINDOW_S / 2, "drive": w["drive"], "speed_mps": w["speed_mps"],
            "froude": w["froude"], "physical_gait": w["physical_gait"]}


GAIT_COLORS = {"walk": "tab:green", "run": "tab:red", "jump": "tab:purple", "hop": "tab:orange",
               "none": "0.6"}


def picture(res: dict, path) -> None:
    """Speed (top), the body's stride length and strides per second with the network's cycles
    per second beside them (middle) and the physical gait (bottom) against the drive, up and
    down. The top and middle panels leave out the windows in and after a fall (a fallen body
    has neither a gait's speed nor strides); an x marks the last window before it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cpgbiped.cpg.io import atomic_path

    fig, (a1, am, a2) = plt.subplots(3, 1, figsize=(6.4, 6.6), sharex=True,
                                     gridspec_kw={"height_ratios": [3, 1.8, 1.4]})
    af = am.twinx()
    names = sorted({w["physical_gait"] for w in res["windows"]} | {res["from"], res["to"]})
    for legname, ls, marker, dy in (("up", "-", "^", 0.12), ("down", "--", "v", -0.12)):
        ws = [w for w in res["windows"] if w["leg"] == legname]
        d = [w["drive"] for w in ws]
        nan, fell = float("nan"), res["fell_at_s"]

        def upright(w, key):  # the window's value, NaN in or after a fall
            x = w[key]
            late = fell is not None and w["start_s"] + WINDOW_S >= fell
            return nan if x is None or late else x

        speed = [upright(w, "speed_mps") for w in ws]
        a1.plot(d, speed, ls, color="k", lw=1, label=f"drive {legname}")
        kept = [i for i, v in enumerate(speed) if np.isfinite(v)]
        if fell is not None and kept and kept[-1] < len(ws) - 1:  # the fall comes on this leg
            a1.plot(d[kept[-1]], speed[kept[-1]], "x", color="k", ms=9, mew=2,
                    label=f"fell at {fell:.1f} s")

        am.plot(d, [upright(w, "stride_length_m") for w in ws], ls, color="tab:brown", lw=1,
                label="stride (m)" if legname == "up" else None)
        af.plot(d, [1.0 / upright(w, "stride_period_s") for w in ws], ls, color="tab:cyan",
                lw=1, label="strides / s" if legname == "up" else None)
        af.plot(d, [1.0 / upright(w, "cpg_period_s") for w in ws], ls, color="k", lw=0.6,
                alpha=0.5, label="CPG cycles / s" if legname == "up" else None)
        for w in ws:
            y = names.index(w["physical_gait"]) + dy
            a2.plot(w["drive"], y, marker, color=GAIT_COLORS.get(w["physical_gait"], "0.3"), ms=5)
    for key, color in (("switch_up", "tab:red"), ("switch_down", "tab:blue")):
        p = res[key]
        if p is not None:
            for ax in (a1, am, a2):
                ax.axvline(p["drive"], color=color, lw=1.2)
            a1.text(p["drive"], a1.get_ylim()[1], f" {key.replace('_', ' ')}\n d={p['drive']:.2f}",
                    color=color, fontsize=8, va="top")
    a2.set_yticks(range(len(names)), names)
    a1.set_ylabel("speed (m/s)")
    am.set_ylabel("stride (m)", color="tab:brown", fontsize=8)
    af.set_ylabel("strides / s (CPG cycles / s)", color="tab:cyan", fontsize=8)
    a2.set_xlabel(f"drive d ({res['from']} preset at 0, {res['to']} preset at 1)")
    hy = res["hysteresis_drive"]
    a1.set_title(f"{res['network']} {res['pair']} sweep, ramps of {res['ramp_s']:g} s"
                 + (f", feedback K = {res['feedback_gain']:g}" if res["feedback_gain"] else "")
                 + ("" if hy is None else f": hysteresis {hy:+.2f}"), fontsize=9)
    a1.legend(fontsize=8, loc="lower right")
    h1, l1 = am.get_legend_handles_labels()
    h2, l2 = af.get_legend_handles_labels()
    am.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper center", ncol=3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
