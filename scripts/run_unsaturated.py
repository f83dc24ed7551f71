"""The run corner moved out of the bounding basin by hand: one link of a tuning chain
(set_by_hand, with what was set and why), from START's gains into OUT.

    python scripts/run_unsaturated.py START.json OUT.json

Used by scripts/tune_run_experiment.sh (docs/JOURNAL.md, "The run's duty, tried after the walk").
"""
import sys

from cpgbiped.envs.search.controller_tuning import set_by_hand


def main() -> None:
    start, out = sys.argv[1], sys.argv[2]
    set_by_hand(start, {
        "alternating_coactive.k_ax": 3.0, "alternating_coactive.k_av": 0.3,
        "alternating_coactive.push": 0.3, "alternating_coactive.kp_push": 1.0,
        "alternating_coactive.land_yield": 0.5}, out,
        "the run's ankle balance reflex (k_av 1.6 per m/s at 2 m/s) held both ankle extensors "
        "saturated through every stance, a bound; unsaturated, with a softer knee push and the "
        "landing yield on, as the start of a search outside the bounding basin")


if __name__ == "__main__":
    main()
