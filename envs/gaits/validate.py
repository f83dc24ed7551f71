"""Physical validation: one rollout, contact metrics, and both verdicts.

A network (any kind, any preset or weights) drives the body through the one controller; the
gait asked for (``gait``) is only the target the verdict checks. ``cpg_gait`` is what
:func:`cpg.gaits.classify` names from the four CPG outputs recorded during the rollout;
``physical_gait`` is what :mod:`cpgbiped.envs.gaits.gait_metrics` names from the foot contacts alone. A gait
passes when it meets every criterion of :data:`cpgbiped.envs.gaits.criteria.CRITERIA` that one rollout can
show (no fall, both classifiers agree with the target, its pattern and distance).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.gaits import classify
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import Network

from cpgbiped.envs.control.controller import CONTROL, ControlParams
from cpgbiped.envs.gaits.criteria import CRITERIA, SETTLE_S
from cpgbiped.envs.gaits.gait_metrics import Biomechanics, GaitMetrics, biomechanics, measure
from cpgbiped.envs.simulation.rollout import Recording, check_seconds, rollout


@dataclass
class Validation:
    network: Network
    gait: str | None  # the target the verdict checks (None: no target)
    recording: Recording
    metrics: GaitMetrics
    cpg_gait: str
    settle_s: float
    ankle_drive: bool = True
    biomech: Biomechanics | None = None

    def summary(self, cpg_period: bool = True) -> dict:
        """The measurements, the verdict (``failures``, ``passed``) against ``gait``'s criteria,
        and the network's own period; ``cpg_period=False`` leaves that period out (None): it
        integrates the network alone for 30 s, and no criterion reads it."""
        m = self.metrics
        s = {
            "network": self.network.kind, "preset": self.network.preset, "gait": self.gait,
            "ankle_drive": self.ankle_drive,
            "settle_s": self.settle_s, "fell": m.fell, "fell_at_s": m.fell_at_s,
            "unstable": self.recording.unstable,
            "duty_factor": m.duty_factor, "lr_phase_lag": m.lr_phase_lag,
            "double_support": m.double_support, "flight": m.flight,
            "stride_period_s": m.stride_period_s,
            "cpg_period_s": _cpg_period_s(self.network) if cpg_period else None,
            "distance_m": m.distance_m, "speed_mps": m.speed_mps,
            "footfalls_per_stride": m.footfalls_per_stride,
            "ankle_excursion_deg": m.ankle_excursion_deg,
            "physical_gait": m.physical_gait, "cpg_gait": self.cpg_gait,
            "feedback_gain": self.recording.feedback_gain,
            "feedback_form": self.recording.feedback_form,
            "feedback_rms": _feedback_rms(self.recording, self.settle_s),
        }
        if self.biomech is not None:
            s.update(self.biomech.as_dict())
        s["failures"] = CRITERIA[self.gait].failures(s) if self.gait else []
        s["passed"] = bool(self.gait and not s["failures"])
        return s


def _feedback_rms(rec: Recording, settle_s: float) -> dict:
    """Root mean square of the feedback term each cell received after settling (zero open
    loop); units of cpg.feedback's equations for the network."""
    from cpgbiped.cpg.morris_lecar import CELLS

    sel = rec.t >= settle_s
    fb = rec.feedback[sel] if len(rec.feedback) == len(rec.t) else np.zeros((0, 4))
    rms = np.sqrt((fb ** 2).mean(axis=0)) if len(fb) else np.zeros(4)
    return {c: float(x) for c, x in zip(CELLS, rms)}


def _cpg_period_s(net: Network) -> float | None:
    try:
        return net.period_s()
    except InputError:
        return None


def check_gait(gait: str | None) -> str | None:
    if gait is not None and gait not in CRITERIA:
        raise InputError(f"unknown gait {gait!r}: physical gaits are {', '.join(CRITERIA)}")
    return gait


def validate(network: Network, gait: str | None = None, seconds: float = 20.0, *,
             friction_scale: float = 1.0, push: tuple[float, ...] | None = None,
             settle_s: float = SETTLE_S, stop_on_fall: bool = True, ankle_drive: bool = True,
             params: ControlParams = CONTROL, to: Network | None = None,
             change: Schedule | None = None, feedback: float = 0.0,
             feedback_form: str | None = None) -> Validation:
    """Roll out ``settle_s + seconds`` and measure the gait over the last ``seconds``;
    ``feedback``: the gain K of the body's feedback into the CPG (0: open loop), through the
    network's chosen pathway or, Morris-Lecar only, ``feedback_form`` (one of
    cpg.feedback.ML_FORMS); ``push``:
    (time s, impulse N s[, held s]) as :func:`rollout` takes it (held one control tick when
    no duration is given; ``cpgbiped validate --push`` holds it 0.2 s)."""
    check_gait(gait)
    seconds = check_seconds(seconds)
    rec = rollout(network, seconds + settle_s, params, friction_scale=friction_scale, push=push,
                  stop_on_fall=stop_on_fall, ankle_drive=ankle_drive, to=to, change=change,
                  feedback=feedback, feedback_form=feedback_form)
    return measure_recording(network, gait, rec, settle_s, ankle_drive)


def measure_recording(network: Network, gait: str | None, rec: Recording, settle_s: float,
                      ankle_drive: bool = True, t_end: float | None = None) -> Validation:
    """Metrics and verdicts of a recording over [settle_s, t_end]."""
    fell_at = rec.fell_at if rec.unstable is None else (rec.t[-1] if len(rec.t) else 0.0)
    sel = rec.t <= (np.inf if t_end is None else t_end)
    m = measure(rec.t[sel], rec.contact[sel], rec.com_x[sel], fell_at, settle_s=settle_s,
                ankle=rec.joints[sel][:, [2, 5]])
    steady = sel & (rec.t >= settle_s)
    cpg_name = classify(rec.t[steady], rec.cpg_v[steady])[0] if steady.sum() > 16 else "none"
    from cpgbiped.envs.simulation.biped import body_constants, foot_edges_x

    leg, mass, joint, side = body_constants(rec.xml_path)
    toe_x = heel_x = None
    if rec.body_pose.shape[0] == len(rec.t) and len(rec.t):
        toe_x, heel_x = (e[sel] for e in foot_edges_x(rec.body_pose, rec.xml_path))
    bio = biomechanics(rec.t[sel], rec.contact[sel], rec.com_x[sel], rec.com_z[sel],
                       rec.power[sel], joint, side, m, leg, mass, settle_s,
                       pitch=rec.torso_pitch[sel],
                       grf_x=rec.grf_x[sel] if len(rec.grf_x) == len(rec.t) else None,
                       grf_z=rec.grf_z[sel] if len(rec.grf_z) == len(rec.t) else None,
                       toe_x=toe_x, heel_x=heel_x)
    return Validation(network, gait, rec, m, cpg_name, settle_s, ankle_drive, bio)


def biomechanics_text(s: dict) -> str:
    """The biomechanics of one ``Validation.summary()`` as three lines of text (what `validate`
    prints under its table; the same numbers as ``--json``): speed, Froude number, stride and
    its length against Alexander's 2.3 Fr^0.3, apex, ankle excursion, stride CV and when the
    strides became regular, trunk lean;
    then the ground: the peak vertical force per foot (body weights, where in the stance) and
    the stance's horizontal impulses; then the balance: the margins of stability."""
    from cpgbiped.envs.gaits.criteria import alexander_relative_stride

    def f(key, p=2, scale=1.0):
        x = s.get(key)
        return "nan" if x is None or not np.isfinite(x) else f"{scale * x:.{p}f}"

    fr = s.get("froude")
    alex = (f"{alexander_relative_stride(fr):.2f}" if fr is not None and np.isfinite(fr) and fr > 0
            else "nan")
    return (f"biomechanics: speed {f('speed_mps')} m/s, Fr {f('froude', 3)}, stride "
            f"{f('stride_period_s')} s, stride/leg {f('relative_stride_length')} (Alexander "
            f"{alex}), apex {f('apex_height_m', 1, 100)} cm, ankle excursion "
            f"{f('ankle_excursion_deg', 0)} deg, stride CV {f('stride_cv', 1, 100)}% (strides "
            f"regular from {f('regular_from_s', 1)} s), trunk lean {f('trunk_lean_deg', 0)} deg\n"
            f"ground: peak vertical force {f('peak_vertical_grf_bw', 1)} body weights at "
            f"{f('peak_vertical_grf_at')} of the stance; horizontal impulse "
            f"{f('stance_impulse_first_half_Ns', 1)} / {f('stance_impulse_second_half_Ns', 1)} N s "
            f"(stance first / second half), touches {f('touch_impulse_per_step_Ns', 1)} N s per step\n"
            f"balance: margin of stability forward {f('mos_forward_m')} m (5th percentile "
            f"{f('mos_forward_p5_m')}, at touchdown {f('mos_touchdown_m')}), backward "
            f"{f('mos_backward_m')} m (5th percentile {f('mos_backward_p5_m')})")


def metrics_table(summaries: dict[str, dict]) -> str:
    """Physical metrics and verdicts as text, from ``Validation.summary()`` per rollout."""
    from cpgbiped.cpg.io import format_table

    rows = []
    for name, s in summaries.items():
        d = s["duty_factor"]
        f = lambda x, p=2: "nan" if x is None or not np.isfinite(x) else f"{x:.{p}f}"  # noqa: E731
        verdict = "-" if not s.get("gait") else ("PASS" if s["passed"] else "fail")
        rows.append([name, "yes" if s["fell"] else "no", f"{f(d['left'])}/{f(d['right'])}",
                     f(s["lr_phase_lag"]), f(s["double_support"]), f(s["flight"]),
                     f(s["stride_period_s"]), f(s["distance_m"]), s["physical_gait"],
                     s["cpg_gait"], verdict])
    return format_table(rows, ["rollout", "fell", "duty L/R", "L-R lag", "double", "flight",
                               "stride s", "dist m", "physical", "cpg", "verdict"])
