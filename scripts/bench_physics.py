"""Benchmark: the physical biped, in one run (ratios against baselines measured here).

1. Physics steps per second with the CPG and the one controller in the loop (``rollout``: the
   CPG is integrated ahead in one batch, the controller runs every 2 physics steps) vs plain
   ``mujoco.mj_step`` of the same model with zero control. Target ratio >= 0.5. The same for
   the closed loop (``rollout(feedback=K)``, the CPG stepped with the physics in the compiled
   loop, ``poses=False``): target >= 0.5.
2. Video frames per second of the renderer used by ``cpgbiped render`` vs a bare
   ``mujoco.Renderer`` loop over the same states with the same scene flags. Target >= 0.9x.
3. Rollout time with the rerun recording (body included) written vs without. Target <= 1.2x.

    MUJOCO_GL=osmesa python scripts/bench_physics.py [--seconds 20]
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time

os.environ.setdefault("MUJOCO_GL", "osmesa")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from cpgbiped.cpg.network import build  # noqa: E402
from cpgbiped.envs.simulation.rollout import rollout  # noqa: E402
from cpgbiped.models import BIPED_SCENE  # noqa: E402


def best_of(n, f):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def paired(n, f, g):
    """Time f and g alternately (f, g, f, g, ...), so that drifts in this machine's speed hit
    both alike. Returns (best time of f, best time of g, median over the pairs of t_g / t_f):
    the ratio of each adjacent pair, then the median, is steadier than a ratio of two minima."""
    tf, tg = [], []
    for _ in range(n):
        tf.append(best_of(1, f)[0])
        tg.append(best_of(1, g)[0])
    return min(tf), min(tg), float(np.median(np.array(tg) / np.array(tf)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--frames", type=int, default=150)
    a = ap.parse_args(argv)
    net = build("ml", "walk")
    rollout(net, 0.5)  # warm up (kernel cache, imports)

    rec = rollout(net, a.seconds)
    n_steps = int(round(rec.t[-1] / rec.physics_dt))
    m = mujoco.MjModel.from_xml_path(str(BIPED_SCENE))

    def plain():
        d = mujoco.MjData(m)
        for _ in range(n_steps):
            mujoco.mj_step(m, d)

    t_loop, t_plain, r_plain = paired(7, lambda: rollout(net, a.seconds), plain)
    print(f"1. physics, {n_steps} steps ({rec.t[-1]:.1f} s simulated, walk):")
    print(f"   CPG + controller in the loop : {n_steps / t_loop:10.0f} steps/s")
    print(f"   plain mj_step, zero control  : {n_steps / t_plain:10.0f} steps/s")
    print(f"   ratio                        : {r_plain:10.2f}   (target >= 0.5)")

    from cpgbiped.cpg.feedback import RECOMMENDED

    K = RECOMMENDED["ml"]
    rollout(net, 0.5, poses=False, feedback=K)  # compile the closed loop
    t_cl, t_plain2, r_cl = paired(7, lambda: rollout(net, a.seconds, poses=False, feedback=K),
                                  plain)
    print(f"1b. closed loop (feedback K = {K:g}, CPG stepped in the compiled loop):")
    print(f"   closed loop                  : {n_steps / t_cl:10.0f} steps/s")
    print(f"   plain mj_step, zero control  : {n_steps / t_plain2:10.0f} steps/s")
    print(f"   ratio                        : {r_cl:10.2f}   (target >= 0.5)")

    from cpgbiped.envs.media.render import FrameRenderer

    rec = rollout(net, 6.0)
    idx = np.linspace(0, len(rec.t) - 1, a.frames).astype(int)
    fr = FrameRenderer(640, 480)
    fr.frame(rec.qpos[0], rec.contact[0])
    d = mujoco.MjData(m)
    with fr, mujoco.Renderer(m, 480, 640) as r:
        opt = mujoco.MjvOption()
        cam = mujoco.MjvCamera()  # the same view as the cpgbiped renderer
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.distance, cam.elevation, cam.azimuth = 3.0, -8.0, 90.0
        torso = m.body("torso").id

        def bare():
            for k in idx:
                d.qpos[:] = rec.qpos[k]
                mujoco.mj_forward(m, d)
                cam.lookat[:] = [d.xpos[torso][0], 0.0, 0.6]
                r.update_scene(d, cam, opt)
                for flag in (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION,
                             mujoco.mjtRndFlag.mjRND_SKYBOX):
                    r.scene.flags[flag] = 0
                r.render()

        bare()
        t_ours, t_bare, r_bare = paired(5, lambda: [fr.frame(rec.qpos[k], rec.contact[k]) for k in idx],
                                bare)
    print(f"2. rendering {a.frames} frames at 640x480 (MUJOCO_GL={os.environ['MUJOCO_GL']}):")
    print(f"   cpgbiped renderer            : {a.frames / t_ours:10.1f} frames/s")
    print(f"   bare mujoco.Renderer loop    : {a.frames / t_bare:10.1f} frames/s")
    print(f"   ratio                        : {r_bare:10.2f}   (target >= 0.9)")

    from cpgbiped.envs.gaits.gait_metrics import measure
    from cpgbiped.envs.media.record import write_rrd

    def without():
        r_ = rollout(net, a.seconds)
        return r_, measure(r_.t, r_.contact, r_.com_x, r_.fell_at, settle_s=2.0)

    with tempfile.TemporaryDirectory() as tmp:
        def with_rrd():
            r_, m_ = without()
            write_rrd(os.path.join(tmp, "b.rrd"), {"walk": (r_, m_)})

        with_rrd()
        t_without, t_with, r_rrd = paired(15, without, with_rrd)
    print(f"3. rollout of {a.seconds:g} s with and without the rerun recording:")
    print(f"   without                      : {t_without:10.2f} s")
    print(f"   with .rrd                    : {t_with:10.2f} s")
    print(f"   ratio                        : {r_rrd:10.2f}   (target <= 1.2)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
