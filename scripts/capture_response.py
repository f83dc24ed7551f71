"""The jump's capture response (capture_place, capture_ankle at the jump's corner): measured on
tuning CPG states, and set by hand as one link of a tuning chain (set_by_hand, with what was
set and why), from START's gains into OUT/cr.

    python scripts/capture_response.py --grid [--n 60] [--gait jump|hop] [--cells "15,1;30,0"]
    python scripts/capture_response.py START.json OUT       # the link (scripts/tune_gains.sh)

Why: pushed forwards by 5 N s at 6 s, the jump falls from about half of all CPG states; the
outcome follows where the push leaves Hof's extrapolated centre of mass (XcoM) against the
toes (journal, session 45: scripts/capture_point.py). Traced (state 1002), the balance reflex
answers the centre of mass ahead of the feet by plantarflexing (k_ax, x_bal), which is the
right answer while the foot is flat and the wrong one once the XcoM is past the toes: the body
rises onto its toes, its base of support shortens by some 6 cm (the toe site 0.17 m ahead of
the ankle, 0.11 m once the foot is turned 0.6 rad), and a flight of 0.1 s places the feet no
further forward. The capture response (the controller's docstring, steps 3 and 4), in a rhythm
whose legs push together and with the two feet side by side: the placing thigh's target moves
by capture_place per metre of XcoM beyond the toes (or behind the heels), and the reflex
withholds the share capture_ankle of its push from a foot already turned onto its toes (heel).

Chosen on tuning CPG states 1000-1059 only (--grid; 14 s rollouts, falls of 60 after +5 N s /
-5 N s held 0.2 s at 6 s, unpushed, friction x0.5, x2.0): the committed gains 32 / 12 / 0 / 3 /
1; the jump's corner with capture_place 10, 15, 20, 30 rad/m and capture_ankle 1: 13, 10, 15,
11 after +5 N s, the others within one of the committed; capture_place 10 alone 30,
capture_ankle 1 alone 27. Those were the joint-angle form's counts (below). The foot-angle
form gives 17, 15, 15, 12 and 23 after +5 N s, and 9-10 after -5 N s: session 48's grid in
docs/JOURNAL.md. (Session files, out/s47: the two as shared gains, in every corner's
rhythm, 10, but the hop's falls after -5 N s 20 -> 22; with a threshold of 2-8 cm before the
response starts, 14-32: it must act while the push is still on, when the XcoM is only just
past the toes; a hip strategy, the trunk's pitch target raised by the XcoM's excess, 18-21 of
40 against 21). Over tuning states 1000-1099 (x1.0, x0.7, x1.3 open loop and x1.0 with K =
0.03) the jump passes validate in 399 of 400 with either gains, the hop in 361 and 358.
capture_place 15 and capture_ankle 1 were put to rule K (docs/JOURNAL.md, session 47), in a
form that read "on its toes" from the ankle joint's angle; the kernel now reads the foot's tilt
in the world (session 47 thought --grid gave the same counts in every cell; it does not,
see above). Put to rule L (session 48) in that form: not adopted. Session 47's grid held
its pushes 0.2 s; --grid now also blows them in one tick, where the withholding costs falls
(tuning states 1000-1059: 9 -> 12 at 15 / 1, 35 with capture_ankle 1 alone).
"""
import argparse
import sys
from concurrent.futures import ProcessPoolExecutor

from cpgbiped.envs.simulation.rollout import PUSH_TICK_S

PLACE, ANKLE = 15.0, 1.0  # rad/m, share: the jump's corner (synchronous)
GRID = ((0.0, 0.0), (10.0, 1.0), (15.0, 1.0), (20.0, 1.0), (30.0, 1.0), (10.0, 0.0), (0.0, 1.0))
# (N s at 6 s, held s, friction): the first five are session 47's columns; the one-tick blows
# (a 4 ms control tick) were added in session 48, after rule L found them (docs/JOURNAL.md)
CONDITIONS = ((5.0, 0.2, 1.0), (-5.0, 0.2, 1.0), (0.0, 0.0, 1.0), (0.0, 0.0, 0.5),
              (0.0, 0.0, 2.0), (5.0, PUSH_TICK_S, 1.0), (-5.0, PUSH_TICK_S, 1.0))
RULE = ("rule K (docs/JOURNAL.md, session 47): not met (in-family transitions 7 -> 5 of 16, "
        "cross-family 6 -> 3 of 8); rule L (session 48): not met (the jump's forward pushes "
        "from unused states 68 -> 67 of 100: held 28 -> 39, one-tick blows 40 -> 28; the hop "
        "from state 7 kept in 8 of 21 re-rolls); not adopted")


def _fell(job):
    gait, seed, impulse, held_s, friction, place, ankle = job
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import CONTROL
    from cpgbiped.envs.simulation.rollout import rollout

    p = CONTROL.with_corner("synchronous", capture_place=place, capture_ankle=ankle)
    push = (6.0, impulse, held_s) if impulse else None
    return rollout(build("ml", gait, seed=seed), 14.0, p, push=push, friction_scale=friction,
                   poses=False).fell_at is not None


def grid(gait: str, n: int, cells=GRID) -> None:
    print(f"{gait}, tuning CPG states 1000-{999 + n}, 14 s; falls after +5 / -5 N s held 0.2 s "
          f"at 6 s, unpushed, friction x0.5, x2.0, +5 / -5 N s as one-tick blows at 6 s")
    with ProcessPoolExecutor(2) as ex:
        for place, ankle in cells:
            falls = [sum(ex.map(_fell, [(gait, s, imp, held, fr, place, ankle)
                                        for s in range(1000, 1000 + n)]))
                     for imp, held, fr in CONDITIONS]
            print(f"capture_place {place:4g} capture_ankle {ankle:g}: "
                  + " / ".join(str(f) for f in falls) + f" of {n}", flush=True)


def cells_arg(text: str) -> tuple:
    """--cells "15,1;30,0" -> ((15.0, 1.0), (30.0, 0.0)); argparse's error for anything else."""
    try:
        cells = tuple(tuple(float(x) for x in c.split(",")) for c in text.split(";"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not numbers: {text!r}") from None
    if not all(len(c) == 2 and c[0] >= 0.0 and 0.0 <= c[1] <= 1.0 for c in cells):
        raise argparse.ArgumentTypeError(f"pairs P,A with P >= 0 and A in 0-1: {text!r}")
    return cells


def main() -> None:
    if "--grid" in sys.argv[1:]:
        ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
        ap.add_argument("--grid", action="store_true")
        ap.add_argument("--gait", default="jump", choices=("jump", "hop"))
        ap.add_argument("--n", type=int, default=60, choices=range(1, 101), metavar="1..100")
        ap.add_argument("--cells", type=cells_arg, default=GRID, metavar="P,A;P,A;...",
                        help="capture_place (rad/m, >= 0) and capture_ankle (0-1) pairs "
                             "(default: session 47's grid)")
        a = ap.parse_args()
        grid(a.gait, a.n, a.cells)
        return
    from cpgbiped.envs.search.controller_tuning import hand_set_link

    hand_set_link(sys.argv[1:], "cr", {"synchronous.capture_place": PLACE,
                                       "synchronous.capture_ankle": ANKLE},
                  f"the jump corner's capture response: capture_place 0 -> {PLACE:g} rad/m, "
                  f"capture_ankle 0 -> {ANKLE:g} (scripts/capture_response.py); " + RULE)


if __name__ == "__main__":
    main()
