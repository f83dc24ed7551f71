"""Pareto-optimal weight sets checked in physics: every point through the validation."""
from __future__ import annotations

import csv
import io as _io
import os
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.io import to_json, write_json, write_text
from cpgbiped.cpg.outdir import ResultDir
from cpgbiped.cpg.results import load_result, point_cell


def _one(args):
    gait, k, weights, i_app, phi, seconds, render_dir = args
    from cpgbiped.cpg.network import build
    from cpgbiped.envs.gaits.validate import validate

    net = build("ml", gait, weights=weights, i_app=i_app, phi=phi)
    v = validate(net, gait, seconds, stop_on_fall=render_dir is None)
    video = None
    if render_dir is not None:
        from cpgbiped.envs.media.render import render_video

        video = f"point_{k:03d}.mp4"  # beside pareto_check.json
        render_video(v.recording, Path(render_dir) / video, seconds=min(seconds, 8.0), width=480,
                     height=360)
    return k, v.summary(), video, (v.recording, v.metrics)


def _pool_map(fn, jobs, workers: int, progress: bool, desc: str):
    """fn over jobs in worker processes, in order, with a progress bar. On Ctrl-C the pending
    jobs are cancelled and the workers terminated at once (no wait for running rollouts)."""
    from tqdm import tqdm

    # spawn: forking a parent that already runs OpenMP threads aborts the child
    from cpgbiped.envs.simulation.trials import quiet_worker

    ex = ProcessPoolExecutor(min(workers, len(jobs)),
                             mp_context=multiprocessing.get_context("spawn"),
                             initializer=quiet_worker)
    try:
        futures = [ex.submit(fn, j) for j in jobs]
        out = []
        for f in tqdm(futures, total=len(jobs), disable=not progress, desc=desc, unit="point"):
            out.append(f.result())
        ex.shutdown()
        return out
    except BaseException:
        for proc in list(getattr(ex, "_processes", {}).values()):
            proc.terminate()
        ex.shutdown(wait=False, cancel_futures=True)
        raise


def check_pareto(result: str, out: str, first: int | None = None, seconds: float = 20.0,
                 render: bool = False, rrd: str | None = None, workers: int = 2,
                 progress: bool = True) -> dict:
    data = load_result(result)
    if first is not None and first < 1:
        raise InputError(f"--first must be at least 1, got {first}")
    if workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    if rrd is not None and not str(rrd).endswith(".rrd"):
        raise InputError(f"--rrd must name an .rrd file, got {rrd!r}")
    points = data["pareto"][:first] if first else data["pareto"]
    if not points:
        raise InputError(f"{result!r} holds no Pareto points to check")
    gait = data["gait"]
    with ResultDir(out) as rd:
        jobs = [(gait, k, p["weights"], *point_cell(data, p), seconds,
                 str(rd.staging) if render else None) for k, p in enumerate(points)]
        results = {k: (summary, video, rec) for k, summary, video, rec in
                   _pool_map(_one, jobs, workers, progress, f"physics check {gait}")}
        report = _write(rd, result, data, gait, points, seconds, results, rrd)
        rd.commit()
    return report


def _write(rd, result, data, gait, points, seconds, results, rrd) -> dict:
    """Write the table, CSV and JSON into the staging folder; the report."""
    rows = []
    for k, p in enumerate(points):
        s, video, _ = results[k]
        i_app, phi = point_cell(data, p)
        rows.append({"point": k, "weights": p["weights"], "i_app": i_app, "phi": phi,
                     "errors_deg": p.get("errors_deg"), "objectives": p.get("objectives"),
                     **{key: s[key] for key in ("fell", "duty_factor", "lr_phase_lag",
                                                "double_support", "flight", "stride_period_s",
                                                "distance_m", "speed_mps", "physical_gait",
                                                "cpg_gait", "passed")},
                     "video": video})
    md = [f"## Pareto points of {os.path.basename(result)} ({gait}) in physics, {seconds:g} s", "",
          "| # | w_a, w_b, w_c | I_app, phi | objectives | fell | duty L/R | lag | flight "
          "| dist m | physical | cpg | verdict |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        d = r["duty_factor"]
        obj = (r["objectives"] or {}) if r["errors_deg"] is None else {
            "phase errors (deg)": ", ".join(f"{e:.3f}" for e in r["errors_deg"])}
        md.append(f"| {r['point']} | {', '.join(f'{w:.3f}' for w in r['weights'])} | "
                  f"{r['i_app']:.3f}, {r['phi']:.3f} | "
                  f"{'; '.join(f'{n} {v:.3g}' if isinstance(v, float) else f'{n} {v}' for n, v in obj.items())} | "
                  f"{'yes' if r['fell'] else 'no'} "
                  f"| {d['left']:.2f}/{d['right']:.2f} | {r['lr_phase_lag']:.2f} | {r['flight']:.2f} "
                  f"| {r['distance_m']:.2f} | {r['physical_gait']} | {r['cpg_gait']} | "
                  f"{'PASS' if r['passed'] else 'fail'} |")
    markdown = "\n".join(md) + "\n"
    buf = _io.StringIO()
    w = csv.writer(buf)
    w.writerow(["point", "w_a", "w_b", "w_c", "i_app", "phi", "z_RF", "z_LE", "z_RE", "fell",
                "duty_left",
                "duty_right", "lr_phase_lag", "double_support", "flight", "stride_period_s",
                "distance_m", "speed_mps", "physical_gait", "cpg_gait", "passed"])
    for r in rows:
        w.writerow([r["point"], *r["weights"], r["i_app"], r["phi"],
                    *(r["errors_deg"] or ["", "", ""]), r["fell"], r["duty_factor"]["left"],
                    r["duty_factor"]["right"], r["lr_phase_lag"], r["double_support"], r["flight"],
                    r["stride_period_s"], r["distance_m"], r["speed_mps"], r["physical_gait"],
                    r["cpg_gait"], r["passed"]])
    if rrd:
        from cpgbiped.envs.media.record import write_rrd

        write_rrd(rrd, {f"point_{k:03d}": results[k][2] for k in sorted(results)})
    write_text(rd.path("pareto_check.md"), markdown)
    write_text(rd.path("pareto_check.csv"), buf.getvalue())
    write_json(rd.path("pareto_check.json"), {"result": str(result), "gait": gait, "points": rows})
    return {"markdown": markdown, "rows": rows, "json": to_json(rows)}
