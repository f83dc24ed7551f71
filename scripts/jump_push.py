"""The jump corner's burst push, set by hand: one link of a tuning chain (set_by_hand, with
what was set and why), from START's gains into OUT/p1.

    python scripts/jump_push.py START.json OUT

Used by scripts/tune_gains.sh (the committed chain), before stage jx3.
"""
import sys

from cpgbiped.envs.search.controller_tuning import hand_set_link


def main() -> None:
    hand_set_link(sys.argv[1:], "p1", {"synchronous.push": 0.45},
                  "the jump corner's knee torque per unit of burst drive 0.752 -> 0.45: on the "
                  "eight first tuning conditions (CPG seeds 1000-1007) the jumps that stand then "
                  "rise 4.3-5.5 cm with 23-34 deg of ankle in stance, against 3.0-4.6 cm and "
                  "18-33 deg, named jump without a fall in 4 of 8 against 3 (a hand sweep of "
                  "0.4-0.6 on the same conditions)")


if __name__ == "__main__":
    main()
