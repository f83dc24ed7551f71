"""The jump corner's countermovement, set by hand: two links of a tuning chain (set_by_hand,
with what was set and why), from START's gains into OUT/set1 and OUT/set2.

    python scripts/jump_countermovement.py START.json OUT

Used by scripts/tune_gains.sh (the committed chain) and scripts/tune_jump_experiment.sh.
"""
import sys
from pathlib import Path

from cpgbiped.envs.search.controller_tuning import set_by_hand


def main() -> None:
    start, out = sys.argv[1], Path(sys.argv[2])
    for d in ("set1", "set2"):
        (out / d).mkdir(parents=True, exist_ok=True)
    set_by_hand(start, {"synchronous.theta0": 0.0}, out / "set1" / "gains.json",
                "the jump corner aims the thighs straight down (theta0 0.22 put each landing "
                "ahead of the centre of mass: backward drift and falls)")
    set_by_hand(out / "set1" / "gains.json", {"synchronous.knee_crouch": -0.5,
                                              "synchronous.pitch_d": 0.1},
                out / "set2" / "gains.json",
                "a countermovement: the jump corner crouches to -0.5 rad outside the extensor "
                "burst (it stood at -0.15: the legs stayed straight and only the ankles "
                "pushed), with the trunk nearer upright (pitch target 0.1 rad, was 0.24) so "
                "that the take-off does not pitch it forward")


if __name__ == "__main__":
    main()
