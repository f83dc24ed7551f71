"""Acceptance criteria of the physical gaits, as data: the one place the physical classifier,
the tests, the tuner and the README's table read them from.

Each gait has a *pattern* (what the contact-only classifier checks: left-right lag, duty
factor, double support, flight) and *acceptance* terms that need more than one rollout or the
distance (at least 2 m; farther than another gait; duty above or below another gait's).
Quantities are those of :mod:`envs.gait_metrics`: lag in strides (0 together, 0.5
alternating), duty factor per foot, double support and flight as fractions of the time.
The numbers are those of the physical-biped issue; ``HOP_DUTY`` (the mean duty factor that
separates a hop from a jump in a single rollout) is this project's choice, since the issue
only orders them (hop's duty below jump's). So is ``duty_gap_max`` for jump and hop: both
feet share the stance (duty factors within 0.1), added after a tuning run found a "hop" that met
every other criterion on one leg (duty 0.11 left, 0.76 right).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

HOP_DUTY = 0.45
SETTLE_S = 2.0  # s of each rollout before the metrics' window (the body starts standing)
WINDOW_S = 20.0  # s of the metrics' window in the tests and the README


@dataclass(frozen=True)
class Criteria:
    gait: str
    lag: float  # target left-right lag (strides)
    lag_tol: float
    duty_min: float | None = None  # every foot
    duty_max: float | None = None  # every foot (strictly below)
    mean_duty_min: float | None = None
    mean_duty_max: float | None = None  # strictly below
    double_support_min: float | None = None  # strictly above
    flight_min: float | None = None
    flight_max: float | None = None  # strictly below
    duty_gap_max: float | None = None  # |duty left - duty right| at most this: both feet
    # share the stance (a two-legged gait, not one leg hopping while the other taps)
    # acceptance only
    distance_min_m: float | None = None
    farther_than: str | None = None
    duty_above: str | None = None  # mean duty factor above that gait's
    duty_below: str | None = None

    def pattern_failures(self, m) -> list[str]:
        """What of the pattern a metrics object (GaitMetrics or its dict) misses; [] = match."""
        g = m if isinstance(m, dict) else m.as_dict()
        duty = np.array([g["duty_factor"]["left"], g["duty_factor"]["right"]], dtype=float)
        lag = float(g["lr_phase_lag"]) if g["lr_phase_lag"] is not None else float("nan")
        flight = _num(g["flight"])
        double = _num(g["double_support"])
        out = []
        d = abs(((lag - self.lag) + 0.5) % 1.0 - 0.5) if np.isfinite(lag) else np.inf
        if not d <= self.lag_tol:
            out.append(f"left-right lag {lag:.2f} not within {self.lag} +- {self.lag_tol}")
        if self.duty_min is not None and not np.all(duty >= self.duty_min):
            out.append(f"duty factor {duty.min():.2f} below {self.duty_min}")
        if self.duty_max is not None and not np.all(duty < self.duty_max):
            out.append(f"duty factor {duty.max():.2f} not below {self.duty_max}")
        if self.mean_duty_min is not None and not duty.mean() >= self.mean_duty_min:
            out.append(f"mean duty factor {duty.mean():.2f} below {self.mean_duty_min}")
        if self.mean_duty_max is not None and not duty.mean() < self.mean_duty_max:
            out.append(f"mean duty factor {duty.mean():.2f} not below {self.mean_duty_max}")
        if self.double_support_min is not None and not double > self.double_support_min:
            out.append(f"double support {double:.2f} not above {self.double_support_min}")
        if self.flight_min is not None and not flight >= self.flight_min:
            out.append(f"flight {flight:.2f} below {self.flight_min}")
        if self.flight_max is not None and not flight < self.flight_max:
            out.append(f"flight {flight:.2f} not below {self.flight_max}")
        gap = abs(duty[0] - duty[1])
        if self.duty_gap_max is not None and not gap <= self.duty_gap_max:
            out.append(f"duty factors {duty[0]:.2f}/{duty[1]:.2f} differ by more than "
                       f"{self.duty_gap_max}")
        return out

    def failures(self, s: dict, others: dict | None = None) -> list[str]:
        """Every criterion a rollout summary (``Validation.summary()``) misses: no fall, both
        classifiers name the gait, the pattern, the distance, and the comparisons with the
        other gaits' summaries in ``others`` (gait -> summary) where given."""
        out = []
        if s["fell"]:
            out.append(f"fell at {s['fell_at_s']} s")
        if s["physical_gait"] != self.gait:
            out.append(f"physical gait {s['physical_gait']}")
        if s.get("cpg_gait", self.gait) != self.gait:
            out.append(f"CPG gait {s['cpg_gait']}")
        out += self.pattern_failures(s)
        if self.distance_min_m is not None and not s["distance_m"] >= self.distance_min_m:
            out.append(f"distance {s['distance_m']:.2f} m below {self.distance_min_m} m")
        others = others or {}
        if self.farther_than in others and not s["distance_m"] > others[self.farther_than]["distance_m"]:
            out.append(f"distance {s['distance_m']:.2f} m not beyond {self.farther_than}'s "
                       f"{others[self.farther_than]['distance_m']:.2f} m")
        if self.duty_above in others and not mean_duty(s) > mean_duty(others[self.duty_above]):
            out.append(f"mean duty {mean_duty(s):.2f} not above {self.duty_above}'s "
                       f"{mean_duty(others[self.duty_above]):.2f}")
        if self.duty_below in others and not mean_duty(s) < mean_duty(others[self.duty_below]):
            out.append(f"mean duty {mean_duty(s):.2f} not below {self.duty_below}'s "
                       f"{mean_duty(others[self.duty_below]):.2f}")
        return out

    def shortfall(self, s: dict, others: dict | None = None, margin: float = 0.0) -> float:
        """How far a rollout summary is from meeting the criteria, as one non-negative number
        (0 = met with ``margin`` to spare): the sum of the shortfalls of each threshold, in
        its own units (strides, fractions of time, fractions of a 20 s walk's 2 m), for the
        tuner. A fall is not scored here (the caller knows how long the body survived)."""
        if s["lr_phase_lag"] is None or not np.isfinite(_num(s["lr_phase_lag"])):
            lag_err = 0.5
        else:
            lag_err = abs(((float(s["lr_phase_lag"]) - self.lag) + 0.5) % 1.0 - 0.5)
        duty = np.nan_to_num(np.array([_num(s["duty_factor"]["left"]),
                                       _num(s["duty_factor"]["right"])]), nan=0.0)
        flight = np.nan_to_num(_num(s["flight"]), nan=1.0)
        double = np.nan_to_num(_num(s["double_support"]), nan=0.0)
        m = margin
        c = max(0.0, lag_err - self.lag_tol + m)
        if self.duty_min is not None:
            c += np.maximum(0.0, self.duty_min + m - duty).sum()
        if self.duty_max is not None:
            c += np.maximum(0.0, duty - self.duty_max + m).sum()
        if self.mean_duty_min is not None:
            c += max(0.0, self.mean_duty_min + m - duty.mean())
        if self.mean_duty_max is not None:
            c += max(0.0, duty.mean() - self.mean_duty_max + m)
        if self.double_support_min is not None:
            c += max(0.0, self.double_support_min + m - double)
        if self.flight_min is not None:
            c += max(0.0, self.flight_min + m - flight)
        if self.flight_max is not None:
            c += max(0.0, flight - self.flight_max + m / 5)
        if self.duty_gap_max is not None:
            c += max(0.0, abs(duty[0] - duty[1]) - self.duty_gap_max + m)
        if self.distance_min_m is not None:
            c += max(0.0, self.distance_min_m * (1 + m) - s["distance_m"]) / 2.0
        others = others or {}
        if self.farther_than in others:
            c += max(0.0, others[self.farther_than]["distance_m"] * (1 + m) - s["distance_m"]) / 2.0
        if self.duty_above in others:
            c += max(0.0, mean_duty(others[self.duty_above]) + m - duty.mean())
        if self.duty_below in others:
            c += max(0.0, duty.mean() - mean_duty(others[self.duty_below]) + m)
        return float(c)

    def describe(self) -> str:
        """The criteria as one line of text (README table)."""
        parts = ["no fall"]
        parts.append("together within 0.1 stride" if self.lag == 0.0
                     else f"lag {self.lag} ± {self.lag_tol}")
        if self.duty_min is not None:
            parts.append(f"duty ≥ {self.duty_min}")
        if self.duty_max is not None:
            parts.append(f"duty < {self.duty_max}")
        if self.mean_duty_min is not None:
            parts.append(f"mean duty ≥ {self.mean_duty_min}")
        if self.mean_duty_max is not None:
            parts.append(f"mean duty < {self.mean_duty_max}")
        if self.double_support_min is not None:
            parts.append(f"double support > {self.double_support_min:.0%}")
        if self.flight_min is not None:
            parts.append(f"flight ≥ {self.flight_min:.0%}")
        if self.flight_max is not None:
            parts.append(f"flight < {self.flight_max:.0%}")
        if self.duty_gap_max is not None:
            parts.append(f"both feet's duty within {self.duty_gap_max}")
        if self.distance_min_m is not None:
            parts.append(f"≥ {self.distance_min_m:g} m")
        if self.farther_than:
            parts.append(f"farther than {self.farther_than}")
        if self.duty_above:
            parts.append(f"duty above {self.duty_above}'s")
        if self.duty_below:
            parts.append(f"duty below {self.duty_below}'s")
        return ", ".join(parts)


def _num(x) -> float:
    return float("nan") if x is None else float(x)


def mean_duty(s: dict) -> float:
    return float(np.mean([_num(s["duty_factor"]["left"]), _num(s["duty_factor"]["right"])]))


CRITERIA = {
    "walk": Criteria("walk", 0.5, 0.1, duty_min=0.55, double_support_min=0.05, flight_max=0.02,
                     distance_min_m=2.0),
    "run": Criteria("run", 0.5, 0.1, duty_max=0.5, flight_min=0.10, farther_than="walk"),
    "jump": Criteria("jump", 0.0, 0.1, flight_min=0.10, mean_duty_min=HOP_DUTY,
                     duty_gap_max=0.1,
                     duty_above="hop"),
    "hop": Criteria("hop", 0.0, 0.1, flight_min=0.15, mean_duty_max=HOP_DUTY,
                    duty_gap_max=0.1,
                    duty_below="jump"),
}
PHYSICAL_GAITS = tuple(CRITERIA)


def criteria_markdown() -> str:
    """The criteria as the Markdown table the README shows."""
    rows = ["| gait | criteria (20 s after 2 s of settling; both classifiers agree) |",
            "|---|---|"]
    rows += [f"| {g} | {c.describe()} |" for g, c in CRITERIA.items()]
    return "\n".join(rows) + "\n"
