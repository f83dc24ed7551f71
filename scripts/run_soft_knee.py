"""The run corner's stance knee made a spring and its ankle reflex switched off, by hand: one
link of the tuning chain (set_by_hand, with what was set and why), from START's gains into
OUT/rk/gains.json.

    python scripts/run_soft_knee.py START.json OUT
    python scripts/run_soft_knee.py --free     (the run corner's gains the stages after it
                                                search: all but HELD and the opt-in ones)

Why (docs/JOURNAL.md, "Run"): the run bounded (duty 0.13, flight 0.74) because its stance leg launched
at once: the ankle's balance reflex (k_av 1.6 activation per m/s) held both extensors saturated
at 2 m/s, and the knee extended as a piston (kp_push 3.9, a constant push 0.47 of the gear).
Searches from there always returned to the bound (docs/JOURNAL.md, "The run's duty, tried"). Here the
reflex is off (k_ax = k_av = 0: the CPG's own drive, at the shared gain, still reaches the
ankles) and the knee in the burst is soft (target -0.75 rad, stiffness 0.5, push 0.25: the
values of the hand sweep in which the duty reached 0.32-0.42 before the trunk fell), and the
stages after it search the run corner's other gains with these held.
"""
import sys
from pathlib import Path

from cpgbiped.envs.control.control_kernel import BLENDED
from cpgbiped.envs.search.controller_tuning import OPT_IN, set_by_hand

HELD = {"alternating_coactive.k_ax": 0.0, "alternating_coactive.k_av": 0.0,
        "alternating_coactive.knee_ext": -0.75, "alternating_coactive.kp_push": 0.5,
        "alternating_coactive.push": 0.25}


def free_gains() -> list[str]:
    """The run corner's gains that the stages after this link search: every blended gain but
    the ones held here and the opt-in ones (searched only when named)."""
    held = {n.split(".")[-1] for n in HELD} | set(OPT_IN)
    return [f"alternating_coactive.{g}" for g in BLENDED if g not in held]


def main() -> None:
    if sys.argv[1:] == ["--free"]:
        print(",".join(free_gains()))
        return
    start, out = sys.argv[1], Path(sys.argv[2])
    set_by_hand(start, HELD, out / "rk" / "gains.json",
                "the run corner's stance leg launched the body (saturated ankle reflex, a "
                "piston knee): ankle reflex off and a soft stance knee, held by the stages "
                "after it (scripts/run_soft_knee.py)")


if __name__ == "__main__":
    main()
