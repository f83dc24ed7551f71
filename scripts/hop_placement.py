"""The hop corner's foot-placement speed term, set by hand: one link of a tuning chain
(set_by_hand, with what was set and why), from START's gains into OUT/hp.

    python scripts/hop_placement.py START.json OUT

Used by scripts/tune_gains.sh after the walk's stance knee (docs/JOURNAL.md, "The hop corner's foot placement"). The hop
corner (synchronous, co-activated) placed the feet with c_v = 0.054 rad per m/s of forward
speed, the value a search for a hop in place left it at: a body that arrives at a walk's or a
run's speed when the network's bursts go in phase (a change from walk or run to jump or hop)
has nothing that brakes it, and pronks forwards until it falls (docs/JOURNAL.md, "The hop corner's foot placement"). A run
-> walk change, whose network also bursts both legs together for cycles, was expected to gain
too and was measured to lose: as a ramp with feedback it reaches the walk later (docs/JOURNAL.md). 0.3 rad per m/s is a
Raibert hopper's sign and about twice the neutral point of a 0.2 s stance (v T_st / 2 over a
0.8 m leg: 0.13 rad per m/s); at the hop's own drift (-0.07 m/s) it moves the feet by 0.02 rad.
Measured before the rule on tuning CPG seeds only (1000-1031): the switches of walk -> jump,
walk -> hop, run -> jump and run -> hop (step at 8 s, open loop and K = 0.01) rose from 34 to
42 and from 33 to 50 of 128 (c_v 0.6: 34 -> 44; both synchronous corners at 0.3: 49, but the
jump's drift crossed -0.05 m/s, passes 14 -> 2 of 16); the four presets' criteria passes over
seeds 1000-1031: walk 32 -> 30, jump 28 -> 27.
"""
import sys

from cpgbiped.envs.search.controller_tuning import hand_set_link

C_V = 0.3
RULE = ("rule fixed before it was measured on fresh states (CPG seeds 3000-3029): adopt if the "
        "switches of walk/run -> jump/hop (step at 8 s, K = 0 and 0.01) rise by >= 12 of 240, no "
        "gait's named count in any of the five census columns (unperturbed, friction x0.5, x2.0, "
        "push +-5 N s at 6 s held 0.2 s) drops by more than 3 of 30 and their summed falls rise "
        "by at most 5, and on the tests' conditions walk 13, run 13, jump >= 12 open loop, 13 each "
        "with K = 0.01, perturbations kept >= 12 of 16. Measured: switches 62 -> 78 of 240; "
        "falls 171 -> 159 of 600, named counts within -2; walk 13, run 13, jump 12, with "
        "feedback 13/13/13; perturbations 12 of 16 (blows 10 -> 11). The same R1 and R2 on CPG "
        "seeds 2200-2229, which neither tuning, tests nor README use: switches 54 -> 77 of 240, "
        "falls 188 -> 177 of 600, named counts within -2")


def main() -> None:
    hand_set_link(sys.argv[1:], "hp", {"synchronous_coactive.c_v": C_V},
                  f"the hop corner's foot-placement speed term 0.054 -> {C_V} rad per m/s: a body "
                  "arriving at a walk's or a run's speed in the hop's rhythm had nothing to brake "
                  "it (scripts/hop_placement.py); " + RULE)


if __name__ == "__main__":
    main()
