"""The lift abort, switched on by hand: one link of a tuning chain (set_by_hand, with what was
set and why), from START's gains into OUT/la.

    python scripts/lift_abort.py START.json OUT

Used by scripts/tune_gains.sh as its last link (docs/RESULTS.md, "Start-up deadlock"). A leg lifts only
while the other stands, but until now its lift lasted until its own foot had left the ground
and landed again: when the other foot left the ground first (pushed off by its extensor burst in
a CPG start-up transient), the lifting leg stood on the ground in its swing mode, tucking its
knee and placing a foot that carried the body, and the body fell. lift_abort = 1 ends such a
lift; 0 is the controller before it. Not a search: a rule, measured on the tuning conditions
before it was adopted (SWEEP).
"""
import sys

from cpgbiped.envs.search.controller_tuning import hand_set_link

SWEEP = ("tuning cost (the tuner's rollout_cost, 20 s, tuning conditions 1-24, each gait "
         "alone) without -> with: walk 21.24 -> 19.73 (condition 12 named a walk), run 58.57 -> "
         "50.97 (condition 18, the Hopf run, no longer stops in a deadlock), jump 114.85 and "
         "hop 121.22 unchanged; no condition worse")


def main() -> None:
    hand_set_link(sys.argv[1:], "la", {"lift_abort": 1.0},
                  "a lift ends while its foot is still down when the other foot leaves the ground "
                  "first (a start-up deadlock: a swinging leg carrying the body); " + SWEEP)


if __name__ == "__main__":
    main()
