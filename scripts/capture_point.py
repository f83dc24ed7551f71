"""Where a push leaves the capture point: against the front toe (a forward push) or the rear
heel (a backward one), state by state, and whether the body falls.

For a body standing on its feet, the instantaneous capture point (Hof, Gazendam & Sinke 2005;
Pratt et al. 2006) is x_cp = x_com + v_com / omega, omega = sqrt(g / z_com): the point the
centre of mass would come to rest over if the centre of pressure were put there. The ankles
can put the centre of pressure anywhere between heel and toe, no further; a push that carries
x_cp past the front toe cannot be stopped by the ankles alone: the body must step, hop, or
bend at the hips (and likewise past the rear heel). For each CPG seed of [--first, --first +
--n) the preset is rolled out from that random state, pushed at --at s (held 0.2 s, as
``cpgbiped validate --push`` holds it), and the margin is printed at the end of the push, with
its median and minimum over 4 s before the push while both feet are down: toe - x_cp for a
forward push, x_cp - heel for a backward one (m, > 0: the capture point inside the feet):

    python scripts/capture_point.py [--gait jump] --first 1000 --n 40 [--impulse 5] [--at 6]

The front toe: the foremost of the two feet's toe sites (models/biped/biped.xml, 0.17 m ahead
of the ankle and 0.06 m below it, turned with the foot: envs.simulation.biped.foot_edges_x), a
foot in the air included; the rear heel: the hindmost heel site (0.07 m behind the ankle).
The capture point is gait_metrics.extrapolated_com (z_com floored at 0.3 m: a fallen body only). The margin
is a correlate, not a verdict: in a jump the capture point passes the toes briefly at every
take-off (the minimum before the push is negative) without a fall. (``validate --json``
reports the margins of stability, ``mos_*``: the same extrapolated centre of mass over a whole
window, against the feet on the ground only.) Session 45 measured with it why the
jump falls after a forward push (journal, "Session 45").
"""
import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

HELD_S = 0.2


def margins(job):
    gait, seed, impulse, at_s = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.gait_metrics import extrapolated_com
    from cpgbiped.envs.simulation.biped import foot_edges_x
    from cpgbiped.envs.simulation.rollout import rollout

    rec = rollout(build("ml", gait, seed=seed), at_s + 6.0, push=(at_s, impulse, HELD_S))
    end = int(np.searchsorted(rec.t, at_s + HELD_S))
    if end >= len(rec.t):  # fell before the push ended
        return seed, rec.fell_at, float("nan"), float("nan"), float("nan"), float("nan")
    toe_x, heel_x = foot_edges_x(rec.body_pose, rec.xml_path)
    t = rec.t
    cp = extrapolated_com(t, rec.com_x, rec.com_z)
    margin = toe_x.max(axis=1) - cp if impulse >= 0 else cp - heel_x.min(axis=1)
    both = rec.contact.all(axis=1)
    before = (t > at_s - 4.0) & (t < at_s) & both
    m_before = margin[before] if before.any() else np.array([np.nan])
    return (seed, rec.fell_at, float(margin[end]), float(np.median(m_before)),
            float(np.min(m_before)), float(np.gradient(rec.com_x, t)[end]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gait", default="jump")
    ap.add_argument("--first", type=int, default=1000)
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--impulse", type=float, default=5.0, help="N s, > 0 forwards")
    ap.add_argument("--at", type=float, default=6.0, help="s, simulation time")
    a = ap.parse_args()
    from cpgbiped.cpg.network import PRESETS

    if a.gait not in PRESETS["ml"] or a.n < 1 or not 1.0 <= a.at <= 60.0:
        ap.error(f"--gait one of {', '.join(PRESETS['ml'])}, --n >= 1, --at in [1, 60] s")
    jobs = [(a.gait, s, a.impulse, a.at) for s in range(a.first, a.first + a.n)]
    with ProcessPoolExecutor(2) as ex:
        rows = list(ex.map(margins, jobs))
    edge = "front toe - capture point" if a.impulse >= 0 else "capture point - rear heel"
    print(f"{a.gait}, {a.impulse:+g} N s held {HELD_S:g} s at {a.at:g} s; margin = {edge} (m)")
    print(" seed   fell at   margin at push end   speed m/s   before: median  min")
    for seed, fell, m_end, m_med, m_min, v in rows:
        f = "-" if fell is None else f"{fell:.2f}"
        print(f"{seed:5d}  {f:>8s}   {m_end:18.3f}   {v:9.2f}   {m_med:14.3f}  {m_min:.3f}")
    edge = "toe" if a.impulse >= 0 else "heel"
    for inside, what in ((True, f"inside the {edge}"), (False, f"at or past the {edge}")):
        sel = [r for r in rows if np.isfinite(r[2]) and (r[2] > 0) == inside]
        print(f"capture point {what} at the push's end: {len(sel)} states, "
              f"{sum(r[1] is not None for r in sel)} fell")
    early = [r[0] for r in rows if not np.isfinite(r[2])]
    if early:
        print(f"fell before the push ended: seeds {early}")


if __name__ == "__main__":
    main()
