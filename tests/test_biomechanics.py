"""Biomechanics from a real rollout, recomputed here independently of the recorder."""
import numpy as np
import pytest

from cpgbiped.cpg.network import build
from cpgbiped.envs.simulation.biped import body_constants, load_model
from cpgbiped.envs.gaits.gait_metrics import G
from cpgbiped.envs.gaits.validate import validate
from cpgbiped.envs.simulation.rollout import rollout


@pytest.fixture(scope="module")
def walk():
    return validate(build("ml", "walk"), "walk", 10.0)


def test_froude_from_distance_and_duration(walk):
    s, rec = walk.summary(), walk.recording
    sel = rec.t >= walk.settle_s
    v = (rec.com_x[sel][-1] - rec.com_x[sel][0]) / (rec.t[sel][-1] - rec.t[sel][0])
    import mujoco

    m = load_model()
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    L = d.xanchor[m.joint("left_hip").id, 2]  # the standing hip height
    assert L == pytest.approx(0.862, abs=1e-6)  # the torso's height in biped.xml
    assert s["froude"] == pytest.approx(v * v / (G * L), rel=1e-6)


def test_apex_from_the_recorded_com_height():
    """The hop's apex against ballistics, not against the library's own algorithm: in a flight
    the centre of mass rises v^2 / (2 g) above its take-off height, v its vertical speed at
    take-off. Flights here come from the raw contact forces (no debounce), 40 ms or longer;
    take-off speeds from central differences of the recorded height. (The hop: the two-legged
    gait with the most regular flights, README "Status".)"""
    v = validate(build("ml", "hop"), "hop", 10.0)
    rec = v.recording
    sel = np.flatnonzero(rec.t >= v.settle_s)
    air = ~(rec.force > 1.0).any(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], air[sel].astype(int), [0]])))
    rises = []
    for a, b in zip(edges[::2], edges[1::2]):
        if (b - a) * rec.dt >= 0.04 and 0 < a:
            k = sel[a]
            vz = (rec.com_z[k + 1] - rec.com_z[k - 1]) / (2 * rec.dt)
            if vz > 0:
                rises.append(vz * vz / (2 * G))
    assert len(rises) >= 3, "too few flights"
    apex = v.summary()["apex_height_m"]
    assert apex == pytest.approx(float(np.median(rises)), rel=0.3, abs=0.004)


def test_cost_of_transport_from_force_times_velocity(walk):
    """Rebuild each actuator's torque from what was recorded - the motors' controls x gear, the
    muscles' activation x (F0 - K q) within their force range - and each joint's velocity
    from the recorded angles, then CoT = sum max(tau omega, 0) dt / (m g distance)."""
    rec = walk.recording
    m = load_model()
    sel = rec.t >= walk.settle_s
    dt = rec.dt
    omega = np.gradient(rec.qpos[:, m.jnt_qposadr[m.actuator_trnid[:, 0]]], rec.t, axis=0)
    tau = np.empty((len(rec.t), m.nu))
    for a in range(m.nu):
        if a < 4:  # the ankle muscles (general, affine gain in the joint angle)
            q = rec.qpos[:, m.jnt_qposadr[m.actuator_trnid[a, 0]]]
            f = rec.muscle_activation[:, a] * (m.actuator_gainprm[a, 0] + m.actuator_gainprm[a, 1] * q)
            tau[:, a] = np.clip(f, *m.actuator_forcerange[a])
        else:
            tau[:, a] = m.actuator_gear[a, 0] * np.clip(rec.ctrl[:, a], -1, 1)
    work = np.maximum(tau * omega, 0)[sel].sum() * dt
    _, mass, _, _ = body_constants()
    s = walk.summary()
    assert s["positive_work_J"] == pytest.approx(work, rel=0.1)
    assert s["cost_of_transport"] == pytest.approx(work / (mass * G * abs(s["distance_m"])),
                                                   rel=0.1)


def test_recorded_ground_force_accounts_for_the_momentum():
    """Newton's second law on the whole body: the feet are the only things touching the floor,
    so the horizontal ground reaction forces the recorder logs must add up to the change of
    the body's momentum, m (v_B - v_A), with each window's mean speed taken from the recorded
    centre-of-mass positions alone. The run, from standing (0-1 s) to full speed (7-8 s): a
    change of about 33 N s. Each tick's force is the mean over its two physics steps, so the
    balance closes to the integration's own error: within 2% (0.4% measured; 6% when one
    step per tick was sampled, before 2026-12-06); a force with its sign turned would miss by
    200%."""
    rec = validate(build("ml", "run"), "run", 7.0).recording
    _, mass, _, _ = body_constants()
    impulse = np.cumsum(rec.grf_x.sum(axis=1)) * rec.dt  # N s from t = 0

    def window(t0, t1):
        i0, i1 = np.searchsorted(rec.t, t0), np.searchsorted(rec.t, t1)
        return i0, i1, (rec.com_x[i1] - rec.com_x[i0]) / (rec.t[i1] - rec.t[i0])

    a0, a1, v_a = window(0.0, 1.0)
    b0, b1, v_b = window(7.0, 8.0)
    n = min(a1 - a0, b1 - b0)
    # mean over s in [0, T) of J(t_B + s) - J(t_A + s) = m (mean v over B - mean v over A)
    from_forces = float(np.mean(impulse[b0:b0 + n] - impulse[a0:a0 + n]))
    assert mass * (v_b - v_a) > 15.0  # the run did speed up
    assert from_forces == pytest.approx(mass * (v_b - v_a), rel=0.02)


def test_stance_impulses_split_each_stance_at_its_middle():
    """Hand-made contacts and forces (dt 10 ms). Left foot: a touchdown bounce (tick 3), a
    one-tick gap (tick 4, shorter than the 30 ms debounce, so it is closed and the bounce's
    braking counts), then contact to tick 12: a 10-tick stance, ticks 3-7 its first half at
    -100 N (the gap carries no force), ticks 8-12 its second at +50 N. Right foot: a 6-tick
    stance at +20 N, a 2-tick scuff at -300 N (shorter than half the 75th percentile of the
    stances' 10, 6 and 2 ticks: a touch, not a stance), and a stance cut by the window's end,
    which is left out."""
    from cpgbiped.envs.gaits.gait_metrics import stance_impulses

    dt = 0.01
    c = np.zeros((30, 2), bool)
    f = np.zeros((30, 2))
    c[3, 0] = True
    c[5:13, 0] = True
    f[[3, 5, 6, 7], 0] = -100.0
    f[8:13, 0] = 50.0
    c[10:16, 1] = True
    f[10:16, 1] = 20.0
    c[20:22, 1] = True
    f[20:22, 1] = -300.0
    c[27:, 1] = True
    f[27:, 1] = 999.0
    first, second, touches = stance_impulses(c, f, dt)
    # stances: left (4 x -1.0, 5 x +0.5) = (-4.0, +2.5) N s, right (0.6, 0.6) N s; the
    # medians of two values are their means
    assert first == pytest.approx((-4.0 + 0.6) / 2)
    assert second == pytest.approx((2.5 + 0.6) / 2)
    assert touches == pytest.approx(2 * -300.0 * dt / 2)  # -6 N s over the 2 stances counted


def test_the_run_brakes_then_propels():
    """A gait moving forwards at a steady speed brakes in the first half of each stance and
    propels in the second (Cavagna et al. 1976 for human running). (The hop's pattern, which
    pushed backwards at take-off until session 35 and brakes then propels since, is a
    measurement the README reports, not an expectation.)"""
    run = validate(build("ml", "run"), "run", 8.0).summary()
    assert run["stance_impulse_first_half_Ns"] < 0 < run["stance_impulse_second_half_Ns"]


@pytest.mark.parametrize("push", [
    pytest.param(None, id="none"), pytest.param((6.0, 10.0, 0.2), id="held+10"),
    pytest.param((6.0, -10.0, 0.2), id="held-10"), pytest.param((6.0, 10.0), id="blow+10")])
def test_a_push_delivers_its_impulse(push):
    """Newton's second law across a push: the change of the walk's momentum between the
    stride before the push and the stride after it (mean speeds from the centre of mass), less
    the ground's horizontal impulse over the same time (from the recorded contact forces, each
    tick's the mean over its two physics steps), is the push's impulse (0 without one),
    whether its force is held 0.2 s or struck in one 4 ms tick. Within 0.5 N s: a force held
    for one tick at impulse / 0.2 s would deliver 0.2 N s, one held 0.2 s at impulse / 4 ms
    500 N s; with the force sampled at one of a tick's two steps (before 2026-12-06) the
    estimate read -1.6 N s unpushed and 6.0 for +10 N s (a landing's impact aliased).
    """
    rec = rollout(build("ml", "walk"), 9.0, push=push, poses=False)
    _, mass, _, _ = body_constants()
    ground = np.cumsum(rec.grf_x.sum(axis=1)) * rec.dt

    def window(t0, t1):
        i0, i1 = np.searchsorted(rec.t, t0), np.searchsorted(rec.t, t1)
        return i0, i1, (rec.com_x[i1] - rec.com_x[i0]) / (rec.t[i1] - rec.t[i0])

    a0, a1, v_a = window(4.9, 5.97)  # about one stride (1.07 s) before the push
    b0, b1, v_b = window(6.3, 7.37)  # ... and one after its force has ended
    n = min(a1 - a0, b1 - b0)
    from_ground = float(np.mean(ground[b0:b0 + n] - ground[a0:a0 + n]))
    assert rec.fell_at is None
    assert mass * (v_b - v_a) - from_ground == pytest.approx(push[1] if push else 0.0, abs=0.5)


def test_a_held_push_gives_the_same_rows_in_the_compiled_and_the_python_loop():
    """The force held over whole control ticks in both tick loops, open and closed loop."""
    net = build("ml", "run")
    for K in (0.0, 0.01):
        a, b = (rollout(net, 3.0, push=(2.2, -6.0, 0.2), poses=p, feedback=K)
                for p in (False, True))
        assert np.array_equal(a.com_x, b.com_x) and np.array_equal(a.ctrl, b.ctrl), K


@pytest.mark.parametrize("gait", ["walk", "run", "jump", "hop"])
def test_the_vertical_ground_force_carries_the_weight(gait):
    """Newton's second law, vertically, on the whole body: over the window, the mean of the
    feet's vertical ground reaction forces is the body's weight plus m times the change of the
    centre of mass's vertical speed over the window's length, mean F_z / (m g) = 1 + dv_z /
    (g T). Within 0.002 of it (each tick's force the mean over its two physics steps: measured
    within 0.0001 in all four gaits; the force at one of the two steps, as the contact column
    records it, misses by 0.0024-0.0042 in the walk, the jump and the hop)."""
    v = validate(build("ml", gait), gait, 20.0)
    rec = v.recording
    _, mass, _, _ = body_constants()
    sel = np.nonzero(rec.t >= v.settle_s)[0]
    i0, i1 = sel[0], sel[-1]
    vz = np.gradient(rec.com_z, rec.t)
    expected = 1.0 + (vz[i1] - vz[i0]) / (G * (rec.t[i1] - rec.t[i0]))
    assert rec.fell_at is None
    assert rec.grf_z[sel].sum(axis=1).mean() / (mass * G) == pytest.approx(expected, abs=0.002)


def test_each_row_s_force_is_the_mean_of_its_own_tick_s_steps():
    """Row k of grf_z is the mean of the vertical force over tick k's two physics steps; row k
    of the contact column's force is that of the tick's last step alone (the sensor read when
    the row is recorded). Contact forces are never negative, so grf_z >= force / 2 in every
    row, with equality in a loaded row only where the foot touched down at the tick's second
    step (its first carried nothing): a recorder that wrote the sum of one tick into the row
    of the next or the last would break the inequality at each landing (a row shifted by one
    tick: -177 to -284 N, a review's measurement), as would a sign error; one that summed
    instead of averaging, or averaged over other steps, would leave no loaded row at equality."""
    rec = rollout(build("ml", "walk"), 4.0, poses=False)
    gap = rec.grf_z - rec.force / 2.0
    assert gap.min() >= -1e-9, gap.min()
    loaded = rec.force > 1.0
    assert np.isclose(gap[loaded], 0.0, atol=1e-9).any()  # touchdowns at a tick's second step


def test_vertical_force_peaks_by_hand():
    """Hand-made contacts and vertical forces (dt 10 ms, weight 100 N). Left foot: a 10-tick
    stance whose force rises to 300 N at its second tick (an impact, (1 + 0.5) / 10 = 0.15 of
    the way) and holds 100 N after; right foot: a 10-tick stance with a 200 N peak at its
    sixth tick (0.55), and, 60 ms later (a gap longer than the 30 ms closed), a 2-tick touch
    at 900 N that is not a stance. Medians of two: a peak of 2.5 body weights at 0.35 of the
    stance."""
    from cpgbiped.envs.gaits.gait_metrics import vertical_force_peaks

    c = np.zeros((40, 2), bool)
    f = np.zeros((40, 2))
    c[2:12, 0] = True
    f[2:12, 0] = 100.0
    f[3, 0] = 300.0
    c[14:24, 1] = True
    f[14:24, 1] = 50.0
    f[19, 1] = 200.0
    c[30:32, 1] = True
    f[30:32, 1] = 900.0
    peak, when = vertical_force_peaks(c, f, 0.01, 100.0)
    assert peak == pytest.approx((3.0 + 2.0) / 2)
    assert when == pytest.approx((0.15 + 0.55) / 2)


def test_foot_edges_are_mujoco_s_own_site_positions(walk):
    """The toe and heel x that the margins of stability use, rebuilt from the recorded body
    quaternions, against MuJoCo's forward kinematics of the recorded joint positions (its
    site_xpos), at every 50th tick of a walk: within a micrometre."""
    import mujoco

    from cpgbiped.envs.simulation.biped import foot_edges_x

    rec = walk.recording
    toe_x, heel_x = foot_edges_x(rec.body_pose, rec.xml_path)
    m = mujoco.MjModel.from_xml_path(rec.xml_path)
    d = mujoco.MjData(m)
    for k in range(0, len(rec.t), 50):
        d.qpos[:] = rec.qpos[k]
        mujoco.mj_kinematics(m, d)
        for leg, side in enumerate(("left", "right")):
            assert toe_x[k, leg] == pytest.approx(d.site(side + "_toe").xpos[0], abs=1e-6)
            assert heel_x[k, leg] == pytest.approx(d.site(side + "_heel").xpos[0], abs=1e-6)


def test_gaits_that_travel_carry_their_extrapolated_com_past_the_toes():
    """Hof's extrapolated centre of mass x + v / omega (omega = sqrt(g / z)) runs ahead of the
    centre of mass by v / omega: about 0.27 m at the walk's 0.97 m/s and its 0.74 m stance
    height, 0.4 m at the run's 1.5 m/s. The stance toes reach only a few centimetres ahead of
    the centre of mass at best, so a walk and a run hold their XcoM well past the stance toes
    (forward margin below minus half of v / omega: a margin taken from the centre of mass
    alone, about -0.03 m, would fail this), while the jump and the hop, which hardly travel
    and whose balance reflex holds the centre of mass over the ball of the foot, keep it inside
    their feet (both margins > 0). Table 3 states, 20 s after settling."""
    for g in ("walk", "run", "jump", "hop"):
        v = validate(build("ml", g), g, 20.0)
        s, rec = v.summary(), v.recording
        sel = rec.t >= v.settle_s
        lead = abs(s["speed_mps"]) / np.sqrt(G / rec.com_z[sel].mean())
        if g in ("walk", "run"):
            assert s["mos_forward_m"] < -0.5 * lead < 0.0 < s["mos_backward_m"], (g, s, lead)
        else:
            assert s["mos_forward_m"] > 0.0 and s["mos_backward_m"] > 0.0, (g, s)
