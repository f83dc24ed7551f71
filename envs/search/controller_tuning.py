"""``cpgbiped tune``: the one controller's gains searched by pymoo and scored in physics.

Decision variables. The controller's blended gains have a value at each corner of the
(sigma, kappa) square (:mod:`cpgbiped.envs.control.controller`), and each Morris-Lecar preset's rhythm sits at
one corner (walk: alternating, run: alternating and co-active, jump: synchronous, hop:
synchronous and co-active; measured in tests/test_controller.py). A run scores the gaits it
names (``--gait walk``, ``--gait jump,hop``, ``--gait all``) and searches (``--search``) their
corners, in the box :data:`CORNER_RANGES`, or the shared parameters (:data:`SHARED_RANGES`:
ankle gain, swing wiring, contact hold; the lift abort only when named), which every gait
uses, or both; the start-up gains (the gains file's "startup" corners, which hand over to the
corners in the first seconds) only when ``--only`` names them (``startup.<corner>.*``);
everything else stays as in the starting gains file. Shared parameters are best searched with every gait scored
(``--gait all --search shared``): a walk tuned alone once turned the crossed-extension swing
drive down to 0.1, and the run, which swings on it, could no longer lift a leg.

Conditions. Every candidate drives each named preset under every tuning condition
(:func:`tuning_conditions`): a random initial CPG state drawn from a seed of 1000 or more,
some with another floor friction or a horizontal push on the torso; from the ninth on, the
walk driven by another walk network or the loop closed
(:data:`TUNING_FEEDBACK`); from the seventeenth on, every preset driven by the Hopf network's;
the twenty-first to fortieth: transient CPG states, bigger pushes, slippery floors and pushes
of a settled gait; the forty-first to forty-eighth: a transition to the gait's partner in its
family (walk <-> run, jump <-> hop) in mid-run, judged as the partner; the forty-ninth to
fifty-sixth: pushes held 0.2 s with the feedback on (:func:`tuning_conditions`).
The tests and the README report other conditions (the Table 3 state, CPG seeds 10-19, friction x0.5, x0.7, x1.3,
x2.0, pushes of 5 N s at 6 s): a tuning condition never starts from the Table 3 state or
from a test seed, so the two sets are disjoint (tested), and the result file lists its
conditions.

Cost of one rollout (lower is better), from the criteria of :mod:`cpgbiped.envs.gaits.criteria`:
  SURVIVAL (1 - t_up / T)                         T: the measured window, t_up: its part
                                                  before a fall
  + W_p (1 - min(d, v* T) / (v* T))               walk and run only: d the distance covered
                                                  forwards (until a fall), v* the speed of
                                                  TARGET_FROUDE (above the criteria's minimum;
                                                  ``--target-froude``), W_p = PROGRESS unless
                                                  ``--progress-weight`` sets it
  + FALL                                          if it fell (and nothing more), else
  + w_s x Criteria.shortfall (margin MARGIN)      pattern and quality terms; w_s =
                                                  SHORTFALL unless ``--shortfall-weight``
                                                  sets it (TuneSettings.shortfall_weight)
  + 2 |stride - CPG period| / CPG period           one stride per CPG cycle: the rhythm is the
                                                  network's, not a bounce of the body
  + 2 sum over feet max(0, |footfalls per stride - 1| - 0.05)
  + 1 when the contact classifier names another gait
  + POSTURE per 10 deg of mean trunk lean beyond LEAN_FREE_DEG (humans walk and run with the
    trunk within about 10 deg of upright; a search left free bends the body forward).
Progress is the distance until a fall, as in SCONE's gait measures: a candidate that walks
far before it falls ranks above one that stands still, so a search that starts from
standing is led towards walking instead of towards not moving.
A candidate's cost sums its gaits' costs per condition; over the conditions, CMA-ES minimises
mean + w max (the worst condition counts; w = WORST = 0.5 unless ``--worst-weight`` sets it),
NSGA-II the pair (mean, max), and the best point is the least mean + w max.
``--target-froude run=0.26`` moves a gait's progress target (v* of that Froude number): a
target just above the criteria's minimum asks a search to keep the speed, not to gain more;
``--progress-weight W`` sets PROGRESS's weight (default 10, the same as SURVIVAL's: a speed
short of v* by a tenth costs what a fall a tenth into the window does).
``--survival-only 29-36`` scores the named conditions on SURVIVAL and FALL alone (a slippery
floor where staying up is all that is asked, not the speed or the criteria).
The guard (``--guard walk``): a guarded gait's cost in a condition may not rise above its cost
there under the guard's gains (``--guard-gains``, default the start) by more than GUARD_TOL;
each unit beyond adds GUARD to that condition. A search of the jump's corner scored on the
walk as well once traded the walk's start-up for the jump (the sum let it); the guard makes
the walk a constraint rather than one term of a sum.

Algorithms: CMA-ES (:class:`cpg.cmaes.CMAES`, checkpointable, started from the gains file's
values) and NSGA-II (pymoo, its first population the gains file's values plus points around
them). Rollouts run in a pool of processes or on Dask (:mod:`cpgbiped.envs.simulation.trials`); every rollout is
deterministic, so a seed gives one result whatever runs it, and a resumed run the result of an
uninterrupted one.

Output (all-or-nothing, in ``--out``): ``gains.json``, the starting gains file with the
searched values replaced by the best point's and a provenance entry appended (the command,
the seed, the algorithm and budget, the conditions, the cost, the SHA-256 of the gains file
it started from) - the file the controller loads once copied to :data:`cpgbiped.envs.control.controller.GAINS_FILE`;
``tune_history.csv`` (per generation: best and median cost); ``tune_conditions.csv`` (the best
point's metrics under every condition).

The horizon check: a search scores only its window (``--seconds`` after the settling), and a
body may drift out of a gait just after it (a run stage with 10 s windows gave a run whose
trunk leaned further every stride and fell at 13-17 s in every test condition). So the best
point is rolled out once more under every condition for HORIZON times the window; the time
of any fall goes into ``tune_conditions.csv`` (``fell_at_s_horizon``, s from the start) and
the provenance entry (``horizon``), and the command line says how many fell. It never
changes the search or its result.
"""
from __future__ import annotations

import hashlib
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from pymoo.core.problem import Problem

from cpgbiped.cpg.errors import InputError

from cpgbiped.envs.control import control_kernel as kernel
from cpgbiped.envs.control.controller import (GAINS_FILE, GAINS_FORMAT, ControlParams, params_array,
                         params_from_array, params_from_dict, params_to_dict, read_gains)
from cpgbiped.envs.experiments.transition import IN_FAMILY
from cpgbiped.envs.gaits.criteria import CRITERIA, SETTLE_S
from cpgbiped.envs.simulation.trials import ControlTrial

CORNER_OF = {"walk": "alternating", "run": "alternating_coactive", "jump": "synchronous",
             "hop": "synchronous_coactive"}
GAITS = tuple(CORNER_OF)
# The search box of the blended gains (units as in envs.controller.Corner).
CORNER_RANGES = dict(
    k_ax=(0.0, 20.0), k_av=(0.0, 3.0), kp_t=(0.5, 6.0), kd_t=(0.05, 0.8),
    pitch_d=(-0.05, 0.35), theta0=(-0.4, 0.4), c_v=(0.0, 0.8), c_d=(0.0, 1.5),
    kp_sw=(0.3, 4.0), kd_sw=(0.02, 0.4), kf_t=(-1.0, 1.0), knee_ext=(-0.9, 0.0),
    knee_crouch=(-1.0, -0.02), knee_swing=(-1.4, -0.2), knee_land=(-0.9, 0.0),
    kp_knee=(0.3, 5.0), kp_push=(0.1, 5.0), kp_air=(0.3, 5.0), kd_knee=(0.02, 0.3),
    push=(0.0, 1.0), swing_rest=(0.0, 1.0), x_clear=(-0.2, 0.3), push_off=(0.0, 0.6),
    knee_hold=(0.0, 1.0), land_yield=(0.0, 1.0), x_bal=(-0.05, 0.10), lean_knee=(0.0, 1.5),
    toe_up=(0.0, 1.0), capture_place=(0.0, 30.0), capture_ankle=(0.0, 1.0),
    force_fb=(0.0, 0.002))
# Gains added after the stages of scripts/tune_gains.sh that search every gain were run: a
# search takes them only when --only names them, so that those stages reproduce.
OPT_IN = ("land_yield", "lift_abort", "restart_v", "x_bal", "lean_knee", "toe_up", "sync_land",
          "pitch_tau_s", "capture_place", "capture_ankle", "force_fb")
# ... and of the shared parameters.
SHARED_RANGES = dict(ankle_gain=(0.05, 0.35), e_on=(0.3, 0.7), w_flex=(0.0, 1.5),
                     w_cross=(0.0, 1.5), contact_hold=(0.0, 0.06), lift_abort=(0.0, 1.0),
                     restart_v=(0.0, 2.0), sync_land=(0.0, 1.0),
                     pitch_tau_s=(0.0, 5.0))
if tuple(CORNER_RANGES) != kernel.BLENDED or tuple(SHARED_RANGES) != kernel.SHARED:
    raise ImportError("the tuning box and envs.control_kernel's parameter layout disagree")

TARGET_FROUDE = {"walk": 0.11, "run": 0.33}  # progress target (criteria: Fr >= 0.08, 0.25)
MAX_TARGET_FROUDE = 1.0  # --target-froude's bound (a walk-run transition's Fr 0.5, doubled)
SURVIVAL, PROGRESS, FALL, SHORTFALL, MARGIN = 10.0, 10.0, 5.0, 3.0, 0.03
WORST = 0.5  # the worst condition's weight beside the mean (--worst-weight)
MAX_WORST_WEIGHT = 10.0  # --worst-weight's bound (a sanity bound, not a tuned value)
MAX_SHORTFALL_WEIGHT = 100.0  # --shortfall-weight's bound (a sanity bound, not a tuned value)
MAX_PROGRESS_WEIGHT = 1000.0  # --progress-weight's bound (a sanity bound, not a tuned value)
POSTURE, LEAN_FREE_DEG = 1.0, 10.0  # per 10 deg of mean trunk lean beyond 10 deg
# The guard (--guard): a guarded gait's cost in a condition may exceed its cost under the
# guard's gains by GUARD_TOL (the rollouts are deterministic, but a body this chaotic moves
# its cost by a few hundredths for any change); each unit beyond counts GUARD times.
GUARD, GUARD_TOL = 10.0, 0.1
HORIZON = 2.0  # the horizon check rolls the best point out for this many windows
ALGORITHMS = ("cmaes", "nsga2")
SEARCHES = ("corners", "shared", "both")
# The hand-set gains every tuning chain starts from (its provenance says what they are).
ROOT_GAINS_FILE = Path(__file__).parents[1] / "control" / "gains_root.json"
MAX_CONDITIONS = 56
FIRST_TUNING_SEED = 1000  # CPG seeds of the tuning conditions start here (tests use 10-19)
# CPG seeds of the conditions 21-24: random initial states from which the Table 2 walk network
# starts with its extensors in phase (a jump's rhythm) for one to three cycles before they
# alternate, so that the controller's rhythm features pass the synchronous corner: the four
# seeds of 1016-1099 whose extensors overlap by more than 0.4 (<e_L e_R> / sqrt(<e_L^2>
# <e_R^2>) over 0.5-3 s; the settled walk's is 0) in scripts/scan_transients.py. Of the tests'
# CPG seeds, 15 starts that way (0.58) and 10 and 16 partly (0.23, 0.16); of the sixteen
# first tuning conditions' open-loop Table 2 walks none does (at most 0.22): a corner tuned
# without them is paid for nothing it does to the walk's start-up.
TRANSIENT_SEEDS = (1030, 1037, 1038, 1075)
# Conditions 25-28: pushes twice the size of the first eight's (8 N s), at two other moments,
# both ways (issue 21's push envelope): CPG seeds 1040-1043, never a test's.
BIG_PUSHES = ((1040, (6.3, 8.0)), (1041, (6.3, -8.0)), (1042, (6.8, 8.0)), (1043, (6.8, -8.0)))
# Conditions 29-36: a slippery floor, friction x0.4 (below every other condition's and the tests'
# x0.5: a start-up that survives it is paid for a margin, not for the tests' floor), then x0.6
# (the sixth condition's, from more states), from CPG seeds 1052-1059, never a test's.
SLIPPERY = tuple((1052 + k, 0.4) for k in range(4)) + tuple((1056 + k, 0.6) for k in range(4))
# Conditions 37-40: a settled gait pushed: 5 N s held 0.2 s (SCONE's form, the product's
# robustness push) at 12.3 and 12.8 s, both ways, from CPG seeds 1060-1063, never a test's. Every
# push before them comes at 4.5-6.8 s, while the run still accelerates (1.43 m/s over 5-8 s,
# 1.55 settled); pushed once settled, the committed run fell in 29-30 of 30 census states
# (docs/JOURNAL.md, "Pushed once settled"). A rollout must last HELD_PUSH_MARGIN_S past the push's end
# (--seconds 12 with condition 40; 16 leaves the body 3 s to fall, as the searches used).
HELD_PUSH_MARGIN_S = 1.0  # a held push's condition needs this long after the push ends
SETTLED_PUSHES = ((1060, (12.3, 5.0, 0.2)), (1061, (12.3, -5.0, 0.2)),
                  (1062, (12.8, 5.0, 0.2)), (1063, (12.8, -5.0, 0.2)))
# Conditions 41-48: a transition within the gait's family (issue 22): at 7 s (41-44) or 7.5 s
# (45-48) the network's parameters move to the partner preset's (PARTNER: walk <-> run, jump
# <-> hop), a step or a 2 s ramp, open loop or with TUNING_FEEDBACK, from CPG seeds 1080-1087,
# never a test's (the tests change at 8 s from the Table 3 state; the census from seeds 3000
# and up). The rollout is judged as the partner from 4 of its CPG cycles after the change began
# (envs.simulation.trials.SWITCH_CYCLES) for 5 s: the survival, progress and criteria terms of
# the partner, so that a transition that falls, or reaches the partner late, costs.
PARTNER = dict(IN_FAMILY)  # each gait's partner in its family
TRANSITIONS = tuple((1080 + 4 * j + i, (at, ramp), closed)  # (CPG seed, change, feedback on)
                    for j, at in enumerate((7.0, 7.5))
                    for i, (ramp, closed) in enumerate(((0.0, False), (0.0, True), (2.0, False),
                                                        (2.0, True))))

# Conditions 49-56: pushes the product reports with feedback on (issue 21's envelope: held 0.2 s,
# with the Morris-Lecar feedback that was recommended when they were added, Taga's angle in
# alternating rhythms at K = 0.03, frozen here as TUNING_FEEDBACK is), from CPG seeds 1088-1095,
# never a test's. Forwards 10 N s at four moments, 6.3-6.75 s (the impulse ladder's rung just
# below the issue's 0.5 N s/kg, 10.5 N s on this body);
# backwards 5 N s (the size a re-search of the run corner once lost at one phase of the stride,
# session 41) and 15 N s. Every state's network has its own phase at a given time,
# so the four moments with four states sample the stride's phases, not one phase four times.
PUSH_FEEDBACK = ("angle_alternating", 0.03)
FEEDBACK_PUSHES = ((1088, (6.3, 10.0, 0.2)), (1089, (6.45, 10.0, 0.2)),
                   (1090, (6.6, 10.0, 0.2)), (1091, (6.75, 10.0, 0.2)),
                   (1092, (6.3, -5.0, 0.2)), (1093, (6.6, -5.0, 0.2)),
                   (1094, (6.45, -15.0, 0.2)), (1095, (6.75, -15.0, 0.2)))


# Other walk networks for the tuning conditions from the ninth on: Morris-Lecar weight sets
# (w_a, w_b, w_c) with the walk's I_app and phi that the CPG classifier names a walk, found by
# a random scan of [-1, 1]^3 (numpy default_rng(5), the first 60 draws), periods 16.32 and
# 10.47 model units (1.33 s and 0.85 s strides) around the Table 2 walk's 13.11. They are not
# the tests' two walk networks (tests/test_physics.py: periods 9.57 and 16.63), so a
# controller tuned with them is checked on networks it never saw.
TUNING_WALKS = ((-0.566, 0.202, 0.772), (-0.039, -0.09, 0.334))


def extensor_overlap(gait: str, seed: int, t0_s: float = 0.5, t1_s: float = 3.0) -> float:
    """How much the extensor cells of ``gait``'s Morris-Lecar preset, started from CPG seed
    ``seed``'s random state, burst together between t0_s and t1_s of the rollout's clock:
    <e_L e_R> / sqrt(<e_L^2> <e_R^2>) of their activations (1 in phase, 0 never together; the
    selection rule of :data:`TRANSIENT_SEEDS`)."""
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.control.controller import cpg_schedule

    s = cpg_schedule(build("ml", gait, seed=seed), t1_s)
    t = np.arange(len(s.a)) * s.dt_s
    e = s.a[(t >= t0_s) & (t < t1_s)][:, 2:4]
    return float((e[:, 0] * e[:, 1]).mean() / np.sqrt((e[:, 0] ** 2).mean()
                                                      * (e[:, 1] ** 2).mean()))


# The Morris-Lecar feedback pathway and gain of the closed-loop tuning conditions (10, 12, 14
# and 16): the recommended choice of cpg/feedback_gains.json when the committed chain of tuning
# runs was made (Taga's gated thigh angle, K = 0.01). Frozen here so that every recorded run of
# the chain replays with the loop it was tuned in, whatever the recommended choice becomes.
TUNING_FEEDBACK = ("angle", 0.01)


def tuning_conditions(n: int) -> list[dict]:
    """The first ``n`` tuning conditions: ``cpg_seed`` (a random initial CPG state), and for
    most of them a floor friction scale or a push (time s, impulse N s) on the torso, struck in
    one 4 ms control tick (the rollout's default form; the pushes the product reports are held
    0.2 s, :data:`cpgbiped.envs.experiments.robustness.PUSH_S`, a form only conditions 37-40
    and 49-56 use, (time s, impulse N s, 0.2), so the committed chain of tuning runs, which
    used none of them, replays bit for bit). From the
    ninth on, half of them drive the walk by another walk network (``weights``:
    {"walk": (w_a, w_b, w_c)}, :data:`TUNING_WALKS`) and half close the loop (``feedback``:
    the gain of :data:`TUNING_FEEDBACK`, through its pathway), so that the
    gains are paid for serving a walk rhythm rather than one network, and the coupled system.
    From the seventeenth on, every gait is driven by the Hopf network's preset (``network``:
    "hopf"), whose bursts have another shape (a walk's extensors burst for about 43% of the
    cycle, the Morris-Lecar walk's for 30%), so that the gains serve a rhythm rather than one
    network's waveform. The twenty-first to twenty-fourth start from :data:`TRANSIENT_SEEDS`
    (the walk network starts in a jump's rhythm), the twenty-fifth to twenty-eighth push the
    torso by 8 N s (:data:`BIG_PUSHES`), the twenty-ninth to thirty-second stand on a floor of
    friction x0.4 and the thirty-third to thirty-sixth on x0.6 (:data:`SLIPPERY`), the
    thirty-seventh to fortieth push a settled gait, 5 N s held 0.2 s at 12.3 and 12.8 s
    (:data:`SETTLED_PUSHES`), the forty-first to forty-eighth change the network to the
    gait's partner in its family mid-run (``change``: (at s, ramp s), :data:`TRANSITIONS`,
    judged as the partner), the forty-ninth to fifty-sixth push the torso with the feedback on
    (``feedback_form``: :data:`PUSH_FEEDBACK`, held 0.2 s: 10 N s forwards, 5 and 15 N s
    backwards, :data:`FEEDBACK_PUSHES`); pick them with :attr:`TuneSettings.condition_ids`
    (``--conditions 1-8,21-24``)."""
    if not 1 <= int(n) <= MAX_CONDITIONS:
        raise InputError(f"tuning conditions must be 1-{MAX_CONDITIONS}, got {n}")
    extra = [{}, {"friction_scale": 0.8}, {"friction_scale": 1.25}, {"push": (5.5, 4.0)},
             {"push": (5.5, -4.0)}, {"friction_scale": 0.6}, {"friction_scale": 1.6},
             {"push": (4.5, 3.0)}]
    k_fb = TUNING_FEEDBACK[1]
    variants = [{"weights": {"walk": TUNING_WALKS[0]}}, {"feedback": k_fb},
                {"weights": {"walk": TUNING_WALKS[1]}}, {"feedback": k_fb, "friction_scale": 0.8},
                {"weights": {"walk": TUNING_WALKS[0]}, "friction_scale": 1.25},
                {"feedback": k_fb, "push": (5.5, 4.0)},
                {"weights": {"walk": TUNING_WALKS[1]}, "friction_scale": 0.8},
                {"feedback": k_fb, "push": (5.5, -4.0)}]
    variants += [{"network": "hopf"}, {"network": "hopf", "friction_scale": 0.8},
                 {"network": "hopf", "push": (5.5, 4.0)},
                 {"network": "hopf", "friction_scale": 1.25}]
    out = [{"cpg_seed": FIRST_TUNING_SEED + k,
            **(extra[k] if k < len(extra) else variants[k - len(extra)])}
           for k in range(min(int(n), 20))]
    out += [{"cpg_seed": s} for s in TRANSIENT_SEEDS[:max(0, int(n) - 20)]]
    out += [{"cpg_seed": s, "push": p} for s, p in BIG_PUSHES[:max(0, int(n) - 24)]]
    out += [{"cpg_seed": s, "friction_scale": f} for s, f in SLIPPERY[:max(0, int(n) - 28)]]
    out += [{"cpg_seed": s, "push": p} for s, p in SETTLED_PUSHES[:max(0, int(n) - 36)]]
    out += [{"cpg_seed": s, "change": c, **({"feedback": k_fb} if closed else {})}
            for s, c, closed in TRANSITIONS[:max(0, int(n) - 40)]]
    return out + [{"cpg_seed": s, "push": p, "feedback": PUSH_FEEDBACK[1],
                   "feedback_form": PUSH_FEEDBACK[0]}
                  for s, p in FEEDBACK_PUSHES[:max(0, int(n) - 48)]]


def condition_ids(text: str) -> tuple[int, ...]:
    """The 1-based numbers of tuning conditions in ``1-8,21-24`` (numbers and ranges), in order,
    without repeats (``--conditions`` takes this or a plain N, the first N)."""
    ids = []
    for part in str(text).split(","):
        part = part.strip()
        try:
            if "-" in part:
                a, b = (int(x) for x in part.split("-", 1))
                ids += range(a, b + 1) if a <= b else [0]
            else:
                ids.append(int(part))
        except ValueError:
            raise InputError(f"tuning conditions must be N or numbers and ranges such as "
                             f"1-8,21-24, got {text!r}") from None
    if not ids or any(not 1 <= k <= MAX_CONDITIONS for k in ids):
        raise InputError(f"tuning conditions are numbered 1-{MAX_CONDITIONS}, got {text!r}")
    return tuple(dict.fromkeys(ids))


def condition_trial(gait: str, control: tuple, cond: dict) -> ControlTrial:
    """The rollout of ``gait``'s preset under one tuning condition (its own network's weights
    when the condition names some for it)."""
    w = cond.get("weights", {}).get(gait)
    change = cond.get("change")
    return ControlTrial(gait, control, cpg_seed=cond["cpg_seed"],
                        to=None if change is None else PARTNER[gait], change=change,
                        friction_scale=cond.get("friction_scale", 1.0), push=cond.get("push"),
                        weights=None if w is None else tuple(w),
                        feedback=cond.get("feedback", 0.0), network=cond.get("network", "ml"),
                        feedback_form=cond.get("feedback_form", TUNING_FEEDBACK[0])
                        if cond.get("feedback") and cond.get("network", "ml") == "ml" else None)


def check_gaits(text: str) -> tuple[str, ...]:
    names = GAITS if text == "all" else tuple(x.strip() for x in str(text).split(","))
    bad = [g for g in names if g not in CORNER_OF]
    if bad or not names:
        raise InputError(f"unknown gait {', '.join(bad) or repr(text)}: tune takes "
                         f"{', '.join(GAITS)}, a comma-separated list of them, or all")
    return tuple(dict.fromkeys(names))


@dataclass(frozen=True)
class TuneSettings:
    """What a tuning run searches and how each candidate is scored."""

    gaits: tuple[str, ...]
    search: str = "corners"  # "corners", "shared" or "both"
    algorithm: str = "cmaes"
    seconds: float = 10.0  # measured seconds per rollout, after SETTLE_S
    n_conditions: int = 6
    sigma: float = 0.15  # CMA-ES: initial step, in units of each variable's range
    only: tuple[str, ...] = ()  # search only these gains (names of gains; empty: all)
    condition_ids: tuple[int, ...] = ()  # 1-based tuning conditions (empty: the first n_conditions)
    guard: tuple[str, ...] = ()  # gaits that may not get worse than under guard_gains
    guard_gains: str = ""  # the gains file the guard compares with (empty: the start's)
    shortfall_weight: float = SHORTFALL  # weight of the pattern and quality shortfalls
    worst_weight: float = WORST  # CMA-ES and the final pick minimise mean + worst_weight x max
    survival_only: tuple[int, ...] = ()  # 1-based conditions scored on seconds upright and fall
    target_froude: tuple[tuple[str, float], ...] = ()  # (gait, Fr): progress targets replacing
    #                                                    TARGET_FROUDE's for those gaits
    progress_weight: float = PROGRESS  # weight of the progress term (walk and run)

    def froude_target(self, gait: str) -> float | None:
        """The Froude number of ``gait``'s progress target (None: no progress term)."""
        return dict(self.target_froude).get(gait, TARGET_FROUDE.get(gait))

    def ids(self) -> tuple[int, ...]:
        """The 1-based numbers of :meth:`conditions`, in order."""
        return self.condition_ids or tuple(range(1, self.n_conditions + 1))

    def survival_mask(self) -> np.ndarray:
        """Per condition of :meth:`conditions`: scored on seconds upright alone."""
        return np.array([k in self.survival_only for k in self.ids()], bool)

    def conditions(self) -> list[dict]:
        """The tuning conditions every candidate is scored under."""
        if not self.condition_ids:
            return tuning_conditions(self.n_conditions)
        every = tuning_conditions(MAX_CONDITIONS)
        return [every[k - 1] for k in self.condition_ids]

    def __post_init__(self):
        known = (set(CORNER_RANGES) | set(SHARED_RANGES)
                 | {f"{pre}{c}.{g}" for pre in ("", STARTUP) for c in kernel.CORNERS
                    for g in (*CORNER_RANGES, "*")})
        bad = [n for n in self.only if n not in known]
        if bad:
            raise InputError(f"unknown gain {', '.join(map(repr, bad))} in --only: use names "
                             f"of {', '.join(sorted(set(CORNER_RANGES) | set(SHARED_RANGES)))}, "
                             f"or <corner>.<gain> or <corner>.* with a corner of "
                             f"{', '.join(kernel.CORNERS)}, or startup.<corner>.<gain> or "
                             f"startup.<corner>.* (the start-up gains)")
        check_gaits(",".join(self.gaits))
        if self.guard:
            check_gaits(",".join(self.guard))
            missing = [g for g in self.guard if g not in self.gaits]
            if missing:
                raise InputError(f"--guard {','.join(missing)}: a guarded gait must be scored "
                                 f"too; add it to --gait")
        elif self.guard_gains:
            raise InputError("--guard-gains needs --guard (the gaits it guards)")
        if self.search not in SEARCHES:
            raise InputError(f"unknown search {self.search!r}: use {', '.join(SEARCHES)}")
        if self.algorithm not in ALGORITHMS:
            raise InputError(f"unknown algorithm {self.algorithm!r}: use {', '.join(ALGORITHMS)}")
        if not (np.isfinite(self.seconds) and 2.0 <= self.seconds <= 60.0):
            raise InputError(f"seconds per rollout must be in [2, 60], got {self.seconds}")
        if any(not 1 <= k <= MAX_CONDITIONS for k in self.condition_ids):
            raise InputError(f"tuning conditions are numbered 1-{MAX_CONDITIONS}")
        extra = [k for k in self.survival_only if k not in self.ids()]
        if extra:
            raise InputError(f"--survival-only {','.join(map(str, extra))}: not among the "
                             f"conditions the search scores ({','.join(map(str, self.ids()))})")
        total = SETTLE_S + self.seconds
        for k, cond in zip(self.ids(), self.conditions()):
            push = cond.get("push")
            if push is None:
                continue
            if push[0] >= total:
                raise InputError(
                    f"tuning condition {k} pushes at {push[0]:g} s, after the end of "
                    f"a {total:g} s rollout: use --seconds above "
                    f"{push[0] - SETTLE_S:g} or leave condition {k} out")
            end = push[0] + push[2] + HELD_PUSH_MARGIN_S if len(push) > 2 else 0.0
            if end > total + 1e-9:  # a held push: held, then time to fall
                raise InputError(
                    f"tuning condition {k} pushes at {push[0]:g} s for {push[2]:g} s: a "
                    f"{total:g} s rollout leaves under {HELD_PUSH_MARGIN_S:g} s after it to "
                    f"fall in: use --seconds {end - SETTLE_S:g} or more, or leave condition "
                    f"{k} out")
        if not (np.isfinite(self.sigma) and 0.0 < self.sigma <= 1.0):
            raise InputError(f"sigma must be in (0, 1], got {self.sigma}")
        if not (np.isfinite(self.worst_weight) and 0.0 <= self.worst_weight <= MAX_WORST_WEIGHT):
            raise InputError(f"--worst-weight must be in [0, {MAX_WORST_WEIGHT:g}], "
                             f"got {self.worst_weight}")
        for g, fr in self.target_froude:
            if g not in TARGET_FROUDE:
                raise InputError(f"--target-froude {g}: only {', '.join(TARGET_FROUDE)} have a "
                                 f"progress target")
            if g not in self.gaits:
                raise InputError(f"--target-froude {g}: not among the gaits scored (--gait)")
            if not (np.isfinite(fr) and 0.0 < fr <= MAX_TARGET_FROUDE):
                raise InputError(f"--target-froude {g}={fr}: the Froude number must be in "
                                 f"(0, {MAX_TARGET_FROUDE:g}]")
        if not (np.isfinite(self.progress_weight)
                and 0.0 <= self.progress_weight <= MAX_PROGRESS_WEIGHT):
            raise InputError(f"--progress-weight must be in [0, {MAX_PROGRESS_WEIGHT:g}], "
                             f"got {self.progress_weight}")
        if not (np.isfinite(self.shortfall_weight)
                and 0.0 <= self.shortfall_weight <= MAX_SHORTFALL_WEIGHT):
            raise InputError(f"--shortfall-weight must be in [0, {MAX_SHORTFALL_WEIGHT:g}], "
                             f"got {self.shortfall_weight}")
        if self.only and not variables(self):
            raise InputError(f"--only {','.join(self.only)} names no gain that --search "
                             f"{self.search} searches")

    @property
    def gait(self) -> str:  # the checkpoint header names the run by this
        return ",".join(self.gaits)


STARTUP = "startup."  # prefix of the start-up corners' gains (searched only when --only names them)


def variables(settings: TuneSettings) -> list[tuple[str, float, float]]:
    """(name, low, high) of every searched parameter: "<corner>.<gain>", a shared name, or
    "startup.<corner>.<gain>" (a start-up corner's gain, in the same box as the corner's: only
    when ``only`` names it or its corner, ``startup.<corner>.*``, whatever --gait selects, since
    every gait starts on the start-up corners' blend)."""
    startup = [(f"{STARTUP}{c}.{k}", lo, hi) for c in kernel.CORNERS
               for k, (lo, hi) in CORNER_RANGES.items()
               if f"{STARTUP}{c}.{k}" in settings.only
               or (f"{STARTUP}{c}.*" in settings.only and k not in OPT_IN)]
    out = []
    if settings.search in ("corners", "both"):
        for g in settings.gaits:
            out += [(f"{CORNER_OF[g]}.{k}", lo, hi) for k, (lo, hi) in CORNER_RANGES.items()]
    if settings.search in ("shared", "both"):
        out += [(k, lo, hi) for k, (lo, hi) in SHARED_RANGES.items()]
    if settings.only:  # a gain at every searched corner, "<corner>.<gain>" or "<corner>.*"
        out = [v for v in out if v[0].split(".")[-1] in settings.only or v[0] in settings.only
               or (f"{v[0].split('.')[0]}.*" in settings.only
                   and v[0].split(".")[-1] not in OPT_IN)]
    else:
        out = [v for v in out if v[0].split(".")[-1] not in OPT_IN]
    return out + startup


def _slot(d: dict, name: str) -> tuple[dict, str]:
    """The table of ``d`` (:func:`params_to_dict`) that holds ``name``, and its key there:
    "startup.<corner>.<gain>", "<corner>.<gain>" or a shared name."""
    if name.startswith(STARTUP):
        if "startup" not in d:
            raise InputError("the start-up gains are searched only from a gains file that has "
                             "them (its \"startup\" section; cpgbiped.envs.search."
                             "controller_tuning.set_startup writes one)")
        c, g = name[len(STARTUP):].split(".")
        return d["startup"]["corners"][c], g
    if "." in name:
        c, g = name.split(".")
        return d["corners"][c], g
    return d["shared"], name


def with_values(base: ControlParams, names: list[str], x) -> ControlParams:
    """``base`` with the named parameters set to ``x``."""
    from cpgbiped.envs.control.controller import params_from_dict

    d = params_to_dict(base)
    for n, v in zip(names, np.asarray(x, float)):
        table, key = _slot(d, n)
        table[key] = float(v)
    return params_from_dict(d)


def values_of(p: ControlParams, names: list[str]) -> np.ndarray:
    d = params_to_dict(p)
    return np.array([table[key] for table, key in (_slot(d, n) for n in names)])


def target_speed(gait: str, froude: float | None = None) -> float | None:
    """v* = sqrt(Fr g L) (m/s) of ``froude``, else of TARGET_FROUDE[gait] (None: no target)."""
    from cpgbiped.envs.simulation.biped import body_constants

    fr = TARGET_FROUDE.get(gait) if froude is None else froude
    return None if fr is None else float(np.sqrt(fr * 9.81 * body_constants()[0]))


def rollout_cost(gait: str, s: dict, seconds: float, settle_s: float = SETTLE_S,
                 shortfall: float = SHORTFALL, survival_only: bool = False,
                 target_froude: float | None = None, progress: float = PROGRESS) -> float:
    """The cost of one rollout summary (:func:`cpgbiped.envs.simulation.trials.run_control_trial`); see the module
    docstring. ``shortfall``: the weight of the pattern and quality shortfalls;
    ``survival_only``: the seconds upright and the fall alone (a condition where staying up is
    all that is asked, ``--survival-only``); ``target_froude``: the progress target's Froude
    number (None: TARGET_FROUDE's, ``--target-froude``); ``progress``: its weight
    (``--progress-weight``)."""
    up = float(np.clip(s["survived_s"] - settle_s, 0.0, seconds))
    c = SURVIVAL * (1.0 - up / seconds)
    if survival_only:
        return float(c + (FALL if s["fell"] else 0.0))
    v = target_speed(gait, target_froude)
    if v is not None:
        d = float(s["distance_m"]) if np.isfinite(s["distance_m"]) else 0.0
        c += progress * (1.0 - min(d, v * seconds) / (v * seconds))
    if s["fell"]:
        return c + FALL
    c += shortfall * CRITERIA[gait].shortfall(s, MARGIN)
    lean = s.get("trunk_lean_deg")
    if lean is not None and np.isfinite(lean):  # an upright trunk, as animals' gaits have
        c += POSTURE * max(0.0, abs(lean) - LEAN_FREE_DEG) / 10.0
    period, stride = s.get("cpg_period_s"), s.get("stride_period_s")
    if period and stride is not None and np.isfinite(stride):
        c += 2.0 * abs(stride - period) / period
    else:
        c += 2.0
    ff = np.array([s["footfalls_per_stride"]["left"], s["footfalls_per_stride"]["right"]],
                  dtype=float)
    c += 2.0 * float(np.maximum(0.0, np.abs(np.nan_to_num(ff, nan=2.0) - 1.0) - 0.05).sum())
    return float(c + (0.0 if s["physical_gait"] == gait else 1.0))


class ControllerTuningProblem(Problem):
    """The gains of :func:`variables` scored by rollouts (see the module docstring);
    ``runner`` rolls out lists of trials (:mod:`cpgbiped.envs.simulation.trials`)."""

    def __init__(self, settings: TuneSettings, base: ControlParams, runner=None):
        self.settings = settings
        self.gait = settings.gait
        self.base = base
        self.names = [n for n, _, _ in variables(settings)]
        self.conditions = settings.conditions()
        self.runner = runner
        self.history: list[tuple[int, float, float]] = []  # generation, best, median score
        self.guard_costs = None  # (n_conditions, n_gaits): the guarded gaits' reference costs
        lo = np.array([v[1] for v in variables(settings)])
        hi = np.array([v[2] for v in variables(settings)])
        n_obj = 1 if settings.algorithm == "cmaes" else 2
        super().__init__(n_var=len(self.names), n_obj=n_obj, xl=lo, xu=hi)

    def trials(self, x) -> list[ControlTrial]:
        P = tuple(params_array(with_values(self.base, self.names, x)).tolist())
        return [condition_trial(g, P, c) for c in self.conditions for g in self.settings.gaits]

    def gait_costs(self, results: list) -> np.ndarray:
        """(n_conditions, n_gaits) rollout costs of one point's results (condition-major)."""
        n_g, n_c = len(self.settings.gaits), len(self.conditions)
        only = self.settings.survival_mask()
        def cost(g: str, r: dict, survival_only: bool) -> float:
            judge = r.get("judge")  # a transition: judged as its target over its own window
            g, seconds, settle_s = ((judge["gait"], judge["seconds"], judge["from_s"]) if judge
                                    else (g, self.settings.seconds, SETTLE_S))
            return rollout_cost(g, r, seconds, settle_s=settle_s,
                                shortfall=self.settings.shortfall_weight,
                                survival_only=survival_only,
                                target_froude=self.settings.froude_target(g),
                                progress=self.settings.progress_weight)

        return np.array([[cost(g, results[c * n_g + j], bool(only[c]))
                          for j, g in enumerate(self.settings.gaits)] for c in range(n_c)])

    def reference_costs(self) -> np.ndarray:
        """The guarded gaits' costs under the guard's gains (:attr:`TuneSettings.guard_gains`,
        else the start's), per condition and gait; zero for gaits not guarded."""
        if self.guard_costs is None:
            ref = (read_gains(self.settings.guard_gains)[0] if self.settings.guard_gains
                   else self.base)
            P = tuple(params_array(ref).tolist())
            trials = [condition_trial(g, P, c) for c in self.conditions
                      for g in self.settings.gaits]
            self.guard_costs = self.gait_costs(self.runner(trials))
        return self.guard_costs

    def guard_penalty(self, gait_costs: np.ndarray) -> np.ndarray:
        """Per condition: GUARD x the guarded gaits' excess over their reference cost beyond
        GUARD_TOL (0 without --guard)."""
        if not self.settings.guard:
            return np.zeros(len(gait_costs))
        mask = np.array([g in self.settings.guard for g in self.settings.gaits], float)
        excess = np.maximum(0.0, gait_costs - self.reference_costs() - GUARD_TOL)
        return GUARD * (excess * mask).sum(axis=1)

    def evaluate_points(self, X) -> tuple[np.ndarray, list]:
        """(costs (P, n_conditions), summaries per point) of parameter vectors X: the named
        gaits' rollout costs summed per condition, plus the guard's penalty."""
        X = np.atleast_2d(np.asarray(X, float))
        if self.settings.guard:
            self.reference_costs()
        trials = [t for x in X for t in self.trials(x)]
        results = self.runner(trials)
        n_g, n_c = len(self.settings.gaits), len(self.conditions)
        per = n_g * n_c
        costs = np.zeros((len(X), n_c))
        groups = []
        for k in range(len(X)):
            r = results[k * per:(k + 1) * per]
            groups.append(r)
            gc = self.gait_costs(r)
            costs[k] = gc.sum(axis=1) + self.guard_penalty(gc)
        return costs, groups

    def score(self, costs: np.ndarray) -> np.ndarray:
        """mean + worst_weight x max over the conditions, per point."""
        return costs.mean(axis=1) + self.settings.worst_weight * costs.max(axis=1)

    def objectives(self, costs: np.ndarray) -> np.ndarray:
        if self.n_obj == 1:
            return self.score(costs)[:, None]
        return np.stack([costs.mean(axis=1), costs.max(axis=1)], axis=1)

    def _evaluate(self, X, out, *args, **kwargs):
        costs, _ = self.evaluate_points(X)
        out["F"] = self.objectives(costs)
        score = self.score(costs)
        self.history.append((len(self.history) + 1, float(score.min()), float(np.median(score))))

    def resume_key(self) -> dict:
        """Beside the settings, what a checkpoint must share with this run to resume it: the
        conditions themselves (their seeds, not only their numbers) and the starting gains."""
        import json

        key = {"conditions": json.loads(json.dumps(self.conditions)),
               "start_sha256": params_sha256(self.base)}
        if self.settings.guard_gains:
            key["guard_sha256"] = params_sha256(read_gains(self.settings.guard_gains)[0])
        return key

    def restore(self, saved: "ControllerTuningProblem") -> None:
        """Take over the history of the problem a checkpoint saved (resuming a run)."""
        self.history = list(saved.history)
        self.guard_costs = getattr(saved, "guard_costs", None)

    def __getstate__(self):  # checkpoints never hold worker processes or a cluster
        state = self.__dict__.copy()
        state["runner"] = None
        return state


def algorithm_for(settings: TuneSettings, x0: np.ndarray, lo, hi, pop: int, seed: int):
    """The pymoo algorithm of a run, started at ``x0`` (the starting gains' values)."""
    if settings.algorithm == "cmaes":
        from cpgbiped.cpg.cmaes import CMAES

        return CMAES(x0, sigma=settings.sigma, pop_size=pop)
    from pymoo.algorithms.moo.nsga2 import NSGA2

    rng = np.random.default_rng([int(seed), 11])
    near = np.clip(x0 + settings.sigma * (hi - lo) * rng.standard_normal((pop - 1, len(x0))),
                   lo, hi)
    return NSGA2(pop_size=int(pop), sampling=np.vstack([np.clip(x0, lo, hi)[None], near]),
                 eliminate_duplicates=True)


def horizon_falls(problem: "ControllerTuningProblem", x, seconds: float) -> list:
    """The horizon check (module docstring): the fall time (s from the start; None: no fall)
    of parameters ``x`` under each condition and gait (condition-major, as the trials) when
    rolled out for HORIZON x ``seconds`` after the settling, by the search's own runner."""
    with problem.runner.measuring(HORIZON * seconds) as runner:
        results = runner(problem.trials(x))
    return [round(float(r["survived_s"]), 3) if r["fell"] else None for r in results]


def params_sha256(p: ControlParams) -> str:
    """SHA-256 of a parameter set's values (the canonical JSON of :func:`params_to_dict`):
    which gains a run started from, whatever provenance the file carried."""
    import json

    d = params_to_dict(p)
    for gains in d["corners"].values():  # a gain added later, at its neutral value, is left
        for name, neutral in kernel.ADDED_NEUTRAL.items():  # out: older files hash as before
            if gains[name] == neutral:
                del gains[name]
    for gains in d.get("startup", {}).get("corners", {}).values():
        for name in kernel.ADDED_AFTER_STARTUP:
            if gains[name] == kernel.ADDED_NEUTRAL[name]:
                del gains[name]
    for name, neutral in kernel.ADDED_NEUTRAL_SHARED.items():
        if d["shared"][name] == neutral:
            del d["shared"][name]
    text = json.dumps(d, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def checkpoint_name(settings: TuneSettings) -> str:
    return f"tune_{'_'.join(settings.gaits)}.checkpoint.pkl"


def tune(settings: TuneSettings, rs, out: str | Path, runner, start: str | Path = GAINS_FILE,
         command: str = "", progress=None, stop_after: int | None = None, note=None) -> dict:
    """Run the search and write its files into ``out`` (module docstring). ``rs``:
    :class:`cpg.optimize.RunSettings` (pop, gens, seed); ``start``: the gains file whose
    values the search starts from and keeps for what it does not search; ``progress(gen, n)``
    and ``note(text)`` (the best score so far) after every generation."""
    from cpgbiped.cpg.outdir import run_checkpointed

    base, provenance = read_gains(start)
    return run_checkpointed(out, checkpoint_name(settings), lambda rd, ckpt: _tune(
        rd, ckpt, settings, rs, base, provenance, runner, start, command, progress, stop_after,
        note))


def _tune(rd, ckpt, settings, rs, base, provenance, runner, start, command, progress,
          stop_after, note) -> dict:
    from cpgbiped.cpg.io import write_json
    from cpgbiped.cpg.optimize import run
    from cpgbiped.cpg.search import write_csv

    t0 = time.perf_counter()
    problem = ControllerTuningProblem(settings, base, runner)
    x0 = values_of(base, problem.names)
    outside = [f"{n} {v:g} not in [{a:g}, {b:g}]" for n, v, a, b
               in zip(problem.names, x0, problem.xl, problem.xu) if not a <= v <= b]
    if outside:  # a hand-set link of the chain may leave the box; the start stays a candidate
        print("cpgbiped: warning: the search starts inside its box, from the nearest point: "
              + "; ".join(outside), file=sys.stderr)
    algorithm = algorithm_for(settings, x0, problem.xl, problem.xu, rs.pop, rs.seed)

    def on_generation(gen, n):
        if progress:
            progress(gen, n)
        if note and problem.history:
            note(f"best {min(h[1] for h in problem.history):.3f}")

    res = run(problem, rs, checkpoint=ckpt, on_generation=on_generation, stop_after=stop_after,
              algorithm=algorithm)
    # The best point: CMA-ES's best evaluated; NSGA-II's non-dominated point of least
    # mean + worst_weight x max. Rolled out again (deterministic) for the record.
    # The start itself is a candidate: a search that finds nothing better keeps it.
    P = np.vstack([np.atleast_2d(res.pareto_X), x0[None]])
    costs, summaries = problem.evaluate_points(P)
    score = problem.score(costs)
    k = int(np.argmin(score))
    best_x, start_score = P[k], float(score[-1])
    tuned = with_values(base, problem.names, best_x)
    late = horizon_falls(problem, best_x, settings.seconds)
    entry = {
        "searched": problem.names, "gaits": list(settings.gaits),
        "command": command, "seed": rs.seed, "algorithm": settings.algorithm,
        "pop": rs.pop, "gens": rs.gens, "generations_run": res.n_gen,
        "settings": asdict(settings), "conditions": problem.conditions,
        "cost": round(float(score[k]), 6), "start_cost": round(start_score, 6),
        "kept_start": bool(k == len(P) - 1),
        "started_from": str(start), "started_from_sha256": params_sha256(base),
        "result_sha256": params_sha256(tuned),
        **({"guard": list(settings.guard), "guard_gains": settings.guard_gains or str(start),
            "guard_sha256": params_sha256(read_gains(settings.guard_gains)[0]
                                          if settings.guard_gains else base),
            "guard_reference_costs": np.round(problem.reference_costs(), 4).tolist()}
           if settings.guard else {}),
        "horizon": {"seconds": HORIZON * settings.seconds,
                    "fell": sum(t is not None for t in late), "rollouts": len(late),
                    "fell_at_s": late},
        "wall_s": round(time.perf_counter() - t0, 1),
    }
    gains = {"format": GAINS_FORMAT, **params_to_dict(tuned),
             "provenance": list(provenance) + [entry]}
    write_json(rd.path("gains.json"), gains)
    write_csv(rd.path("tune_history.csv"), ["generation", "best_score", "median_score"],
              problem.history)
    head = ["gait", "network", "cpg_seed", "friction_scale", "push", "weights", "feedback", "cost",
            "fell", "physical_gait", "speed_mps", "froude", "duty_left", "duty_right", "flight",
            "apex_height_m", "stride_cv", "ankle_excursion_deg", "fell_at_s_horizon",
            "to", "change_at_s", "change_ramp_s",  # a transition (41-48): judged as "to"
            "feedback_form"]  # the closed loop's pathway (empty open loop)
    rows = []
    n_g = len(settings.gaits)
    best_costs = problem.gait_costs(summaries[k])
    for c, cond in enumerate(problem.conditions):
        for j, g in enumerate(settings.gaits):
            s = summaries[k][c * n_g + j]
            rows.append([g, cond.get("network", "ml"), cond["cpg_seed"],
                         cond.get("friction_scale", 1.0),
                         cond.get("push", ""), cond.get("weights", {}).get(g, ""),
                         cond.get("feedback", 0.0),
                         round(float(best_costs[c, j]), 4),
                         s["fell"], s["physical_gait"], _r(s["speed_mps"]), _r(s["froude"]),
                         _r(s["duty_factor"]["left"]), _r(s["duty_factor"]["right"]),
                         _r(s["flight"]), _r(s["apex_height_m"]), _r(s["stride_cv"]),
                         _r(s["ankle_excursion_deg"]),
                         "" if late[c * n_g + j] is None else late[c * n_g + j],
                         *((PARTNER[g], *cond["change"]) if "change" in cond else ("", "", "")),
                         condition_trial(g, (), cond).feedback_form or ""])
    write_csv(rd.path("tune_conditions.csv"), head, rows)
    return {"gains": gains, "entry": entry, "best": summaries[k], "params": tuned}


def _r(x, nd: int = 4):
    try:
        return round(float(x), nd)
    except (TypeError, ValueError):
        return ""


def hand_values(base: ControlParams, values: dict[str, float]) -> ControlParams:
    """``base`` with ``values`` ({"<corner>.<gain>", "startup.<corner>.<gain>" or a shared
    name: value}) set, every name checked against the tuner's parameters first."""
    names = list(values)
    known = {v[0] for v in variables(TuneSettings(gaits=GAITS, search="both", only=tuple(
        n.split(".")[-1] for n in names) + tuple(n for n in names if n.startswith(STARTUP))))}
    bad = [n for n in names if n not in known]
    if bad:
        raise InputError(f"unknown gain {', '.join(map(repr, bad))}: use <corner>.<gain>, "
                         f"startup.<corner>.<gain> or a shared name")
    return with_values(base, names, [values[n] for n in names])


def set_by_hand(start: str | Path, values: dict[str, float], out: str | Path, why: str) -> dict:
    """A link of a tuning chain that is not a search: ``start``'s gains with ``values``
    (:func:`hand_values`) set by hand,
    written to ``out`` with a provenance entry (hand_set, what was set and why, and the
    SHA-256 of the values it started from and ended with, as a search's entry has), for a
    search that needs a start outside the basin the previous link ended in
    (scripts/tune_run_experiment.sh)."""
    from cpgbiped.cpg.io import write_json

    base, provenance = read_gains(start)
    names = list(values)
    p = hand_values(base, values)
    entry = {"part": sorted({n.rsplit(".", 1)[0] for n in names if "." in n}) or ["shared"],
             "hand_set": True, "set": {n: float(values[n]) for n in names}, "note": why,
             "command": f"set by hand ({', '.join(names)})",
             "started_from": str(start), "started_from_sha256": params_sha256(base),
             "result_sha256": params_sha256(p)}
    gains = {"format": GAINS_FORMAT, **params_to_dict(p), "provenance": list(provenance) + [entry]}
    write_json(out, gains)
    return gains


def hand_set_link(argv: list[str], subdir: str, values: dict[str, float], why: str) -> dict:
    """The command line of a hand-set link of scripts/tune_gains.sh, ``START.json OUT``:
    :func:`set_by_hand` from START's gains into OUT/<subdir>/gains.json."""
    if len(argv) != 2:
        raise SystemExit("usage: START.json OUT (a link of scripts/tune_gains.sh)")
    out = Path(argv[1]) / subdir
    out.mkdir(parents=True, exist_ok=True)
    return set_by_hand(argv[0], values, out / "gains.json", why)


def set_startup(start: str | Path, startup_from: str | Path, tau_s: float, out: str | Path,
                why: str) -> dict:
    """A link of a tuning chain that is not a search: ``start``'s gains with start-up gains,
    the four corners of ``startup_from``'s gains, handed over to ``start``'s corners as
    exp(-t / tau_s) (:class:`cpgbiped.envs.control.controller.ControlParams`), written to
    ``out`` with a provenance entry as :func:`set_by_hand` writes (what was set, why, the
    SHA-256 of the values it started from, of the start-up corners' source, and of the result)."""
    from dataclasses import replace

    from cpgbiped.cpg.io import write_json

    base, provenance = read_gains(start)
    source, _ = read_gains(startup_from)
    corners = tuple(source.corner(c) for c in kernel.CORNERS)
    p = params_from_dict(params_to_dict(replace(base, startup=corners, startup_tau_s=float(tau_s))),
                         "start-up gains")
    entry = {"part": ["startup"], "hand_set": True,
             "set": {"startup.tau_s": float(tau_s), "startup.corners": str(startup_from)},
             "startup_from_sha256": params_sha256(source), "note": why,
             "command": f"set by hand (start-up gains: the corners of {startup_from}, "
                        f"tau_s {float(tau_s):g})",
             "started_from": str(start), "started_from_sha256": params_sha256(base),
             "result_sha256": params_sha256(p)}
    gains = {"format": GAINS_FORMAT, **params_to_dict(p), "provenance": list(provenance) + [entry]}
    write_json(out, gains)
    return gains
