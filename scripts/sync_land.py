"""A lone foot in a synchronous rhythm lands (sync_land), set by hand: one link of a tuning
chain (set_by_hand, with what was set and why), from START's gains into OUT/sl.

    python scripts/sync_land.py START.json OUT

Used by scripts/tune_gains.sh after the walk's start-up corner. In a rhythm whose legs push
together (the extensors' synchrony sigma >= SIGMA_LIFT = 0.4: the jump's, the hop's) no leg
lifts on its own, so a foot that is off the ground while the other stands is a stumble, not a
swing. Without sync_land the knee of any leg in the air follows its swing drive, and the hop
corner's swing_rest (0.955) drives it in the network's silence: the stumbling foot tucked, and
the body, left on one leg, fell (traced from tuning CPG state 1046 with feedback, where the hop
fell at 5.2 s; five of the nine closed-loop hop falls over tuning states 1000-1099 came at
5.0-5.5 s). With sync_land = 1 such a foot extends to land (the controller's docstring, step 5).

Measured before the rule on tuning CPG states 1000-1099 only (2 s + 20 s): the hop with feedback
(K = 0.01) passes 78 -> 85 of 100, falls 9 -> 4; open loop the hop 84 -> 87 (falls 8 -> 5), the
jump 100 -> 99 (falls 0 -> 1), the walk 99 -> 100, the run 99 -> 99; over 1000-1039 the hop after
+5 N s held 0.2 s at 6 s falls 19 -> 10, the jump on friction x0.5 7 -> 4.
"""
import sys

from cpgbiped.envs.search.controller_tuning import hand_set_link

RULE = ("rule (fixed at 08:22 on 2026-12-06 before the switch met any state outside tuning "
        "states 1000-1099; CPG seeds 2900-2999, unused; `python scripts/rule_rates.py "
        "CANDIDATE --first 2900`, baseline the gains before it): S1 the hop's falls, open "
        "loop over 2900-2999 plus with feedback over 2900-2949, fewer than before and its passes "
        "over those 150 no fewer; S2 each preset's passes >= before - 3, falls over the four <= "
        "before + 3; S3 the 840 perturbation rollouts on 2900-2929 kept >= before - 8; S4 all "
        "four presets pass from their Table 3 states; S5 with feedback over 2900-2949 each "
        "preset's passes >= before - 3; S6 matrices Morris-Lecar 4/4 (Table 3 and random state "
        "7), Hopf >= 3/4, Matsuoka >= 2 m, cross-family transitions from the Table 3 states >= 4 "
        "of 8. Measured: S1 met (falls 6 + 5 -> 2 + 1, passes 86 + 37 -> 86 + 41), S2 met (walk "
        "99 -> 98, run 100 -> 100, jump 100 -> 99, hop 86 -> 86; falls 6 -> 4), S3 met (697 -> "
        "713; the hop 124 -> 143, the jump 165 -> 160: on friction x0.5 28 -> 23), S4 met, S5 "
        "met (walk 48 -> 48, run 50 -> 50, jump 50 -> 50, hop 37 -> 41), S6 met (4/4 and 4/4, "
        "Hopf 3/4, Matsuoka 19.0 m, cross-family 5 of 8). Adopted")


def main() -> None:
    hand_set_link(sys.argv[1:], "sl", {"sync_land": 1.0},
                  "sync_land 0 -> 1: in a synchronous rhythm a foot off the ground while the other "
                  "stands, not lifted by the swing latch, extends to land instead of tucking "
                  "(scripts/sync_land.py); " + RULE)


if __name__ == "__main__":
    main()
