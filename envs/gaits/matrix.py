"""The gait matrix: every preset of a network through the one controller.

The controller never sees the preset's name, so the physical gait in each row comes from the
network alone. A diagonal matrix (each preset its own physical gait) is the evidence that the
CPG, not a label, chooses the gait.
"""
from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.network import KINDS, PRESETS, build

from cpgbiped.envs.simulation.rollout import check_seconds

KEYS = ("physical_gait", "cpg_gait", "fell", "fell_at_s", "duty_factor", "lr_phase_lag",
        "double_support", "flight", "stride_period_s", "cpg_period_s", "distance_m",
        "speed_mps", "footfalls_per_stride")


def _row(args) -> dict:
    from cpgbiped.envs.gaits.validate import validate

    kind, preset, seed, seconds, feedback = args
    net = build(kind, preset, seed=seed)
    net.period()
    s = validate(net, None, seconds, feedback=feedback).summary()
    return {k: s[k] for k in KEYS}


def matrix(kind: str = "ml", seconds: float = 20.0, seed: int | None = None,
           workers: int = 2, feedback: float = 0.0) -> dict:
    """{"network": kind, "rows": {preset: {physical_gait, fell, ...metrics}}}; ``feedback``:
    the gain K of the body's feedback into the CPG (0: open loop)."""
    if kind not in KINDS:
        raise InputError(f"unknown network {kind!r}: use {', '.join(KINDS)}")
    check_seconds(seconds)
    if seed is not None and seed < 0:
        raise InputError(f"--seed must be a non-negative integer, got {seed}")
    if workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    for p in PRESETS[kind]:  # a clear error before any process starts
        build(kind, p, seed=seed)
    from cpgbiped.cpg.feedback import check_gain

    feedback = check_gain(kind, feedback)
    jobs = [(kind, p, seed, seconds, feedback) for p in PRESETS[kind]]
    if workers == 1 or len(jobs) == 1:
        rows = [_row(j) for j in jobs]
    else:
        # spawn, not fork: the parent may already run GNU OpenMP threads (numba, BLAS), and
        # forking such a process aborts the child.
        ctx = multiprocessing.get_context("spawn")
        from cpgbiped.envs.simulation.trials import quiet_worker

        with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=ctx,
                                 initializer=quiet_worker) as ex:
            rows = list(ex.map(_row, jobs))
    return {"network": kind, "seed": seed, "seconds": seconds, "feedback_gain": feedback,
            "rows": dict(zip(PRESETS[kind], rows))}


def matrix_table(res: dict) -> str:
    from cpgbiped.envs.gaits.validate import metrics_table

    summaries = {p: dict(r, gait=None) for p, r in res["rows"].items()}
    text = metrics_table(summaries)
    diag = sum(r["physical_gait"] == p for p, r in res["rows"].items())
    return text + f"\n{diag} of {len(res['rows'])} presets give their own physical gait"
