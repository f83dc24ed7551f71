"""A rollout's tick loop compiled whole: control, physics and recording without Python per tick.

``mj_step`` is called from numba through ctypes (MuJoCo's own shared library, the one the
Python bindings load; ``MjModel._address`` and ``MjData._address`` are the C structs). Between
two returns to Python the loop runs up to ``k_end`` ticks, each one
:func:`cpgbiped.envs.control.control_kernel.tick` then ``CONTROL_EVERY`` calls of ``mj_step``. It stops early at a
fallen or non-finite row. Python checks MuJoCo's warnings between chunks.

The results are those of the Python loop in :func:`cpgbiped.envs.simulation.rollout.rollout`, bit for bit (tested);
searches use it (``rollout(poses=False)``): a 20 s rollout's ~5,000 ticks cost two Python
calls each there (``tick`` and ``mj_step``). The function uses a ctypes pointer, which numba
cannot cache: each process compiles it once (about a second) on first use.
"""
from __future__ import annotations

import ctypes
import glob
import os

import mujoco
from numba import njit

from cpgbiped.envs.control import control_kernel as kernel


def _library():
    here = os.path.dirname(mujoco.__file__)
    paths = sorted(glob.glob(os.path.join(here, "libmujoco.so*")))
    if not paths:  # pragma: no cover - the wheel ships it
        raise ImportError(f"no libmujoco shared library beside {mujoco.__file__}")
    lib = ctypes.CDLL(paths[0])
    fn = lib.mj_step
    fn.argtypes = [ctypes.c_size_t, ctypes.c_size_t]  # const mjModel*, mjData*
    fn.restype = None
    return fn


_mj_step = _library()


@njit(inline="always")
def _steps(m_addr, d_addr, k, control_every, t_s, dt_s, push_tick, push_n, push_force, xfrc,
           torso_id, sens, ix, grf):
    """Tick k's physics steps, with the push's force during them when k is one of the push's
    ``push_n`` ticks from ``push_tick``, each step's ground forces added to ``grf``;
    returns MjData.time advanced by ``dt_s`` per step."""
    pushing = 0 <= k - push_tick < push_n  # never with no push (push_n 0)
    if pushing:
        xfrc[torso_id, 0] = push_force
    for _ in range(control_every):
        _mj_step(m_addr, d_addr)
        kernel.add_grf(sens, ix, grf)
        t_s += dt_s
    if pushing:
        xfrc[torso_id, 0] = 0.0
    return t_s


@njit
def run_ticks(m_addr, d_addr, k0, k_end, n_ticks, control_every, t_s, dt_s, sv, sa, sdt, P, S, qpos,
              qvel, sens, xpos, act, ctrl, afrc, avel, ix, v, a, rec, fall_height, fall_pitch,
              push_tick, push_n, push_force, xfrc, torso_id, grf):
    """Ticks k0 .. k_end - 1 (each records row k - 1, sets tick k's controls and steps the
    physics; tick n_ticks only records). It returns after the tick whose row is fallen
    (status 1, its steps done) or non-finite (status 2, before its steps). ``t_s``: MjData.time at tick k0, advanced here by ``dt_s`` per physics step
    as MuJoCo advances it (the same sums). Returns (next tick, status of the last recorded row:
    0 fine, 1 fallen, 2 non-finite). ``grf`` (4,): the ground forces (``kernel.add_grf``) summed over the
    steps of tick k0 - 1 (zeros when k0 = 0), carried between calls."""
    for k in range(k0, k_end):
        status = kernel.tick(k, t_s, sv, sa, sdt, P, S, qpos, qvel, sens, xpos, act, ctrl,
                             afrc, avel, ix, v, a, rec, fall_height, fall_pitch)
        if k > 0:
            kernel.write_grf(rec, k - 1, grf, control_every)
        if k > 0 and status == 2:
            return k + 1, status
        if k == n_ticks:
            return k + 1, status if k > 0 else 0
        t_s = _steps(m_addr, d_addr, k, control_every, t_s, dt_s, push_tick, push_n, push_force,
                     xfrc, torso_id, sens, ix, grf)
        if k > 0 and status == 1:  # row k - 1 fell; tick k's steps are done
            return k + 1, status
    return k_end, 0


@njit
def run_ticks_closed(m_addr, d_addr, k0, k_end, n_ticks, control_every, t_s, dt_s, code, NP,
                     P_ab, knots, y, K, n_sub, h, noise, act_c, act_w, weight_n, tick_s, sensors,
                     fb, scratch, P, S, qpos, qvel, sens, xpos, act, ctrl, afrc, avel, ix, v, a,
                     rec, fall_height, fall_pitch, push_tick, push_n, push_force, xfrc, torso_id,
                     grf):
    """:func:`run_ticks` with the CPG stepped in the loop
    (:func:`cpgbiped.envs.control.control_kernel.tick_closed`)."""
    for k in range(k0, k_end):
        status = kernel.tick_closed(k, t_s, code, NP, P_ab, knots, y, K, n_sub, h, noise, act_c,
                                    act_w, weight_n, tick_s, sensors, fb, scratch, P, S, qpos,
                                    qvel, sens, xpos, act, ctrl, afrc, avel, ix, v, a, rec,
                                    fall_height, fall_pitch)
        if k > 0:
            kernel.write_grf(rec, k - 1, grf, control_every)
        if k > 0 and status == 2:
            return k + 1, status
        if k == n_ticks:
            return k + 1, status if k > 0 else 0
        t_s = _steps(m_addr, d_addr, k, control_every, t_s, dt_s, push_tick, push_n, push_force,
                     xfrc, torso_id, sens, ix, grf)
        if k > 0 and status == 1:
            return k + 1, status
    return k_end, 0
