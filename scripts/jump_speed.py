"""The jump corner's foot-placement speed term, set by hand: one link of a tuning chain
(set_by_hand, with what was set and why), from START's gains into OUT/v1.

    python scripts/jump_speed.py START.json OUT

Used by scripts/tune_gains.sh after stage jx3 (docs/JOURNAL.md, "Jump"). The speed
term c_v of the thigh target theta = theta0 + c_v v_com + c_d (x_com - x_sup) is searched in
[0, 0.8] by every stage (a Raibert hopper's sign: the foot lands further ahead the faster the body
moves). In the two-legged jump it works the other way round, measured: a smaller c_v (down to
negative values) slows the jump's backward drift (a hand sweep on the tuning conditions,
below). Why was not analysed; a likely cause is that both legs swing together in flight and
the torso takes their reaction, so the thigh target moves the trunk more than the feet.
"""
import sys

from cpgbiped.envs.search.controller_tuning import hand_set_link

C_V = -0.3
SWEEP = ("summed tuning cost (walk and jump, tuning conditions 1-16 and 21-24, 20 s, the "
         "tuner's rollout_cost) against synchronous.c_v: 0.51 (jx3) 94.2, 0 99.1, -0.15 97.5, "
         "-0.3 84.7, -0.4 118.9, -0.5 100.5, -0.75 118.5; the lowest is taken. The jump's mean "
         "speed on those conditions: -0.047 to -0.058 m/s at 0.51, -0.037 to -0.050 at -0.3, "
         "-0.033 to -0.045 at -0.5 (more falls)")


def main() -> None:
    hand_set_link(sys.argv[1:], "v1", {"synchronous.c_v": C_V},
                  f"the jump corner's foot-placement speed term 0.51 -> {C_V}, outside the tuning "
                  "box [0, 0.8]: a Raibert hopper's sign does not carry over to the two-legged "
                  "jump (measured; why not analysed); " + SWEEP)


if __name__ == "__main__":
    main()
