"""Feedback from the body into the CPG: cpg.feedback, the closed loop in envs, robustness and
phase response (issue 21)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.feedback import CHOICE, LOAD_CONTACT, RECOMMENDED, check_gain, loop_network, run_open
from cpgbiped.cpg.network import build
from cpgbiped.envs.simulation.rollout import rollout
from tests.test_physics import CONDITION_IDS, CONDITIONS, others_for, summary
from tests.test_physics import _cases as physics_cases

# The rollouts recorded before the closed loop existed (commit 7c11c25): network, preset, CPG
# seed, push (time s, impulse N s); 2.5 s each, stop_on_fall=False; every 5th row of their 45
# columns (float64, little-endian), kept as the SHA-256 of those bytes: a rollout with K = 0
# must reproduce them bit for bit. The bits depend on the host: the machines of two sessions
# gave two digests for the same code (the second machine: AVX2 and FMA, no AVX-512; presumably
# numpy's and numba's CPU-specific code), so each case holds both; the second set was made on
# that machine by commit bcd1fc2, before the double-support reflexes, and today's code gives
# the same digests there. They were recorded with the controller's gains of that time,
# kept in tests/data/gains_before_double_support.json (the gains file before the double-support
# reflexes were tuned; a file without them reads as their neutral 0).
RECORDED_GAINS = Path(__file__).with_name("data") / "gains_before_double_support.json"
RECORDED = {  # (digest on the first machine, digest on the AVX2 machine)
    ("ml", "walk", None, None):
        ("2c2cc3a005710811d6c6af4ae8a36d0248255f0e223c1b186811d32fda888a69",
         "a1cb8f9a2592830175718ff4f362932b5382c2258facafad7854cd58f60d775e"),
    ("ml", "jump", 3, (1.5, 4.0)):
        ("66a6d915dc8dca94bd3cc4cc7bb2acb503bbd30bd8f0d75dd2043452923ac0aa",
         "53d39506fbf4d31fac1797b895b7c6afdea92b13ae436a288f42ab21c95041b7"),
    ("hopf", "run", None, None):
        ("245d4367aad358ccdfa1d43eb510a242fe9dceb762f14f079f59dd19617f58dc",
         "a7ab011c6c0c0f4eae907f4e122b7dc8d71bbe93696bcf2a8b0a8e93736a7691"),
    ("matsuoka", "walk", None, None):
        ("7d569344b86941f46d3732b1c2e7f57f1ffcf777d77b39e76b7a67bbba306475",
         "b30194c1c6992cc68cfc44e46543a2f7d90ba87c805eff719695c00bb86f6149"),
}


def _rows(rec) -> np.ndarray:
    """The 45 columns a recording had before the feedback columns were added."""
    return np.column_stack([rec.t, rec.contact, rec.force, rec.cpg_v, rec.drive,
                            rec.muscle_activation, rec.joints, rec.torso_height, rec.torso_pitch,
                            rec.com_x, rec.com_z, rec.modes, rec.ctrl, rec.power])


@pytest.mark.parametrize("poses", [False, True], ids=["compiled loop", "python loop"])
def test_zero_gain_reproduces_the_rows_recorded_before_feedback_existed(poses):
    import hashlib

    from cpgbiped.envs.control.controller import read_gains

    params = read_gains(RECORDED_GAINS)[0]
    for (kind, preset, seed, push), digest in RECORDED.items():
        net = build(kind, preset, seed=seed)
        if kind == "hopf":  # recorded with the Hopf activation centred at y = 0, as it then was
            net.act_centre = 0.0
        rec = rollout(net, 2.5, params, push=push, poses=poses,
                      stop_on_fall=False, feedback=0.0)
        rows = np.ascontiguousarray(_rows(rec)[::5], dtype="<f8")
        assert rows.shape == (125, 45)
        assert hashlib.sha256(rows.tobytes()).hexdigest() in digest, (kind, preset)
        assert rec.feedback_gain == 0.0 and not rec.feedback.any()


@pytest.mark.parametrize("kind,preset,tol", [("ml", "walk", 5e-4), ("ml", "hop", 5e-4),
                                             ("hopf", "run", 1e-9), ("matsuoka", "walk", 1e-9)])
def test_the_stepped_network_without_input_follows_its_open_loop_integration(kind, preset, tol):
    """The closed loop's integrator (4 ms ticks; Morris-Lecar 3 RK4 steps of 0.0164 units,
    Hopf and Matsuoka 4 of 1 ms with the same noise) against the network's own open-loop
    integration (Morris-Lecar step 0.02 units), interpolated to the ticks: 5 s."""
    net = build(kind, preset)
    v = run_open(loop_network(net, 0.0, 0.004, 5.0), 1250)
    u = net.units_per_s
    out = net.outputs(5.1 * u, record_every=max(1, int(round(0.002 * u / net.dt))))
    t = np.arange(1251) * 0.004
    ref = np.column_stack([np.interp(t, out.t_model / u, out.v[:, c]) for c in range(4)])
    assert np.max(np.abs(v - ref)) < tol * np.ptp(ref)


def test_closed_loop_compiled_and_python_loops_agree_bit_for_bit():
    for kind in ("ml", "hopf", "matsuoka"):
        net = build(kind, "walk")
        K = RECOMMENDED[kind]
        a = rollout(net, 3.0, poses=False, feedback=K)
        b = rollout(net, 3.0, poses=True, feedback=K)
        assert np.array_equal(_rows(a), _rows(b)) and np.array_equal(a.feedback, b.feedback)
        assert a.feedback_gain == K and np.abs(a.feedback).max() > 0  # the loop is closed


def test_an_unloaded_leg_silences_its_morris_lecar_extensor_under_load_feedback():
    """Load form: dv_LE/dt += K (n_L - 1/2). A left leg that never carries load (n_L = 0) at
    K = 0.5 gives the left extensor -0.25, more than its applied current (0.229): it falls
    silent, while without feedback it bursts."""
    net = build("ml", "walk")
    sensors = np.tile([0.0, 0.5, 0.0, 0.0], (2500, 1))
    act = lambda v: net.activation(v)[-750:, 2]  # noqa: E731  the last 3 s of LE
    closed = run_open(loop_network(net, 0.5, 0.004, 10.0, form="load"), 2500, sensors)
    opened = run_open(loop_network(net, 0.0, 0.004, 10.0, form="load"), 2500, sensors)
    assert act(closed).max() < 0.5 < 0.9 < act(opened).max()


def test_tegotae_holds_a_loaded_hopf_leg_in_its_stance_half():
    """dtheta/dt += K n cos(theta): with K n above the burst's angular speed (omega_st = 8.4
    rad/s for the walk) the loaded left extensor stops in the second half of its oscillator's
    stance half (y > 0, theta in (0, pi)) instead of cycling through y = -1. (Whether the body
    sees it as a burst depends on the activation map's centre, 0.46 for the walk: held
    between y = 0.3 and 0.9 by the other cells' coupling at K = 20, it crosses that centre.)"""
    net = build("hopf", "walk")
    assert 20.0 > net.p.omega_st
    sensors = np.tile([1.0, 0.0, 0.0, 0.0], (2500, 1))
    closed = run_open(loop_network(net, 20.0, 0.004, 10.0), 2500, sensors)
    opened = run_open(loop_network(net, 0.0, 0.004, 10.0), 2500, sensors)
    assert closed[-750:, 2].min() > 0.0
    assert opened[-750:, 2].min() < -0.9


def test_the_thigh_angle_pathway_is_gated_by_ground_contact():
    """Taga form (a Morris-Lecar candidate, and the Matsuoka network's): nothing reaches a
    leg's cells while its foot carries less than LOAD_CONTACT body weights, and the flexor
    receives the opposite of the extensor."""
    from cpgbiped.envs.simulation.biped import body_constants

    rec = rollout(build("ml", "walk"), 6.0, poses=False, feedback=0.1, feedback_form="angle")
    weight = body_constants()[1] * 9.81
    for leg in range(2):
        air = rec.force[:, leg] / weight < LOAD_CONTACT
        # a row's feedback was computed from the sensors of the row before it (the input of a
        # tick, held over it; the row's force is measured at its end)
        fb, air = rec.feedback[1:, [leg, 2 + leg]], air[:-1]
        assert 0.2 < air.mean() < 0.8
        assert not fb[air].any() and np.abs(fb[~air]).max() > 0.01
        assert np.array_equal(fb[:, 0], -fb[:, 1])


def test_the_alternating_angle_form_is_the_angle_form_scaled_by_one_minus_the_synchrony():
    """"angle_alternating" (cpg/feedback.py): each cell receives the angle form's term times
    (1 - sigma), sigma the rhythm's synchrony in the sensor slot SYNC_SLOT, clipped to [0, 1]."""
    from cpgbiped.cpg.feedback import KIND_ML_ANGLE, ML_FORMS, SYNC_SLOT, THETA_REF, inputs

    y = np.zeros(8)
    for sigma in (0.0, 0.25, 1.0, 1.7, -0.3):
        sensors = np.zeros(11)
        sensors[:4] = (0.8, 0.0, 0.21, -0.12)  # loads, then contact-gated thigh angles (rad)
        sensors[SYNC_SLOT] = sigma
        gated, plain = np.zeros(4), np.zeros(4)
        inputs(ML_FORMS["angle_alternating"], 0.05, y, sensors, gated)
        inputs(KIND_ML_ANGLE, 0.05, y, sensors, plain)
        scale = 1.0 - min(max(sigma, 0.0), 1.0)
        expect = 0.05 * scale * np.array([-0.21, 0.12, 0.21, -0.12]) / THETA_REF
        assert np.allclose(gated, expect, atol=1e-15)
        assert np.allclose(gated, scale * plain, atol=1e-15)


def test_the_alternating_angle_form_leaves_the_hop_s_synchronous_network_alone():
    """In the hop's rhythm both legs' extensors burst together (sigma -> 1), so the gated form
    feeds the cells almost nothing once the controller has seen the rhythm, and the network
    stays the open loop's hop; the plain angle form at the same K feeds the standing thighs'
    angle into every cell (measured, session 39: the CPG classifier names the hop's network
    none from 19 of 20 tuning states)."""
    from cpgbiped.envs.gaits.validate import validate

    net = build("ml", "hop")
    gated = validate(net, "hop", 8.0, feedback=0.05, feedback_form="angle_alternating")
    plain = validate(net, "hop", 8.0, feedback=0.05, feedback_form="angle")
    late = gated.recording.t > 4.0
    fb_gated = np.abs(gated.recording.feedback[late]).mean()
    fb_plain = np.abs(plain.recording.feedback[plain.recording.t > 4.0]).mean()
    assert fb_gated < 0.1 * fb_plain, (fb_gated, fb_plain)
    assert gated.summary()["cpg_gait"] == "hop"


def test_the_phase_response_moves_the_cpg_only_with_feedback():
    """Open loop the network never hears the body: a push leaves its phase exactly where it
    was. With Tegotae feedback (Hopf run, K = 3) a 10 N s push moves it, at each phase tried,
    by more than a hundredth of a cycle (numerical noise is far below: open loop it is 0)."""
    from cpgbiped.envs.experiments.phase_response import phase_response

    net = build("hopf", "run")
    open_, closed = (phase_response(net, K, phases=(0.1, 0.4), impulse=10.0) for K in (0.0, 3.0))
    assert open_["dphi"] == [0.0, 0.0]
    assert min(abs(x) for x in closed["dphi"]) > 0.01, closed["dphi"]


def _cli(*args, timeout=300):
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "osmesa"))
    return subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", *args], capture_output=True,
                          text=True, timeout=timeout, env=env)


@pytest.mark.parametrize("args,says", [
    (("validate", "--feedback", "-1"), "K >= 0"),
    (("validate", "--feedback", "nan"), "K >= 0"),
    (("validate", "--feedback", "inf"), "K >= 0"),
    (("validate", "--feedback", "2"), "[0, 1]"),
    (("validate", "--network", "hopf", "--feedback", "1e9"), "[0, 50]"),
    (("matrix", "--network", "spiking", "--feedback"), "invalid choice"),
    (("robustness", "--feedback", "x"), "K >= 0"),
    (("optimize", "--gait", "walk", "--feedback", "0.1"), "belongs to optimize --physics"),
    (("validate", "--feedback-form", "angle"), "--feedback-form needs a feedback gain K > 0"),
    (("validate", "--feedback", "0", "--feedback-form", "angle"), "needs a feedback gain K > 0"),
    (("validate", "--feedback", "0.03", "--feedback-form", "tegotae"),
     "unknown --feedback-form 'tegotae'"),
    (("validate", "--network", "hopf", "--feedback", "--feedback-form", "load"),
     "the hopf network has one, tegotae"),
    (("robustness", "--feedback-form", "angle"), "--feedback-form needs a feedback gain K > 0"),
    (("transition", "--from", "walk", "--to", "run", "--feedback", "--feedback-form", "x"),
     "unknown --feedback-form 'x'"),
])
def test_bad_feedback_input_is_one_line_and_exit_2(args, says):
    r = _cli(*args, timeout=60)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cpgbiped: error:") and says in lines[0]
    assert r.stdout == ""


def test_feedback_through_a_parameter_change_is_the_morris_lecar_networks_only():
    from cpgbiped.cpg.integrate import Schedule

    with pytest.raises(InputError, match="Morris-Lecar network only"):
        rollout(build("hopf", "walk"), 2.0, to=build("hopf", "run"),
                change=Schedule.change(1.0), feedback=1.0)
    rec = rollout(build("ml", "walk"), 2.0, to=build("ml", "run"), change=Schedule.change(1.0),
                  feedback=0.01, poses=False)
    assert rec.feedback_gain == 0.01
    with pytest.raises(InputError):
        check_gain("ml", float("nan"))


def test_validate_json_reports_the_feedback_signals():
    r = _cli("validate", "--gait", "run", "--seconds", "3", "--feedback", "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["feedback_gain"] == RECOMMENDED["ml"]
    assert set(s["feedback_rms"]) == {"LF", "RF", "LE", "RE"}
    assert min(s["feedback_rms"].values()) > 0


def test_feedback_form_chooses_the_pathway_the_rollout_uses():
    """``--feedback-form`` reaches the rollout: at the same K the load and the angle pathways
    feed the cells different terms (cpg/feedback.py: the foot's load against the thigh's
    angle), the JSON names the pathway the loop ran, and naming the recommended pathway gives
    the rollout ``--feedback K`` alone gives."""
    from cpgbiped.cpg.feedback import ML_FORMS

    rms = {}
    for form in ("load", "angle", CHOICE["ml"][0], None):
        extra = ("--feedback-form", form) if form else ()
        r = _cli("validate", "--gait", "walk", "--seconds", "3", "--feedback", "0.03",
                 *extra, "--json")
        assert r.returncode == 0, r.stderr
        s = json.loads(r.stdout)
        assert s["feedback_form"] == (form or CHOICE["ml"][0])
        named = [f for f in ML_FORMS if f"({f})" in s["source"]]
        assert named == ([form] if form else [])
        rms[form] = s["feedback_rms"]
    assert rms["load"] != rms["angle"]
    assert rms[CHOICE["ml"][0]] == rms[None]
    r = _cli("validate", "--gait", "walk", "--seconds", "1", "--json")  # open loop: no pathway
    assert json.loads(r.stdout)["feedback_form"] is None


def test_robustness_and_transition_pass_the_form_on(monkeypatch):
    """The commands hand --feedback-form to the library (stubs record what they receive), and
    ``robustness`` gives the pathway to the gains above 0 only: open loop uses none."""
    import cpgbiped.envs.experiments.robustness as rb
    import cpgbiped.envs.experiments.transition as tr
    from cpgbiped.envs.cli.main import main

    seen = {}

    def stop(name):
        def f(*args, **kw):
            seen[name] = kw
            raise KeyboardInterrupt  # ends the command before any rollout or output
        return f

    monkeypatch.setattr(rb, "robustness", stop("robustness"))
    monkeypatch.setattr(tr, "transition", stop("transition"))
    for args in (["robustness", "--gait", "walk", "--feedback", "--feedback-form", "load"],
                 ["transition", "--from", "walk", "--to", "run", "--feedback",
                  "--feedback-form", "load"]):
        try:
            main(args)
        except KeyboardInterrupt:
            pass
    assert seen["robustness"]["form"] == "load"
    assert seen["transition"]["feedback_form"] == "load"
    monkeypatch.undo()

    forms = []
    monkeypatch.setattr(rb, "push_envelope", lambda net, K, **kw: forms.append(
        ("push", K, kw["form"])) or {"forward": [1.0], "backward": [1.0]})
    monkeypatch.setattr(rb, "condition_survival", lambda net, gait, K, form=None: forms.append(
        ("conditions", K, form)) or {})
    res = rb.robustness(build("ml", "walk"), "walk", [0.0, 0.03], form="load")
    assert forms == [("push", 0.0, None), ("conditions", 0.0, None), ("push", 0.03, "load"),
                     ("conditions", 0.03, "load")]
    assert res["feedback_form"] == "load"
    assert rb.robustness(build("ml", "walk"), "walk", [0.0])["feedback_form"] is None


def test_robustness_envelope_is_the_largest_impulse_survived_before_the_first_fall(tmp_path):
    """The command's envelope at one phase, checked against rollouts made here: the impulse it
    reports is survived and the next one up the ladder is not."""
    from cpgbiped.envs.experiments.robustness import HOLD_S, IMPULSE_LADDER_NS, stride_phase

    r = _cli("robustness", "--gait", "run", "--json", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    assert (tmp_path / "robustness_ml_run.png").stat().st_size > 10_000
    g = res["by_gain"][0]
    assert g["feedback_gain"] == 0.0 and g["total"] == 12
    best = g["push"]["forward"][0]
    net = build("ml", "run")
    sp = stride_phase(net, 0.0)
    assert sp.t0_s == pytest.approx(g["push"]["stride"]["t0_s"])
    nxt = IMPULSE_LADDER_NS[IMPULSE_LADDER_NS.index(best) + 1] if best else IMPULSE_LADDER_NS[0]
    assert res["push_s"] == 0.2  # SCONE's perturbed-gait tutorial holds its push 0.2 s
    def fails(imp):  # as the envelope counts: a fall, or physics that became unstable
        rec = rollout(net, sp.t0_s + HOLD_S, push=(sp.t0_s, imp, res["push_s"]), poses=False)
        return rec.fell_at is not None or rec.unstable is not None

    assert (not best or not fails(best)) and fails(nxt)


def test_push_after_moves_the_pushes_to_a_later_stride():
    """robustness --push-after S: phase 0 is the first left touchdown at or after S seconds
    (the issue's 6 s by default), so a settled gait can be pushed; the stride is the
    unperturbed rollout's, found here from its contacts."""
    from cpgbiped.envs.experiments.robustness import push_envelope
    from cpgbiped.envs.gaits.gait_metrics import debounce, edges

    net = build("ml", "walk")
    rec = rollout(net, 20.0, poses=False)
    td, _ = edges(rec.t, debounce(rec.contact[:, 0], rec.dt))
    for after in (6.0, 12.0):
        env = push_envelope(net, 0.0, phases=(0.0,), ladder=(2.5,), after_s=after)
        assert env["stride"]["t0_s"] == pytest.approx(td[td >= after][0], abs=1e-9)
        assert after <= env["stride"]["t0_s"] < after + 1.5  # within one walk stride (1.07 s)


def test_the_envelope_takes_the_gains_it_is_given(monkeypatch):
    """push_envelope(params=...) rolls the body out with those gains (an adoption rule compares
    a candidate's envelope with the committed one's, scripts/envelope_census.py): with the walk
    corner's foot placement moved (theta0 + 0.03 rad) the walk's touchdowns are not the
    committed gains' (its first left touchdown after 6 s, found here from its own contacts),
    and every rollout the envelope makes is given those gains."""
    from cpgbiped.envs.control.controller import CONTROL
    from cpgbiped.envs.experiments.robustness import push_envelope
    from cpgbiped.envs.gaits.gait_metrics import debounce, edges
    from cpgbiped.envs.search.controller_tuning import values_of, with_values

    name = "alternating.theta0"
    moved = with_values(CONTROL, [name], [values_of(CONTROL, [name])[0] + 0.03])
    net = build("ml", "walk")
    tds = []
    for params in (moved, CONTROL):
        rec = rollout(net, 12.0, params, poses=False)
        td, _ = edges(rec.t, debounce(rec.contact[:, 0], rec.dt))
        tds.append(td[td >= 6.0][0] if rec.fell_at is None and (td >= 6.0).any() else None)
    assert tds[0] is not None and tds[0] != tds[1]  # the other gains walk, elsewhere
    # every rollout of the envelope (the stride's and each push's) gets those gains
    import cpgbiped.envs.experiments.robustness as rb

    given = []

    def spy(network, seconds, params, *args, **kw):
        given.append(params)
        return rollout(network, seconds, params, *args, **kw)

    monkeypatch.setattr(rb, "rollout", spy)
    env = push_envelope(net, 0.0, phases=(0.0,), ladder=(2.5,), params=moved)
    assert env["stride"]["t0_s"] == pytest.approx(tds[0], abs=1e-9)
    assert len(given) == 3 and all(p is moved for p in given)  # stride, +2.5, -2.5 N s


# -- what issue 21 asks and the closed loop does not reach (measured, README "Feedback") ----
# Issue 21's first clause, measured with the recommended feedback (README "Status", issue 21's
# row; scripts/report_feedback.py): case -> (what was measured, strict). Every miss sits at a
# criterion's edge or is a single fall or a late regular start of a chaotic body, which a
# change far away moves (non-strict, as tests/test_physics.py's).
CLOSED_LOOP_SHORTFALLS = {
    "walk-friction1.3": ("Froude number 0.0799 against 0.08 (since session 50)", False),
    "run-friction0.7": ("the left leg's duty 0.299 against 0.30", False),
    "hop-seed18": ("stride CV 0.13: its strides regular only from 5.5 s", False),
    "hop-friction1.3": ("falls at 9.9 s (since session 50)", False),
}


@pytest.mark.parametrize("gait,cond", list(physics_cases(CONDITIONS, CONDITION_IDS,
                                                         CLOSED_LOOP_SHORTFALLS)))
def test_every_preset_meets_its_criteria_with_feedback(gait, cond):
    """Issue 21: with feedback at the recommended gain every Morris-Lecar preset still passes
    every criterion of its gait in each of the 13 test conditions (as
    tests/test_physics.py asks open loop; the hop's cadence against the jump's, both closed
    loop), the CPG classifier's name from the closed-loop cells among them; the jump's cases,
    none expected to fail, are issue 21's "the jump survives all 13 with feedback" (a fall
    fails every criterion)."""
    from cpgbiped.envs.gaits.criteria import CRITERIA

    cond = dict(cond, feedback=RECOMMENDED["ml"])
    failures = CRITERIA[gait].failures(summary(gait, **cond), others_for(gait, cond))
    assert not failures, failures  # the criteria include the CPG classifier's name


# Measured 2026-12-04 (Table 3 state; smallest impulse survived over four stride phases, open
# loop / Taga's thigh angle at K = 0.01): pushes held 0.2 s as SCONE's tutorial holds them,
# and blows of the same impulse in one 4 ms control tick (the form of the tuning conditions,
# and the only form measured until 2026-12-04); re-measured 2026-12-05 after the hop corner's
# foot placement (scripts/hop_placement.py), which the run's first seconds blend: the run's
# forward pushes, 5 N s open loop and 2.5 with feedback before it, were then 2.5 and 5
# (doubled, by the open loop's loss as much as the feedback's gain); since session 35 they
# are 5 N s either way (_ENVELOPE_SHORTFALLS).
_ENVELOPE_SHORTFALLS = {
    # re-measured 2026-12-06 (session 40) when the recommended feedback became Taga's angle in
    # alternating rhythms at K = 0.03: the run's backward push 10 -> 25 N s with feedback (per
    # phase 25/40/30/40; open loop 30/10/25/10), which meets the target; the blows per phase,
    # walk forwards 15/10/15/10 open loop and 15/10/20/10 with feedback, run forwards
    # 10/7.5/10/5 and 10/7.5/10/7.5. With Taga's thigh angle at K = 0.01 (sessions 35-39) the
    # run's backward push was 10 N s either way (0.48 N s/kg, per phase 25/40/40/10).
    ("run", "forward", "push"): "5 N s open loop and with feedback (0.24 N s/kg)",
    ("walk", "forward", "blow"): "10 N s open loop and with feedback (0.48 N s/kg): the blow "
                                 "lifts the stance foot off the ground",
    ("run", "forward", "blow"): "5 N s open loop, 7.5 with feedback (0.36 N s/kg)",
}


def _envelope_cases():
    for preset in ("walk", "run"):
        for direction in ("forward", "backward"):
            for form in ("push", "blow"):
                why = _ENVELOPE_SHORTFALLS.get((preset, direction, form))
                marks = [pytest.mark.xfail(raises=AssertionError, strict=True, reason=why)
                         ] if why else []
                yield pytest.param(preset, direction, form, marks=marks,
                                   id=f"{preset}-{direction}-{form}")


@pytest.mark.parametrize("preset,direction,form", list(_envelope_cases()))
def test_feedback_doubles_the_push_envelope_or_reaches_half_a_newton_second_per_kg(
        preset, direction, form):
    """Issue 21: the smallest impulse survived over four stride phases with the recommended
    feedback is twice the open loop's or at least 0.5 N s/kg of the 21 kg body (10.5 N s),
    for the walk and the run, forwards and backwards. "push": the force held 0.2 s, as
    SCONE's perturbed-gait tutorial holds its 100 N (the product's push); "blow": the same
    impulse in one 4 ms control tick. Measured (session 40, Taga's angle in alternating rhythms
    at K = 0.03): the walk with feedback 12.5 N s forwards and 20 backwards (pushes; 12.5 and
    25 open loop), 10 and 15 (blows, the same open loop); the run 25 N s backwards (pushes; 10
    open loop) and 20 (blows; 15 open loop); its forward ones in _ENVELOPE_SHORTFALLS."""
    from cpgbiped.envs.experiments.robustness import PUSH_S, push_envelope
    from cpgbiped.envs.simulation.rollout import PUSH_TICK_S

    net = build("ml", preset)
    push_s = PUSH_S if form == "push" else PUSH_TICK_S
    o, c = (min(push_envelope(net, K, push_s=push_s)[direction])
            for K in (0.0, RECOMMENDED["ml"]))
    assert c >= 2 * o or c >= 0.5 * 21.0, (preset, direction, form, o, c)


def _admissible_four_seeds(mine, order):
    """The chooser's rule that made the committed file (format 1, sessions 40-51): no rollout
    falls and the CPG names what it names open loop, for every preset and each of the four
    tuning CPG seeds on friction x1.0, and per preset the criteria pass in at least as many
    seeds as open loop."""
    named_open = {(r["preset"], r["cpg_seed"]): r["cpg_gait"] for r in mine if r["gain"] == 0}
    passed_open, passed, ok = {}, {}, dict.fromkeys(order, True)
    for r in mine:
        if r["gain"] == 0:
            passed_open[r["preset"]] = passed_open.get(r["preset"], 0) + r["criteria_passed"]
            continue
        key = (r["form"], r["gain"])
        ok[key] &= (not r["fell"]) and r["cpg_gait"] == named_open[(r["preset"], r["cpg_seed"])]
        passed[key + (r["preset"],)] = passed.get(key + (r["preset"],), 0) + r["criteria_passed"]
    return {k: ok[k] and all(passed[k + (p,)] >= n for p, n in passed_open.items())
            for k in order}


def _admissible_on_floors(mine, order, rule):
    """The chooser's rule since session 52 (format 2, its parameters in the file's "rule"):
    over the admission seeds on each floor, paired with open loop's rollouts from the same
    state and floor, per preset and floor the candidate loses no more than noise_sd sqrt(b + c)
    net pairs (b lost, c gained) in passing every criterion, and no more than new_losses_max net
    in standing and in the CPG's name."""
    opened = {(r["preset"], r["cpg_seed"], r["friction"]): r for r in mine if r["gain"] == 0}
    net = {}
    for r in mine:
        if r["gain"] == 0:
            continue
        o = opened[(r["preset"], r["cpg_seed"], r["friction"])]
        for what, good, open_good in (("passes", r["criteria_passed"], o["criteria_passed"]),
                                      ("standing", not r["fell"], not o["fell"]),
                                      ("named", r["cpg_gait"] == o["cpg_gait"], True)):
            lost_gained = net.setdefault((r["form"], r["gain"], r["preset"], r["friction"],
                                          what), [0, 0])
            lost_gained[0] += open_good and not good
            lost_gained[1] += good and not open_good

    def allowed(what, b, c):
        return (rule["noise_sd"] * np.sqrt(b + c) if what == "passes"
                else rule["new_losses_max"])

    return {k: all(b - c <= allowed(kk[4], b, c) for kk, (b, c) in net.items() if kk[:2] == k)
            for k in order}


def test_the_test_s_rule_and_the_chooser_s_agree_on_hand_made_rows():
    """The re-application below (format 2) and scripts/feedback_choice.py's costs, on rows made
    by hand: a candidate that loses 5 of 20 passes on one floor, one that loses one fall, one
    that loses two, one that renames two rhythms, and one that loses nothing."""
    from tests.test_controller_tuning import _script

    fc = _script("feedback_choice")
    rule = {"noise_sd": fc.NOISE_SD, "new_losses_max": fc.NEW_LOSSES_MAX}

    def row(gain, seed, passed=True, fell=False, gait="walk"):
        return {"form": "angle", "gain": gain, "preset": "walk", "cpg_seed": seed,
                "friction": 0.8, "criteria_passed": passed and not fell, "fell": fell,
                "cpg_gait": gait}

    mine = [row(0.0, s) for s in range(20)]
    cases = {0.01: dict(), 0.02: dict(passed=False), 0.03: dict(fell=True),
             0.04: dict(fell=True), 0.05: dict(gait="none")}
    hit = {0.01: 0, 0.02: 5, 0.03: 1, 0.04: 2, 0.05: 2}  # states 0..hit-1 get the change
    for g, change in cases.items():
        mine += [row(g, s, **(change if s < hit[g] else {})) for s in range(20)]
    order = [("angle", g) for g in cases]
    ok = _admissible_on_floors(mine, order, rule)
    assert ok == {("angle", 0.01): True, ("angle", 0.02): False, ("angle", 0.03): True,
                  ("angle", 0.04): False, ("angle", 0.05): False}
    open_rows = [r for r in mine if r["gain"] == 0]
    assert {k: not fc.costs([r for r in mine if r["gain"] == k[1]], open_rows)
            for k in order} == ok


def test_the_recommended_gains_are_the_rule_applied_to_the_recorded_candidates():
    """cpg/feedback_gains.json keeps every candidate's rollouts (scripts/feedback_choice.py).
    Re-applied here, independently of the script, by the rule of the file's format: the
    four-seed rule on friction x1.0 that made the committed file (format 1, session 40), or the
    rule on several floors that the script applies since session 52 (format 2, its seeds,
    floors and allowances recorded in the file). The recommendation is the best summed envelope
    score among the admissible candidates with K > 0 (the first listed among equals), or, when
    none is admissible, the smallest gain tried. Only the walk's and the run's envelopes from
    the scored seeds on friction x1.0 count; the other rows carry 0 N s."""
    from cpgbiped.cpg.feedback import GAINS_FILE

    d = json.loads(GAINS_FILE.read_text())
    rows = d["candidates"]
    assert d["format"] in ("cpgbiped.feedback_gains/1", "cpgbiped.feedback_gains/2")
    rule = d.get("rule", {"admit_seeds": [1000, 1001, 1002, 1003], "admit_frictions": [1.0],
                          "choice_seeds": [1000, 1001, 1002, 1003], "scored": ["walk", "run"]})
    assert {r["cpg_seed"] for r in rows} == set(rule["admit_seeds"])
    assert set(rule["admit_seeds"]).isdisjoint(range(10, 20))  # not the tests' states
    assert {r.get("friction", 1.0) for r in rows} == set(rule["admit_frictions"])
    assert not {0.5, 0.7, 1.3, 2.0} & set(rule["admit_frictions"])  # not the tests' floors
    assert {r["preset"] for r in rows if r["network"] == "ml"} == {"walk", "run", "jump", "hop"}
    for r in rows:
        scored = (r["preset"] in rule["scored"] and r["cpg_seed"] in rule["choice_seeds"]
                  and r.get("friction", 1.0) == 1.0)
        assert r.get("scored", scored) == scored
        if not scored:
            assert r["forward_ns"] == r["backward_ns"] == [0.0]  # admissibility only
    for kind, chosen in d["networks"].items():
        mine = [r for r in rows if r["network"] == kind]
        order = list(dict.fromkeys((r["form"], r["gain"]) for r in mine if r["gain"] > 0))
        score = {k: sum(min(r["forward_ns"]) + min(r["backward_ns"]) for r in mine
                        if (r["form"], r["gain"]) == k) for k in order}
        ok = (_admissible_on_floors(mine, order, d["rule"]) if "rule" in d
              else _admissible_four_seeds(mine, order))
        best = max((k for k in order if ok[k]), key=lambda k: score[k],
                   default=min(order, key=lambda k: k[1]))
        assert best == (chosen["form"], chosen["recommended_gain"]), (kind, best, chosen)
        assert CHOICE[kind] == best


def test_the_touchdown_pulse_follows_each_landing_for_fifty_milliseconds():
    """Reset form: the extensor receives K (the flexor -K) for RESET_S after each landing,
    the landings taken here from the recorded loads (crossing LOAD_CONTACT upwards)."""
    from cpgbiped.cpg.feedback import RESET_S
    from cpgbiped.envs.simulation.biped import body_constants

    K = 0.05
    rec = rollout(build("ml", "walk"), 8.0, poses=False, feedback=K, feedback_form="reset")
    on = rec.force / (body_constants()[1] * 9.81) > LOAD_CONTACT
    for leg in range(2):
        landings = np.nonzero(on[1:, leg] & ~on[:-1, leg])[0] + 1
        pulse = rec.feedback[1:, 2 + leg] > 0  # row r's input: the sensors of row r - 1
        assert len(landings) >= 6 and pulse[landings[landings < len(pulse)]].all()
        n = int(np.ceil(RESET_S / rec.dt - 1e-9))  # ticks of a pulse (the last one partial)
        since = np.full(len(pulse), 10**9)  # ticks since the last landing
        for j in range(len(pulse)):
            since[j] = 0 if j in set(landings) else (since[j - 1] + 1 if j else 10**9)
        assert np.array_equal(pulse, since < n)
        assert np.allclose(rec.feedback[1:, 2 + leg][pulse], K)
        assert np.array_equal(rec.feedback[:, leg], -rec.feedback[:, 2 + leg])
