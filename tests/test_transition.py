"""Gait transitions and drive sweeps in physics (envs.transition, envs.sweep; issue 22)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cpgbiped.cpg.feedback import RECOMMENDED, loop_network, run_open
from cpgbiped.cpg.integrate import Schedule
from cpgbiped.cpg.network import build
from cpgbiped.envs.simulation.rollout import rollout
from cpgbiped.envs.experiments.sweep import PERSIST, _first_run, cycle_period, schedule
from cpgbiped.envs.experiments.transition import IN_FAMILY, transition


def _cli(*args, timeout=300):
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "osmesa"))
    return subprocess.run([sys.executable, "-m", "cpgbiped.envs.cli", *args], capture_output=True,
                          text=True, timeout=timeout, env=env)


def test_the_stepped_network_follows_its_open_loop_integration_through_a_ramp():
    """Walk to run over 1 s from 3 s: the closed loop's integrator (parameters held over each
    4 ms tick) against the open-loop kernel (held over each 0.02-unit step, 1.6 ms): the two
    holds differ by up to a tick during the ramp, which shifts the phase slightly; 8 s."""
    a, b = build("ml", "walk"), build("ml", "run")
    ch = Schedule.change(3.0, 1.0)
    v = run_open(loop_network(a, 0.0, 0.004, 8.0, to=b, change=ch), 2000)
    u = a.units_per_s
    out = a.outputs(8.1 * u, to=b, schedule=ch.scaled(u))
    t = np.arange(2001) * 0.004
    ref = np.column_stack([np.interp(t, out.t_model / u, out.v[:, c]) for c in range(4)])
    assert np.max(np.abs(v - ref)) < 0.02 * np.ptp(ref)
    # and the parameters did change: after the ramp the cells leave the walk network's orbit
    w = run_open(loop_network(a, 0.0, 0.004, 8.0), 2000)
    assert np.max(np.abs(v[t > 5] - w[t > 5])) > 0.3


def test_closed_loop_through_a_change_agrees_in_both_loops():
    a, b = build("ml", "walk"), build("ml", "run")
    ch = Schedule.change(2.0, 1.0)
    r1 = rollout(a, 5.0, to=b, change=ch, poses=False, feedback=0.01)
    r2 = rollout(a, 5.0, to=b, change=ch, poses=True, feedback=0.01)
    assert np.array_equal(r1.cpg_v, r2.cpg_v) and np.array_equal(r1.com_x, r2.com_x)


@pytest.mark.parametrize("K", [0.0, 0.01])
def test_the_cpg_state_carries_across_a_step(K):
    """No reset: across a step of the parameters the cells' outputs move no more from one tick
    to the next than they do elsewhere in the rollout."""
    res, rec, *_ = transition("ml", "walk", "run", 6.0, 0.0, 9.0, feedback=K)
    dv = np.abs(np.diff(rec.cpg_v, axis=0)).max(axis=1)
    k = int(np.searchsorted(rec.t, 6.0))
    assert dv[k - 3:k + 3].max() <= dv.max() and dv[k - 3:k + 3].max() < 3 * np.percentile(dv, 99)


def test_the_window_before_the_change_holds_whole_cycles_of_a():
    """The gait before the change is measured over whole CPG cycles of A ending at the change:
    5 of them when they fit after the 2 s settling, else as many as fit. Checked against the
    body's own strides: the run's window, 5 of the network's cycles, holds 5 of the contacts'
    stride periods (one stride per CPG cycle)."""
    from cpgbiped.envs.experiments.transition import before_cycles

    res, *_ = transition("ml", "run", "walk", 8.0, 0.0, 9.0)
    w = res["before"]
    assert res["before_cycles"] == 5
    assert w["end_s"] - w["start_s"] == pytest.approx(5 * w["stride_period_s"], rel=0.02)
    assert res["before_from_settling"]["start_s"] == 2.0
    assert before_cycles(4.0, 0.721) == 2 and before_cycles(2.5, 0.721) == 0
    assert before_cycles(100.0, 0.721) == 5


def test_seed_starts_the_network_from_that_random_state():
    """--seed S: A starts from the random CPG state of seed S (as validate --seed does), so up
    to the change the rollout is a plain rollout of build(kind, A, seed=S), and not the Table 3
    state's."""
    from cpgbiped.envs.simulation.rollout import rollout

    res, rec, *_ = transition("ml", "walk", "run", 4.0, 0.0, 5.0, seed=3001)
    assert res["cpg_seed"] == 3001
    plain = rollout(build("ml", "walk", seed=3001), 3.9, poses=False, stop_on_fall=False)
    table3 = rollout(build("ml", "walk"), 3.9, poses=False, stop_on_fall=False)
    n = len(plain.t)
    assert np.allclose(rec.drive[:n], plain.drive, atol=1e-9)
    assert not np.allclose(rec.drive[:n], table3.drive, atol=1e-3)


def test_transition_json_and_pictures(tmp_path):
    out = tmp_path / "t.mp4"
    r = _cli("transition", "--from", "jump", "--to", "hop", "--at", "6", "--seconds", "12",
             "--json", "--out", str(out), "--rrd", str(tmp_path / "t.rrd"), "--fps", "10",
             "--width", "320", "--height", "240")
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    for key in ("before", "before_from_settling", "after", "fell", "cycles_to_switch"):
        assert key in res
    assert res["before"]["physical_gait"] and res["after"]["physical_gait"]
    assert out.stat().st_size > 10_000 and (tmp_path / "t_gait.png").stat().st_size > 5_000
    from cpgbiped.envs.media.record import read_rrd

    series = read_rrd(tmp_path / "t.rrd")
    key = next(k for k in series if k.endswith("/events/change"))
    assert np.allclose(series[key][0], [6.0])


@pytest.mark.parametrize("args,says", [
    (("transition", "--from", "skip", "--to", "run"), "--from"),
    (("transition", "--from", "walk", "--to", "gallop"), "--to"),
    (("transition", "--from", "walk", "--to", "run", "--at", "12", "--seconds", "10"), "outside"),
    (("transition", "--from", "walk", "--to", "run", "--at", "1"), "outside"),
    (("transition", "--from", "walk", "--to", "run", "--ramp", "-1"), ">= 0"),
    (("transition", "--from", "walk", "--to", "run", "--seed", "x"), "--seed"),
    (("transition", "--from", "walk", "--to", "run", "--network", "matsuoka"), "invalid choice"),
    (("transition", "--from", "walk", "--to", "run", "--network", "hopf", "--feedback"),
     "Morris-Lecar"),
    (("sweep", "--pair", "walk-hop"), "unknown sweep"),
    (("sweep", "--ramp-seconds", "1"), "[5, 200]"),
])
def test_bad_transition_input_is_one_line_and_exit_2(args, says):
    r = _cli(*args, timeout=120)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cpgbiped: error:") and says in lines[0]


def test_the_sweep_schedule_goes_up_holds_and_comes_down():
    s = schedule(10.0)
    assert list(s.at([0.0, 4.0, 9.0, 14.0, 16.0, 18.0, 23.0, 28.0, 40.0])) == pytest.approx(
        [0, 0, 0.5, 1, 1, 1, 0.5, 0, 0])


def test_a_switch_needs_persist_windows_in_a_row():
    ws = [{"g": g} for g in ("a", "b", "a", "b", "b", "b", "b")]
    assert _first_run(ws, lambda w: w["g"] == "b") is ws[3]
    assert PERSIST == 3
    assert _first_run(ws[:5], lambda w: w["g"] == "b") is None


def test_sweep_cli_writes_its_json_and_picture(tmp_path):
    r = _cli("sweep", "--pair", "walk-run", "--ramp-seconds", "10", "--json", "--out",
             str(tmp_path))
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    assert {"switch_up", "switch_down", "hysteresis_drive", "windows"} <= set(res)
    d = [w["drive"] for w in res["windows"]]
    assert min(d) == pytest.approx(0.0, abs=1e-9) and max(d) == pytest.approx(1.0, abs=1e-9)
    assert (tmp_path / "sweep_ml_walk-run.png").stat().st_size > 10_000
    # The window wholly before the ramp (1-4 s): the network's own cycle, read from its
    # activations, is the walk preset's Table 2 period (13.1 model units at the network's time
    # unit); the body's stride period, from the contacts, is that cycle's (its stance command is
    # the extensor's burst) up to the start-up's first steps in this window (6% open loop).
    w0 = res["windows"][0]
    assert w0["drive"] == 0.0 and w0["start_s"] + 3.0 <= 4.0 + 1e-9
    walk_period_s = build("ml", "walk").period_s()
    assert w0["cpg_period_s"] == pytest.approx(walk_period_s, rel=0.03)
    assert w0["stride_period_s"] == pytest.approx(walk_period_s, rel=0.10)
    assert w0["stride_length_m"] == pytest.approx(abs(w0["speed_mps"]) * w0["stride_period_s"])


def test_cycle_period_counts_upcrossings_of_the_stance_command_inside_the_window():
    t = np.arange(0.0, 10.0, 0.004)
    a = 0.5 + 0.5 * np.sin(2 * np.pi * t / 0.8 + 0.3)  # a cell's activation, period 0.8 s
    assert cycle_period(t, a, 2.0, 6.0) == pytest.approx(0.8, abs=0.005)
    assert cycle_period(t, a, 2.0, 2.5) is None  # fewer than two upcrossings


# -- issue 22's "done when", measured (README "Transitions"); strict xfails --------------------
# One protocol, the change at 8 s, open loop and with the recommended feedback gain (the issue
# asks for both); the time was never chosen for a passing case (README: 8-14 s, measured).
K_FB = RECOMMENDED["ml"]
IN_FAMILY_CASES = [(a, b, r, k) for a, b in sorted(IN_FAMILY) for r in (0.0, 2.0)
                   for k in (0.0, K_FB)]
IN_FAMILY_SHORTFALL = {
    # Since the recommended feedback became Taga's angle in alternating rhythms at K = 0.03
    # (session 40, scripts/feedback_choice.py) 4 of 16 passed: walk -> run and jump -> hop as
    # open-loop steps, run -> walk as a step and a ramp with feedback. Since the trunk's posture
    # is followed at a rate (pitch_tau_s, session 44) 7 of 16: run -> walk as a step and a ramp
    # with feedback, jump -> hop as a step either way and as an open-loop ramp, hop -> jump as a
    # step and a ramp with feedback; walk -> run as an open-loop step is lost. With Taga's thigh angle
    # at K = 0.01 (sessions 38-39) 6 of 16: walk -> run as an open-loop step, run -> walk as a
    # step with feedback, hop -> jump as a step and a ramp with feedback, jump -> hop as a step
    # either way; the gated pathway is near zero in the hop's and the jump's rhythms, so it no
    # longer carries hop -> jump in time (over 30 random states it still switches in 22 and 18:
    # README "Transitions"). Since the run corner's stiffer stance knee (session 50) 6 of 16:
    # walk -> run as a ramp with feedback is gained, jump -> hop open loop as a step and as a
    # ramp are lost.
    ("walk", "run", 0.0, 0.0): "falls at 10.0 s, 2.0 s after the change (a run 3 CPG cycles "
                               "after it, no fall, before pitch_tau_s)",
    ("walk", "run", 0.0, K_FB): "falls at 9.9 s, 1.9 s after the change (9.8 s before the run "
                                "corner's stiffer stance knee, session 50, the walk then named "
                                "none before it; 10.4 s at K = 0.01)",
    # walk -> run as an open-loop ramp: the network alone is still a walk 2-5 run periods
    # after the change began (test_network.py: ..._keeps_a_walk_past_four_cycles)
    ("walk", "run", 2.0, 0.0): "falls at 14.0 s, 4.0 s after the ramp ends; the network alone "
                               "is a walk to the 5th cycle",
    # run -> walk open loop: the network's own extensors burst in phase for cycles after the
    # change (test_from_the_run_to_the_walk_the_open_loop_network_hops_and_feedback_undoes_it)
    ("run", "walk", 0.0, 0.0): "falls at 19.8 s, 11.8 s after the change (at 9.7 s before the "
                               "run corner's stiffer stance knee, session 50; named a hop after "
                               "it, no fall, before sync_land); the network bursts both legs "
                               "together",
    ("run", "walk", 2.0, 0.0): "falls at 10.3 s, as the ramp ends; the network bursts both "
                               "legs together",
    # jump -> hop open loop: a hop 4 cycles after the change as a step and as a ramp in
    # sessions 44-49; since the run corner's stiffer stance knee (session 50) both fall (over
    # 21 re-rolls of the gains by nothing physical the step held in 9 of 21, against 6 before,
    # the ramp in 6 of 21, against 2)
    ("jump", "hop", 0.0, 0.0): "falls at 11.8 s, 3.8 s after the change",
    ("jump", "hop", 2.0, 0.0): "falls at 14.7 s, 4.7 s after the ramp ends",
    ("jump", "hop", 2.0, K_FB): "a hop 6 CPG cycles after the change, no fall (10 before "
                                "pitch_tau_s, 5 at K = 0.01)",
    # hop -> jump open loop: the network alone stays a hop for 12 cycles and more
    # (test_network.py: ..._the_network_stays_a_hop_for_a_dozen_cycles)
    ("hop", "jump", 0.0, 0.0): "no fall, still a hop 12 s after the change; the network alone "
                               "is a hop for 12 cycles",
    ("hop", "jump", 2.0, 0.0): "no fall, still a hop 12 s after the change; the network alone "
                               "is a hop for 12 cycles",
}


@pytest.mark.parametrize("a,b,ramp,k", [
    pytest.param(a, b, r, k, id=f"{a}-{b}-ramp{r:g}-K{k:g}", marks=[pytest.mark.xfail(
        raises=AssertionError, strict=True,
        reason=f"measured: {IN_FAMILY_SHORTFALL[a, b, r, k]}")]
        if (a, b, r, k) in IN_FAMILY_SHORTFALL else [])
    for a, b, r, k in IN_FAMILY_CASES])
def test_in_family_transition(a, b, ramp, k):
    _assert_issue_22_passes("ml", a, b, ramp, k)


def _assert_issue_22_passes(kind, a, b, ramp, k=0.0):
    """Issue 22: no fall; the physical gait before the change is A; after it, B within 4 CPG
    cycles of the change (at 8 s)."""
    from cpgbiped.envs.experiments.transition import default_seconds

    res, *_ = transition(kind, a, b, 8.0, ramp, default_seconds(a, b, 8.0, ramp), feedback=k)
    assert not res["fell"], res["fell_at_s"]
    assert res["before"]["physical_gait"] == a, res["before"]["physical_gait"]
    assert res["cycles_to_switch"] is not None and res["cycles_to_switch"] <= 4, res["windows"]


# Cross-family pairs (issue 22: at least 4 of the 8 reach their target): the change at 8 s, each
# pair run the four ways (step or 2 s ramp, open loop or the recommended feedback) for the
# command line's default length (30 s after the change: the network alone takes up to 300
# model units, 24 s, to lock to the other family's pattern). A pair is reached when one way
# settles in the target's physical gait without a fall (cycles_to_switch is set).
CROSS = [(a, b) for a in ("walk", "run", "jump", "hop") for b in ("walk", "run", "jump", "hop")
         if a != b and (a, b) not in IN_FAMILY]
CROSS_SHORTFALL = {
    # since the hop's corner and the walk's start-up corner (2026-12-06, session 35) hop -> run
    # is reached (a step with feedback, 15 cycles) and walk -> hop, run -> hop and jump -> run
    # fell all four ways at 8 s (each was reached at other change times, 9-14 s: README)
    # Since sync_land (session 38) walk -> hop (a ramp, 5 cycles) and run -> hop (a step, 5
    # cycles) are reached and run -> jump and hop -> run fall all four ways: 5 of 8 as before
    # Since the gated angle at K = 0.03 became the recommended feedback (session 40) walk -> jump
    # falls all four ways as well: 4 of 8 (walk -> hop, run -> hop, jump -> walk, hop -> walk);
    # hop -> run is reached at none of the change times 8-14 s now
    # Since pitch_tau_s (session 44) jump -> run (a step with feedback, 14 cycles) and hop -> run
    # (a ramp with feedback, 34 cycles) are reached: 6 of 8
    # Since the run corner's stiffer stance knee (session 50) neither is: 4 of 8, the target's
    # 4 (over 21 re-rolls of the gains by nothing physical jump -> run is reached in 4 of 21
    # against 8, hop -> run in 9 against 2; cross-family 4.57 -> 4.81 on average)
    ("walk", "jump"): "falls all four ways, at 9.4, 10.5, 10.7 and 10.9 s (step, step with "
                      "feedback, ramp, ramp with feedback; reached as a ramp with feedback at "
                      "K = 0.01, 23 cycles)",
    ("run", "jump"): "falls all four ways, at 9.2, 10.8, 10.3 and 10.9 s (step, step with "
                     "feedback, ramp, ramp with feedback)",
    ("jump", "run"): "a hop, no fall, as an open-loop step; falls the other three ways, at 14.6, "
                     "10.0 and 16.5 s (step with feedback, ramp, ramp with feedback)",
    ("hop", "run"): "falls all four ways, at 19.5, 21.6, 25.9 and 26.3 s (step, step with "
                    "feedback, ramp, ramp with feedback)",
}


@pytest.mark.parametrize("a,b", [
    pytest.param(a, b, id=f"{a}-{b}", marks=[pytest.mark.xfail(
        raises=AssertionError, strict=True, reason=f"measured: {CROSS_SHORTFALL[a, b]}")]
        if (a, b) in CROSS_SHORTFALL else []) for a, b in CROSS])
def test_cross_family_pair_is_reached_in_one_of_four_ways(a, b):
    from cpgbiped.envs.experiments.transition import default_seconds

    outcomes = []
    for ramp in (0.0, 2.0):
        for k in (0.0, K_FB):
            res, *_ = transition("ml", a, b, 8.0, ramp, default_seconds(a, b, 8.0, ramp),
                                 feedback=k)
            outcomes.append((ramp, k, res["fell_at_s"], res["after"]["physical_gait"]))
            if res["cycles_to_switch"] is not None:  # B settled, no fall
                return
    raise AssertionError(outcomes)


def test_the_default_rollout_across_the_families_covers_the_network_s_lock_time():
    """Issue 22: the network alone takes up to 300 model units to lock to a new pattern; at
    12.3 units/s, plus a settled window of 3 cycles and one more of the slowest target (the
    walk, 13.113 units, Table 2 as reproduced), that is 28.7 s after the change."""
    from cpgbiped.envs.experiments.transition import default_seconds

    need = 300 / 12.3 + (3 + 1) * 13.113 / 12.3
    for a, b in (("hop", "walk"), ("jump", "run"), ("walk", "hop")):
        assert default_seconds(a, b, 8.0, 2.0) - 10.0 >= need
    assert default_seconds("walk", "run", 8.0, 2.0) < default_seconds("walk", "hop", 8.0, 2.0)


def test_the_transition_says_what_the_network_alone_does():
    """The result's network_alone: the same change without a body. From the run to the walk
    the network is still in the hop's pattern 4 cycles after the change, from the jump to the
    hop it is a hop by then; checked against the CPG classifier on the controller's own
    integration of the network (cpg_schedule, another sampling of the same equations) over the
    window of 4 cycles that starts 4 cycles after the change."""
    from cpgbiped.cpg.gaits import classify
    from cpgbiped.envs.control.controller import cpg_schedule

    for a, b, want in (("run", "walk", "hop"), ("jump", "hop", "hop")):
        res, *_ = transition("ml", a, b, 8.0, 0.0, 12.0)
        na = res["network_alone"]
        net, to = build("ml", a), build("ml", b)
        T = to.period_s()
        s = cpg_schedule(net, 8.0 + 9 * T, to=to, change=Schedule.change(8.0, 0.0))
        t = np.arange(len(s.v)) * s.dt_s
        w = (t >= 8.0 + 4 * T) & (t < 8.0 + 8 * T)
        assert classify(t[w], s.v[w])[0] == want == na["windows"][4], (a, b, na)
        within = na["cycles_to_switch"] is not None and na["cycles_to_switch"] <= 4
        assert within == (want == b), na


def test_extensor_synchrony_is_zero_for_alternating_and_one_for_in_phase_bursts():
    """On square bursts made here: the legs' extensors half a cycle apart share no time; in
    phase they share all of it; a quarter cycle apart, a third of the time either bursts
    (both for 1/4 of a cycle, either for 3/4)."""
    from cpgbiped.envs.experiments.transition import extensor_synchrony

    t = np.arange(0.0, 10.0, 0.001)
    burst = lambda lag: ((t / 1.0 + lag) % 1.0 < 0.5).astype(float)  # noqa: E731
    for lag, want in ((0.5, 0.0), (0.0, 1.0), (0.25, 1 / 3)):
        act = np.column_stack([np.zeros_like(t), np.zeros_like(t), burst(0.0), burst(lag)])
        got = extensor_synchrony(t, act, 2.0, 1.0, n=5)
        assert np.allclose(got, want, atol=0.01), (lag, got)
    assert extensor_synchrony(t, act, 8.0, 1.0, n=3)[2] is None  # past the recording


@pytest.mark.parametrize("ramp", [0.0, 2.0])
def test_from_the_run_to_the_walk_the_open_loop_network_hops_and_feedback_undoes_it(ramp):
    """Why run -> walk cannot pass issue 22's test open loop with the Morris-Lecar network,
    whatever the body does: moved from the run's parameters to the walk's, the network's own
    extensors burst in phase (a hop's pattern) in the third and fourth CPG cycles after the
    change, inside the four cycles the test allows for a walk (measured: to the eighth and
    beyond; the CPG classifier names hop in the 2nd-4th cycles, tests/test_network.py).
    The network stepped tick by tick without input does the same (the closed loop's
    integrator is not what differs); with the body's feedback at the recommended gain the
    bursts alternate by then; the Hopf network, swapped in, alternates them open loop."""
    from cpgbiped.envs.experiments.transition import extensor_synchrony

    ml, *_ = transition("ml", "run", "walk", 8.0, ramp, 8.0 + ramp + 6.0)
    assert min(ml["cpg_extensor_synchrony"][2:4]) > 0.9, ml["cpg_extensor_synchrony"]
    a, b = build("ml", "run"), build("ml", "walk")
    n = int((8.0 + ramp + 6.0) / 0.004)
    v = run_open(loop_network(a, 0.0, 0.004, n * 0.004, to=b,
                              change=Schedule.change(8.0, ramp)), n)
    stepped = extensor_synchrony(np.arange(n + 1) * 0.004, a.activation(v), 8.0,
                                 b.period() / b.units_per_s)
    assert min(stepped[2:4]) > 0.9, stepped
    fb, *_ = transition("ml", "run", "walk", 8.0, ramp, 8.0 + ramp + 6.0, feedback=K_FB)
    assert max(fb["cpg_extensor_synchrony"][2:4]) < 0.1, fb["cpg_extensor_synchrony"]
    hopf, *_ = transition("hopf", "run", "walk", 8.0, ramp, 8.0 + ramp + 6.0)
    assert all(x is None or x < 0.2 for x in hopf["cpg_extensor_synchrony"][2:4]), \
        hopf["cpg_extensor_synchrony"]


# The Hopf network's in-family transitions, open loop (its closed loop refuses a parameter
# change), at the same 8 s protocol; measured shortfalls of the ones that do not pass.
HOPF_SHORTFALL = {
    ("walk", "run", 0.0): "a run 9 CPG cycles after the change (4 asked), no fall; the "
                          "Hopf network alone is a run from the 8th",
    ("walk", "run", 2.0): "falls at 10.4 s, as the ramp ends (10.3 s in sessions 44-49, 10.4 s "
                          "in 40-43; since the walk's stance knee; a run after 2 cycles "
                          "before)",
    # re-measured after the hop's corner and the walk's start-up corner (2026-12-06, session
    # 36): run -> walk fell at 8.5 and 9.5 s before it too; jump -> hop at 8.4 s, hop -> jump
    # at 14.9 and 17.5 s (before the run's swing clearance, session 34: run -> walk 8.6 and 9.0
    # s, jump -> hop 8.7 and 8.8 s, hop -> jump 15.0 and 13.5 s)
    ("run", "walk", 0.0): "falls at 8.5 s, 0.5 s after the change; the network's bursts "
                          "alternate from the change on: the body's failure",
    ("run", "walk", 2.0): "falls at 9.5 s, during the ramp",
    # until pitch_tau_s (session 44) the Hopf jump fell at 6.5 s without a change too, and so
    # both ways from it fell before the change; in sessions 44-49 jump -> hop fell at 9.9 s as
    # a step and was a hop 15 cycles after the change as a ramp; since the run corner's stiffer
    # stance knee (session 50) the Hopf jump falls at 8.8 s without a change (named a skip
    # before it), and both ways with it
    ("jump", "hop", 0.0): "falls at 8.8 s, as it does without a change; named a skip before it",
    ("jump", "hop", 2.0): "falls at 8.8 s, as it does without a change; named a skip before it",
    ("hop", "jump", 0.0): "falls at 11.6 s, 3.6 s after the change (12.0 s in sessions 44-49, "
                          "16.9 s before pitch_tau_s)",
    ("hop", "jump", 2.0): "falls at 12.5 s, 2.5 s after the ramp ends (13.7 s in sessions "
                          "44-49, 14.5 s before)",
}


@pytest.mark.parametrize("a,b,ramp", [
    pytest.param(a, b, r, id=f"hopf-{a}-{b}-ramp{r:g}", marks=[pytest.mark.xfail(
        raises=AssertionError, strict=True, reason=f"measured: {HOPF_SHORTFALL[a, b, r]}")]
        if (a, b, r) in HOPF_SHORTFALL else [])
    for a, b in (("walk", "run"), ("run", "walk"), ("jump", "hop"), ("hop", "jump"))
    for r in (0.0, 2.0)])
def test_hopf_in_family_transition(a, b, ramp):
    """Issue 22's test with the Hopf network driving the same controller."""
    _assert_issue_22_passes("hopf", a, b, ramp)


# -- secondary gaits in the body ---------------------------------------------------------------
def _secondary_file(tmp_path, **change):
    from cpgbiped.cpg.morris_lecar import DIRECTED_NAMES, directed_vector, preset, weight_matrix

    p = preset("walk")
    w = directed_vector(weight_matrix(np.array(p.weights)))
    t = {"target": "skip", "source": "walk", "i_app": p.i_app, "phi": p.phi,
         "directed_weights": dict(zip(DIRECTED_NAMES, w.tolist())), "found": False}
    t.update(change)
    path = tmp_path / "secondary.json"
    path.write_text(json.dumps({"format": "cpgbiped.secondary/1", "targets": [t]}))
    return path


def test_check_secondary_runs_each_weight_set_through_the_body(tmp_path):
    """The walk's own weights written as a 'skip' target: the body and the CPG both walk (the
    contacts name the walk preset none, its duty shortfall), so nothing is confirmed."""
    r = _cli("check-secondary", str(_secondary_file(tmp_path)), "--seconds", "5", "--json")
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    row = res["skip"]
    assert row["cpg_gait"] == "walk" and row["confirmed"] is False
    assert {"physical_gait", "fell", "duty_factor", "lr_phase_lag"} <= set(row)


def test_check_secondary_table_names_each_set_by_its_source_and_shows_its_speed():
    """The table says which primary gait each set breaks (the JSON's first key of a target
    does not) and the body's speed with its sign: a hesitation walk that walks backwards reads
    as one."""
    from cpgbiped.envs.experiments.secondary_check import table

    row = {"found_in_network": True, "cpg_gait": "hesitation_walk",
           "physical_gait": "hesitation_walk", "fell": False, "lr_phase_lag": 0.36,
           "flight": 0.0, "speed_mps": -0.25, "confirmed": True}
    text = table({"hesitation_walk": {**row, "source": "jump"},
                  "hesitation_walk from run": {**row, "source": "run", "confirmed": False}})
    lines = text.splitlines()
    assert "speed m/s" in lines[0]
    assert "hesitation_walk from jump" in lines[2] and "-0.25" in lines[2]
    assert "CONFIRMED" in lines[2] and "from run from" not in text


def test_check_secondary_draws_every_rollout_with_out(tmp_path):
    """--out: the results as JSON and, for each weight set, a chronophotograph of its rollout,
    all of them in one panel (two per row, the widest scaled to the panel's column)."""
    from PIL import Image

    from cpgbiped.envs.experiments.secondary_check import PANEL_WIDTH_PX

    (tmp_path / "hop").mkdir()
    hop = json.loads(_secondary_file(tmp_path / "hop", target="asymmetric_hop",
                                     source="hop").read_text())["targets"][0]
    path = _secondary_file(tmp_path)
    data = json.loads(path.read_text())
    data["targets"].append(hop)
    path.write_text(json.dumps(data))
    out = tmp_path / "check"
    r = _cli("check-secondary", str(path), "--seconds", "3", "--out", str(out))
    assert r.returncode == 0, r.stderr
    res = json.loads((out / "check_secondary.json").read_text())
    assert set(res) == {"skip", "asymmetric_hop"}
    for stem in ("skip_from_walk", "asymmetric_hop_from_hop"):
        with Image.open(out / f"{stem}_chrono.png") as im:
            assert im.format == "PNG" and im.width > 300 and im.height > 300
    with Image.open(out / "secondary_chrono.png") as im:
        assert im.width == 2 * PANEL_WIDTH_PX  # two panels side by side


def test_check_secondary_counts_random_states(tmp_path):
    """--states N: every weight set also from N random CPG states, seeds 3000 and up; a
    weight set that is the walk's own cannot be a skip in any of them."""
    r = _cli("check-secondary", str(_secondary_file(tmp_path)), "--seconds", "4", "--states",
             "2", "--json")
    assert r.returncode == 0, r.stderr
    rs = json.loads(r.stdout)["skip"]["random_states"]
    assert rs["seeds"] == [3000, 3001] and rs["confirmed"] == 0
    assert len(rs["physical_gaits"]) == 2
    r = _cli("check-secondary", str(_secondary_file(tmp_path)), "--states", "101", timeout=60)
    assert r.returncode == 2 and "--states must be at most 100" in r.stderr


def test_merge_secondary_keeps_per_target_the_set_the_body_confirms_more_often(tmp_path,
                                                                                monkeypatch):
    """scripts/merge_secondary.py: B's set replaces A's for a target only with more
    confirmations, or as many and fewer falls (with --max-extra-falls, not bought with more
    falls than that; with --by net, more confirmations net of falls); a tie or a target B
    lacks keeps A's. End to end on a one-target pair of
    files (the walk's own weights named a skip, which no state confirms): the tie keeps A's
    set, the body is driven from exactly the states asked for, and the merged file is a
    secondary results file that check-secondary reads. Seeds of the tests or the tuning are
    refused before any rollout."""
    import importlib.util

    import cpgbiped.envs.experiments.secondary_check as sc

    spec = importlib.util.spec_from_file_location(
        "merge_secondary", Path(__file__).parents[1] / "scripts" / "merge_secondary.py")
    ms = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ms)
    assert ms.take_b((0, 9), (2, 27)) and ms.take_b((19, 2), (19, 1))
    assert not ms.take_b((9, 5), (7, 0)) and not ms.take_b((3, 1), (3, 1))
    assert not ms.take_b((0, 0), None)
    assert not ms.take_b((0, 9), (2, 27), max_extra_falls=1)  # bought with 18 falls
    assert ms.take_b((0, 4), (25, 5), max_extra_falls=1) and ms.take_b((19, 2), (21, 0), 1)
    # --by net: confirmations net of falls, the product's own selection criterion
    assert not ms.take_b((0, 9), (2, 27), by="net")  # -25 against -9
    assert ms.take_b((0, 4), (22, 8), by="net") and ms.take_b((9, 5), (7, 0), by="net")
    assert ms.take_b((3, 3), (5, 5), by="net") is False  # same net, more falls: A
    assert ms.take_b((5, 5), (3, 3), by="net") and not ms.take_b((0, 0), None, by="net")
    a = _secondary_file(tmp_path)
    (tmp_path / "b").mkdir()
    b = _secondary_file(tmp_path / "b", i_app=0.2)
    out = tmp_path / "merged.json"
    used = []
    real = sc.check_secondary

    def spy(path, *args, **kw):
        res = real(path, *args, **kw)
        used.extend(r["random_states"]["seeds"] for r in res.values())
        return res

    monkeypatch.setattr(sc, "check_secondary", spy)
    assert ms.main([str(a), str(b), "--first", "5330", "--n", "1", "--seconds", "2",
                    "--workers", "1", "--out", str(out)]) == 0
    assert used == [[5330], [5330]]  # each file's one set, from the one state asked for
    (t,) = json.loads(out.read_text())["targets"]
    assert t["merged_from"]["file"] == str(a) and t["merged_from"]["seeds"] == [5330, 5330]
    assert t["i_app"] == json.loads(a.read_text())["targets"][0]["i_app"]
    assert len(sc.load_secondary(out)) == 1
    for bad in (["--first", "1090", "--n", "20"], ["--first", "5330", "--n", "0"],
                ["--first", "5330", "--by", "net", "--max-extra-falls", "1"]):
        with pytest.raises(SystemExit) as e:
            ms.main([str(a), str(b), *bad, "--out", str(tmp_path / "x.json")])
        assert e.value.code == 2
    assert not (tmp_path / "x.json").exists()


@pytest.mark.parametrize("args,says", [
    (["--physics", "--states", "33"], "--states must be at most 32"),
    (["--states", "3"], "need --physics"),
    (["--workers", "1"], "need --physics"),
])
def test_secondary_physics_options_are_checked_first(tmp_path, args, says):
    r = _cli("secondary", *args, "--out", str(tmp_path / "s"), timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert says in r.stderr and not (tmp_path / "s").exists()


# The weight sets that the body chose, on states the tests never use: `cpgbiped secondary
# --physics` (seed 0) of 2026-12-05 for most targets, and, merged in by a rule written before
# its run (session 41, scripts/merge_secondary.py --by net, decided on CPG seeds 5520-5549,
# judged on 5550-5579), the hesitation walk from the jump of the 16-state re-selection of
# session 40; the commands are in the file. The body judges them here from the Table 3 state,
# which no selection or merge used.
PHYSICS_SECONDARY = Path(__file__).parent / "data" / "secondary_physics.json"
# History: the committed hesitation walk from the jump fell from the Table 3 state from session
# 35 to sync_land (session 38) and was named none there after it; the gallop from the walk was
# confirmed there from session 35 to sync_land and fell there from then to session 49
# (confirmed in 11 of the 30 random states 3000-3029); since the run corner's stiffer stance
# knee (session 50) it does not fall there but the contacts name none.
PHYSICS_SHORTFALL: dict = {
    ("gallop", "walk"): "named none by the contacts from the Table 3 state, no fall (lag 0.41, "
                        "flight 0.19; the CPG names a gallop); confirmed in 11 of 30 random "
                        "states in session 41",
}


@pytest.mark.parametrize("target,source", [
    pytest.param(*t, id=f"{t[0]}-from-{t[1]}",
                 marks=[pytest.mark.xfail(raises=AssertionError, strict=True,
                                          reason=f"measured: {PHYSICS_SHORTFALL[t]}")]
                 if t in PHYSICS_SHORTFALL else [])
    for t in (("hesitation_walk", "jump"), ("gallop", "jump"), ("gallop", "walk"))])
def test_a_secondary_gait_chosen_by_the_body_is_confirmed_from_the_table3_state(target, source):
    """Issue 22: a secondary gait confirmed physically: both classifiers name the target and
    the body does not fall. Two distinct secondary gaits are asked for: the hesitation walk and
    the gallop from the jump (the targets the body confirms from most random states: 26 and 24
    of 3000-3029) are both expected from the Table 3 state, which chose neither; the gallop
    from the walk is a measured shortfall (PHYSICS_SHORTFALL)."""
    from cpgbiped.envs.experiments.secondary_check import _one, load_secondary

    (t,) = [t for t in load_secondary(PHYSICS_SECONDARY)
            if (t["target"], t["source"]) == (target, source)]
    row = _one((t, 20.0, None, None))
    assert row["confirmed"], (row["cpg_gait"], row["physical_gait"], row["fell"],
                              row["lr_phase_lag"])


def test_check_secondary_out_is_all_or_nothing(tmp_path):
    """A malformed file with --out: the one-line error, and no folder."""
    out = tmp_path / "check"
    r = _cli("check-secondary", str(_secondary_file(tmp_path, phi=-1.0)), "--out", str(out),
             timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("change,says", [
    ({"source": "gallop"}, "at targets/0/source"),
    ({"i_app": "0.2"}, "at targets/0/i_app"),
    ({"phi": True}, "at targets/0/phi"),
    ({"phi": -1.0}, "at targets/0/phi"),
    ({"directed_weights": {"w_LF->RF": 1.0}}, "at targets/0/directed_weights"),
    ({"i_app": float("nan")}, "not finite at targets/0/i_app"),
])
def test_malformed_secondary_files_fail_before_any_rollout(tmp_path, change, says):
    r = _cli("check-secondary", str(_secondary_file(tmp_path, **change)), timeout=60)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cpgbiped: error:") and says in lines[0]


def test_a_file_that_is_not_a_secondary_result_is_refused(tmp_path):
    p = tmp_path / "x.json"
    p.write_text(json.dumps({"format": "cpgbiped.result/1", "targets": []}))
    r = _cli("check-secondary", str(p), timeout=60)
    assert r.returncode == 2 and "is not a cpgbiped secondary results file (format" in r.stderr
