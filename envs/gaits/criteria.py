"""Acceptance criteria of the physical gaits, as data: the one place the physical classifier,
the tests, the tuner and the README's tables read them from.

Each gait has two kinds of terms.

*Pattern* terms are what the physical classifier checks on one rollout, from the foot
contacts (and, for the two-legged gaits, the ankle): left-right lag in strides (0 together,
0.5 alternating), duty factor per foot, double support and flight as fractions of the time,
both feet sharing the stance (duty factors within 0.1), and the ankle's excursion in stance
(:func:`cpgbiped.envs.gaits.gait_metrics.ankle_excursion`).

*Quality* terms say whether the gait moves as animals' gaits do (the gait-quality issue):
the Froude number Fr = v^2 / (g L), the relative stride length against Alexander's
lambda / L = 2.3 Fr^0.3, duty-factor and flight windows, the apex of the centre of mass in
flight, the mean speed (the bouncing gaits must not drift backwards) and the stride-to-stride
regularity; one relative term (the hop's cadence above the jump's) compares two rollouts of
the same condition.

Jump against hop. The source paper tells its two-legged gaits apart by the ankle: in the jump
the ankle flexor and extensor alternate (the ankle rotates: a push-off), in the hop all four
cells fire together (co-activation locks the ankle: a spring). Biomechanics separates hopping
from jumping the same way, never by duty factor: two-legged hopping at its preferred frequency
is a spring-mass bounce whose leg stiffness is set mainly at the ankle (Farley et al. 1991;
Farley & Morgenroth 1999), whereas a jump's push-off rotates the ankle through a wide range
(40-55 deg of plantarflexion in human counter-movement and spike jumps). So the split is
measured on the body: the median range of the ankle angle over the stance phases, split at
``ANKLE_SPLIT_DEG`` = 30 deg. Below it the ankle is held: a co-activated ankle of this body
has a stiffness of 50 + 2 x 150 x a N m/rad (passive spring plus both muscles at activation
a), about 150 N m/rad at the controller's ankle gain; a bounce of 2.5 body weights with the
centre of pressure 10 cm ahead of the ankle bends it by about 20 deg. Above it the ankle
rotates through a push-off, as in human jumps (38-58 deg of ankle range in counter-movement
and spike jumps). The split is the middle of that gap, and the tests check that it separates
the presets with a margin in every test condition (tests/test_physics.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SETTLE_S = 2.0  # s of each rollout before the metrics' window (the body starts standing)
WINDOW_S = 20.0  # s of the metrics' window in the tests and the README
ALEXANDER_A, ALEXANDER_B = 2.3, 0.3  # lambda / L = 2.3 Fr^0.3 (Alexander 1989)
# Ankle excursion in stance (deg) that separates a rotating ankle (jump) from one held stiff
# (hop): between a co-activated ankle's bend under a bounce (about 20 deg) and a jump's
# push-off (38 deg and more); the module docstring derives it.
ANKLE_SPLIT_DEG = 30.0


def alexander_relative_stride(froude: float) -> float:
    """lambda / L of a dynamically similar gait at Froude number ``froude`` (Alexander)."""
    return ALEXANDER_A * max(float(froude), 0.0) ** ALEXANDER_B


@dataclass(frozen=True)
class Criteria:
    gait: str
    # -- pattern: the physical classifier (one rollout, contacts and ankle)
    lag: float  # target left-right lag (strides)
    lag_tol: float
    duty_min: float | None = None  # every foot
    duty_max: float | None = None  # every foot (strictly below)
    double_support_min: float | None = None  # strictly above
    flight_min: float | None = None
    flight_max: float | None = None  # strictly below
    duty_gap_max: float | None = None  # |duty left - duty right| at most this: both feet
    # share the stance (a two-legged gait, not one leg hopping while the other taps)
    ankle_min_deg: float | None = None  # ankle excursion in stance at least this
    ankle_max_deg: float | None = None  # ... strictly below this
    # -- quality: the gait-quality targets (one rollout)
    froude_min: float | None = None  # v^2 / (g L), moving forwards
    alexander_tol: float | None = None  # |lambda/L / (2.3 Fr^0.3) - 1| at most this
    quality_duty: tuple[float, float] | None = None  # every foot's duty factor in [lo, hi]
    quality_flight: tuple[float, float] | None = None  # flight fraction in [lo, hi]
    apex_min_m: float | None = None  # apex of the centre of mass in flight
    speed_min_mps: float | None = None  # mean forward speed (negative: backwards)
    stride_cv_max: float | None = None  # strictly below
    # -- relative: compared with another gait's rollout of the same condition
    cadence_above: str | None = None  # stride period shorter than that gait's

    # ------------------------------------------------------------------------- pattern
    def pattern_failures(self, m) -> list[str]:
        """What of the pattern a metrics object (GaitMetrics or its dict) misses; [] = match."""
        g = m if isinstance(m, dict) else m.as_dict()
        duty = np.array([_num(g["duty_factor"]["left"]), _num(g["duty_factor"]["right"])])
        lag = _num(g["lr_phase_lag"])
        flight = _num(g["flight"])
        double = _num(g["double_support"])
        out = []
        d = abs(((lag - self.lag) + 0.5) % 1.0 - 0.5) if np.isfinite(lag) else np.inf
        if not d <= self.lag_tol:
            out.append(f"left-right lag {lag:.2f} not within {self.lag} +- {self.lag_tol}")
        if self.duty_min is not None and not np.all(duty >= self.duty_min):
            out.append(f"duty factor {_extreme(duty, min):.2f} below {self.duty_min}")
        if self.duty_max is not None and not np.all(duty < self.duty_max):
            out.append(f"duty factor {_extreme(duty, max):.2f} not below {self.duty_max}")
        if self.double_support_min is not None and not double > self.double_support_min:
            out.append(f"double support {double:.2f} not above {self.double_support_min}")
        if self.flight_min is not None and not flight >= self.flight_min:
            out.append(f"flight {flight:.2f} below {self.flight_min}")
        if self.flight_max is not None and not flight < self.flight_max:
            out.append(f"flight {flight:.2f} not below {self.flight_max}")
        if self.duty_gap_max is not None and not abs(duty[0] - duty[1]) <= self.duty_gap_max:
            out.append(f"duty factors {duty[0]:.2f}/{duty[1]:.2f} differ by more than "
                       f"{self.duty_gap_max}")
        ankle = _num(g.get("ankle_excursion_deg"))
        if self.ankle_min_deg is not None and not ankle >= self.ankle_min_deg:
            out.append(f"ankle excursion in stance {ankle:.1f} deg below {self.ankle_min_deg:g} "
                       f"(the ankle does not rotate)")
        if self.ankle_max_deg is not None and not ankle < self.ankle_max_deg:
            out.append(f"ankle excursion in stance {ankle:.1f} deg not below "
                       f"{self.ankle_max_deg:g} (the ankle is not held stiff)")
        return out

    # ------------------------------------------------------------------------- quality
    def quality_failures(self, s: dict) -> list[str]:
        """What of the quality targets a rollout summary (``Validation.summary()``, with its
        biomechanics) misses."""
        out = []
        v = _num(s.get("speed_mps"))
        fr = _num(s.get("froude"))
        signed_fr = fr if v >= 0 else -fr
        if self.froude_min is not None and not signed_fr >= self.froude_min:
            out.append(f"Froude number {signed_fr:.3f} below {self.froude_min}")
        if self.alexander_tol is not None:
            ratio = _num(s.get("relative_stride_length")) / alexander_relative_stride(fr) \
                if fr > 0 else np.nan
            if not abs(ratio - 1.0) <= self.alexander_tol:
                out.append(f"stride length {ratio:.2f} x Alexander's 2.3 Fr^0.3, not within "
                           f"{self.alexander_tol:.0%}")
        if self.quality_duty is not None:
            lo, hi = self.quality_duty
            for leg in ("left", "right"):
                d = _num(s["duty_factor"][leg])
                if not lo <= d <= hi:
                    out.append(f"{leg} duty factor {d:.2f} not in {lo}-{hi}")
        if self.quality_flight is not None:
            lo, hi = self.quality_flight
            f = _num(s.get("flight"))
            if not lo <= f <= hi:
                out.append(f"flight {f:.2f} not in {lo}-{hi}")
        if self.apex_min_m is not None and not _num(s.get("apex_height_m")) >= self.apex_min_m:
            out.append(f"apex {100 * _num(s.get('apex_height_m')):.1f} cm below "
                       f"{100 * self.apex_min_m:g} cm")
        if self.speed_min_mps is not None and not v >= self.speed_min_mps:
            out.append(f"mean speed {v:.2f} m/s below {self.speed_min_mps} m/s")
        if self.stride_cv_max is not None and not _num(s.get("stride_cv")) < self.stride_cv_max:
            out.append(f"stride CV {_num(s.get('stride_cv')):.3f} not below "
                       f"{self.stride_cv_max}")
        return out

    def failures(self, s: dict, others: dict | None = None) -> list[str]:
        """Every criterion a rollout summary (``Validation.summary()``) misses: no fall, both
        classifiers name the gait, the pattern, the quality targets, and the comparisons with
        the other gaits' summaries in ``others`` (gait -> summary) where given."""
        out = []
        if s["fell"]:
            out.append(f"fell at {s['fell_at_s']:.2f} s")
        if s["physical_gait"] != self.gait:
            out.append(f"physical gait {s['physical_gait']}")
        if s.get("cpg_gait", self.gait) != self.gait:
            out.append(f"CPG gait {s['cpg_gait']}")
        out += self.pattern_failures(s)
        out += self.quality_failures(s)
        others = others or {}
        if self.cadence_above in others:
            mine, theirs = _num(s["stride_period_s"]), _num(others[self.cadence_above]
                                                             ["stride_period_s"])
            if not mine < theirs:
                out.append(f"stride {mine:.3f} s not shorter than the {self.cadence_above}'s "
                           f"{theirs:.3f} s")
        return out

    def shortfall(self, s: dict, margin: float = 0.0) -> float:
        """How far one rollout summary is from meeting the pattern and quality terms, as one
        non-negative number (0 = met with ``margin`` to spare), for the tuner. Each term is a
        shortfall in its own units scaled to about 1 for a clear miss: strides, fractions of
        time, relative Froude number and stride length, apex relative to its target, speed per
        0.1 m/s, ankle excursion per 20 deg. Falls, the classifiers' names and the comparisons
        with other rollouts are not scored here (the caller knows how long the body survived)."""
        m = margin
        duty = np.nan_to_num([_num(s["duty_factor"]["left"]), _num(s["duty_factor"]["right"])],
                             nan=0.0)
        lag = _num(s.get("lr_phase_lag"))
        lag_err = abs(((lag - self.lag) + 0.5) % 1.0 - 0.5) if np.isfinite(lag) else 0.5
        flight = np.nan_to_num(_num(s.get("flight")), nan=1.0)
        double = np.nan_to_num(_num(s.get("double_support")), nan=0.0)
        c = 2.0 * max(0.0, lag_err - self.lag_tol + m)
        if self.duty_min is not None:
            c += float(np.maximum(0.0, self.duty_min + m - duty).sum())
        if self.duty_max is not None:
            c += float(np.maximum(0.0, duty - self.duty_max + m).sum())
        if self.double_support_min is not None:
            c += max(0.0, self.double_support_min + m - double)
        if self.flight_min is not None:
            c += max(0.0, self.flight_min + m - flight)
        if self.flight_max is not None:
            c += max(0.0, flight - self.flight_max + m / 5)
        if self.duty_gap_max is not None:
            c += max(0.0, abs(duty[0] - duty[1]) - self.duty_gap_max + m)
        ankle = _num(s.get("ankle_excursion_deg"))
        if self.ankle_min_deg is not None:
            a = np.nan_to_num(ankle, nan=0.0)
            c += max(0.0, self.ankle_min_deg * (1 + m) - a) / 20.0
        if self.ankle_max_deg is not None:
            a = np.nan_to_num(ankle, nan=2 * self.ankle_max_deg)
            c += max(0.0, a - self.ankle_max_deg * (1 - m)) / 20.0
        v = np.nan_to_num(_num(s.get("speed_mps")), nan=0.0)
        fr = np.nan_to_num(_num(s.get("froude")), nan=0.0) * (1.0 if v >= 0 else -1.0)
        if self.froude_min is not None:
            c += max(0.0, self.froude_min * (1 + m) - fr) / self.froude_min
        if self.alexander_tol is not None:
            ratio = (_num(s.get("relative_stride_length")) / alexander_relative_stride(fr)
                     if fr > 0 else 0.0)
            c += max(0.0, abs(np.nan_to_num(ratio, nan=0.0) - 1.0) - self.alexander_tol + m)
        if self.quality_duty is not None:
            lo, hi = self.quality_duty
            c += float(np.maximum(0.0, lo + m - duty).sum() + np.maximum(0.0, duty - hi + m).sum())
        if self.quality_flight is not None:
            lo, hi = self.quality_flight
            c += max(0.0, lo + m - flight) + max(0.0, flight - hi + m)
        if self.apex_min_m is not None:
            apex = np.nan_to_num(_num(s.get("apex_height_m")), nan=0.0)
            c += max(0.0, self.apex_min_m * (1 + m) - apex) / self.apex_min_m
        if self.speed_min_mps is not None:  # per 0.1 m/s of drift
            c += max(0.0, self.speed_min_mps + m - v) / 0.1
        if self.stride_cv_max is not None:
            cv = np.nan_to_num(_num(s.get("stride_cv")), nan=1.0)
            c += max(0.0, cv - self.stride_cv_max * (1 - m)) / self.stride_cv_max
        return float(c)

    def describe_pattern(self) -> str:
        parts = ["no fall"]
        parts.append("feet together within 0.1 stride" if self.lag == 0.0
                     else f"lag {self.lag} ± {self.lag_tol}")
        if self.duty_min is not None:
            parts.append(f"duty ≥ {self.duty_min}")
        if self.duty_max is not None:
            parts.append(f"duty < {self.duty_max}")
        if self.double_support_min is not None:
            parts.append(f"double support > {self.double_support_min:.0%}")
        if self.flight_min is not None:
            parts.append(f"flight ≥ {self.flight_min:.0%}")
        if self.flight_max is not None:
            parts.append(f"flight < {self.flight_max:.0%}")
        if self.duty_gap_max is not None:
            parts.append(f"both feet's duty within {self.duty_gap_max}")
        if self.ankle_min_deg is not None:
            parts.append(f"ankle excursion in stance ≥ {self.ankle_min_deg:g}°")
        if self.ankle_max_deg is not None:
            parts.append(f"ankle excursion in stance < {self.ankle_max_deg:g}°")
        return ", ".join(parts)

    def describe_quality(self) -> str:
        parts = []
        if self.froude_min is not None:
            parts.append(f"Fr ≥ {self.froude_min}")
        if self.alexander_tol is not None:
            parts.append(f"λ/L within {self.alexander_tol:.0%} of 2.3·Fr^0.3")
        if self.quality_duty is not None:
            parts.append(f"duty {self.quality_duty[0]:.2f}-{self.quality_duty[1]:.2f}")
        if self.quality_flight is not None:
            parts.append(f"flight {self.quality_flight[0]:.0%}-{self.quality_flight[1]:.0%}")
        if self.apex_min_m is not None:
            parts.append(f"apex ≥ {100 * self.apex_min_m:g} cm")
        if self.stride_cv_max is not None:
            parts.append(f"stride CV < {self.stride_cv_max:.0%}")
        if self.speed_min_mps is not None:
            parts.append(f"mean speed ≥ {self.speed_min_mps} m/s")
        if self.cadence_above is not None:
            parts.append(f"cadence above the {self.cadence_above}'s")
        return ", ".join(parts)


def _extreme(values, pick) -> float:
    """min or max of the finite values (NaN when there are none), without NumPy's warning."""
    finite = [float(v) for v in values if np.isfinite(v)]
    return pick(finite) if finite else float("nan")


def _num(x) -> float:
    try:
        return float("nan") if x is None else float(x)
    except (TypeError, ValueError):
        return float("nan")


CRITERIA = {
    "walk": Criteria("walk", 0.5, 0.1, duty_min=0.55, double_support_min=0.05, flight_max=0.02,
                     froude_min=0.08, alexander_tol=0.25, quality_duty=(0.55, 0.70)),
    "run": Criteria("run", 0.5, 0.1, duty_max=0.5, flight_min=0.10,
                    froude_min=0.25, quality_duty=(0.30, 0.45), quality_flight=(0.15, 0.45)),
    "jump": Criteria("jump", 0.0, 0.1, flight_min=0.10, duty_gap_max=0.1,
                     ankle_min_deg=ANKLE_SPLIT_DEG,
                     apex_min_m=0.06, speed_min_mps=-0.05),
    "hop": Criteria("hop", 0.0, 0.1, flight_min=0.10, duty_gap_max=0.1,
                    ankle_max_deg=ANKLE_SPLIT_DEG,
                    apex_min_m=0.04, stride_cv_max=0.05, speed_min_mps=-0.05,
                    cadence_above="jump"),
}
PHYSICAL_GAITS = tuple(CRITERIA)


def criteria_markdown() -> str:
    """The criteria as the Markdown table the README shows."""
    rows = ["| gait | pattern (the physical classifier) | quality targets |", "|---|---|---|"]
    rows += [f"| {g} | {c.describe_pattern()} | {c.describe_quality()} |"
             for g, c in CRITERIA.items()]
    return "\n".join(rows) + "\n"


# ------------------------------------------------------------------- secondary gaits
@dataclass(frozen=True)
class SecondaryPattern:
    """A secondary gait of the network as the contacts show it (names as cpg.gaits). Checked
    only when no primary gait's pattern matches, in the order of SECONDARY_PATTERNS. Lags are
    the left-right touchdown lag in strides (0 together, 0.5 alternating), its distance
    circular; flight and duty as fractions of the window."""

    name: str
    description: str
    check: str  # the rule, in words that mirror secondary_failures()


LAG_TOGETHER = 0.10  # within this of 0: feet land together
LAG_AWAY = 0.12  # at least this far from 0 and from 0.5: a held lag (gallop)
LAG_UNEQUAL = 0.06  # alternating steps at least this far from 0.5: unequal step times
SECONDARY_FLIGHT = 0.05  # flight fraction that counts as flight
ONE_LEG_DUTY = 0.10  # a foot on the ground less than this is "almost never" down
DUTY_UNEQUAL = 0.15  # |duty L - duty R| of an asymmetric hop
SKIP_PAIRS = 0.6  # fraction of same-foot touchdown runs of length two (L L R R)

SECONDARY_PATTERNS = {
    "one_legged_hop": SecondaryPattern(
        "one_legged_hop", "one foot almost never on the ground while the other hops",
        f"one foot's duty < {ONE_LEG_DUTY}, the other >= 3 touchdowns, flight >= "
        f"{SECONDARY_FLIGHT}"),
    "skip": SecondaryPattern(
        "skip", "each foot lands twice in a row: left-left-right-right",
        f">= 4 runs of same-foot touchdowns, >= {SKIP_PAIRS:.0%} of the inner runs of length 2"),
    "asymmetric_hop": SecondaryPattern(
        "asymmetric_hop", "feet together, with unequal duty",
        f"lag within {LAG_TOGETHER} of 0, duties of L and R differ by >= {DUTY_UNEQUAL}, flight >= "
        f"{SECONDARY_FLIGHT}"),
    "gallop": SecondaryPattern(
        "gallop", "a left-right lag held away from both 0 and 0.5, with flight",
        f"lag >= {LAG_AWAY} from 0 and from 0.5, flight >= {SECONDARY_FLIGHT}, about one "
        f"footfall per foot and stride"),
    "hesitation_walk": SecondaryPattern(
        "hesitation_walk", "alternating steps with an unequal step rhythm",
        f"no flight (< {SECONDARY_FLIGHT}), lag >= {LAG_UNEQUAL} from 0.5 and >= {LAG_AWAY} "
        f"from 0, about one footfall per foot and stride"),
}


def _circ(a: float, b: float) -> float:
    d = abs(a - b) % 1.0
    return min(d, 1.0 - d)


def secondary_failures(name: str, m) -> list[str]:
    """What of secondary gait ``name``'s pattern a GaitMetrics (or its dict) misses."""
    g = (lambda k: m[k]) if isinstance(m, dict) else (lambda k: getattr(m, k))  # noqa: E731
    duty = g("duty_factor")
    dl, dr = duty["left"], duty["right"]
    td = g("touchdowns")
    nl, nr = len(td["left"]), len(td["right"])
    lag, flight = g("lr_phase_lag"), g("flight")
    fps = g("footfalls_per_stride") or {"left": float("nan"), "right": float("nan")}
    one_each = all(0.8 <= fps[k] <= 1.25 for k in ("left", "right"))
    out = []
    if name == "one_legged_hop":
        if not (min(dl, dr) < ONE_LEG_DUTY and max(nl, nr) >= 3):
            out.append("both feet share the ground")
        if not flight >= SECONDARY_FLIGHT:
            out.append(f"flight {flight:.2f} < {SECONDARY_FLIGHT}")
        return out
    if min(nl, nr) < 3 or not np.isfinite(lag):
        return ["fewer than 3 touchdowns of a foot"]
    if name == "skip":
        seq = sorted([(t, 0) for t in td["left"]] + [(t, 1) for t in td["right"]])
        feet = [f for _, f in seq]
        runs_, n = [], 1
        for a, b in zip(feet[:-1], feet[1:]):
            if a == b:
                n += 1
            else:
                runs_.append(n)
                n = 1
        inner = runs_[1:]  # the first run may be cut by the window
        if len(inner) < 3 or np.mean([r == 2 for r in inner]) < SKIP_PAIRS:
            out.append("feet do not land twice in a row")
    elif name == "asymmetric_hop":
        if _circ(lag, 0.0) > LAG_TOGETHER:
            out.append(f"lag {lag:.2f}: feet not together")
        if abs(dl - dr) < DUTY_UNEQUAL:
            out.append(f"duties {dl:.2f}/{dr:.2f} not unequal")
        if not flight >= SECONDARY_FLIGHT:
            out.append(f"flight {flight:.2f} < {SECONDARY_FLIGHT}")
    elif name == "gallop":
        if _circ(lag, 0.0) < LAG_AWAY or _circ(lag, 0.5) < LAG_AWAY:
            out.append(f"lag {lag:.2f} not held away from 0 and 0.5")
        if not flight >= SECONDARY_FLIGHT:
            out.append(f"flight {flight:.2f} < {SECONDARY_FLIGHT}")
        if not one_each:
            out.append("not one footfall per foot and stride")
    elif name == "hesitation_walk":
        if not flight < SECONDARY_FLIGHT:
            out.append(f"flight {flight:.2f}")
        if _circ(lag, 0.5) < LAG_UNEQUAL or _circ(lag, 0.0) < LAG_AWAY:
            out.append(f"lag {lag:.2f}: steps not alternating with unequal times")
        if not one_each:
            out.append("not one footfall per foot and stride")
    else:
        raise KeyError(name)
    return out


def secondary_markdown() -> str:
    """The secondary patterns as the Markdown table the README shows."""
    rows = ["| secondary gait | what it is | rule (contacts only) |", "|---|---|---|"]
    rows += [f"| {g.replace('_', ' ')} | {p.description} | {p.check} |"
             for g, p in SECONDARY_PATTERNS.items()]
    return "\n".join(rows) + "\n"
