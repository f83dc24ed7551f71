"""Drive the NSGA-II searches and write their results (JSON, CSV, PNG, Markdown), atomically.

Result file ``<gait>.json`` (format "cpgbiped.optimize/1"): ``chosen`` {weights, errors_deg,
robustness}, ``pareto`` (list of the same), ``paper`` (Table 2 weights evaluated the same
way), ``settings`` and ``i_app``/``phi``. The chosen point has the smallest total error
among the final population (within 0.01 degree counts as a tie), ties broken by robustness
(fraction of random initial states that reach the gait).
"""
from __future__ import annotations

import csv
import io as _io
import time
from pathlib import Path

import numpy as np

from . import morris_lecar as ml
from .errors import InputError
from .evaluate import SimSettings, evaluate, robustness
from .io import atomic_path, write_json, write_text
from .outdir import ResultDir
from .results import FORMAT, SECONDARY_FORMAT, load_result  # noqa: F401 (re-exported)
from .optimize import (SECONDARY_TARGETS, PrimaryGaitProblem, RunSettings,
                       SymmetryBreakingProblem, extensor_lag, run)

TIE_DEG = 0.01
N_TIE_CANDIDATES = 8


def write_csv(path: Path, header: list[str], rows) -> None:
    buf = _io.StringIO()
    w = csv.writer(buf)
    w.writerow(header)
    for r in rows:
        w.writerow(r)
    write_text(path, buf.getvalue())


def plot_front(path: Path, F_pop: np.ndarray, F_opt: np.ndarray, title: str, names,
               symlog: bool = True) -> None:
    """The three 2-D projections of a 3-objective front (grey: the final population; red: the
    Pareto set); ``names`` label the axes; ``symlog`` for phase errors that span decades."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, (a, b) in zip(axes, ((0, 1), (0, 2), (1, 2))):
        ax.scatter(F_pop[:, a], F_pop[:, b], s=10, c="0.7", label="final population")
        ax.scatter(F_opt[:, a], F_opt[:, b], s=18, c="tab:red", label="Pareto set")
        if symlog:
            ax.set_xscale("symlog", linthresh=1e-3)
            ax.set_yscale("symlog", linthresh=1e-3)
        ax.set_xlabel(names[a])
        ax.set_ylabel(names[b])
    axes[0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)


def choose(X: np.ndarray, F: np.ndarray, robust_fn) -> tuple[int, np.ndarray]:
    """Index of the chosen point among feasible points (X, F) and the robustness of the
    candidates examined (NaN elsewhere).

    Candidates are the points whose total error is within ``TIE_DEG`` of the best: with a
    symmetric network many weight sets hit the targets exactly, and those differ only in how
    many initial states lead to the gait. Up to ``N_TIE_CANDIDATES`` of them, spread over
    weight space, are scored by ``robust_fn``; the most robust wins.
    """
    total = F.sum(axis=1)
    ties = np.nonzero(total <= total.min() + TIE_DEG)[0]
    if len(ties) > N_TIE_CANDIDATES:  # spread: every k-th along the first principal axis
        Xc = X[ties] - X[ties].mean(axis=0)
        axis = np.linalg.svd(Xc, full_matrices=False)[2][0]
        order = ties[np.argsort(Xc @ axis, kind="stable")]
        ties = order[np.linspace(0, len(order) - 1, N_TIE_CANDIDATES).round().astype(int)]
    rob = np.full(len(X), np.nan)
    rob[ties] = robust_fn(X[ties])
    best = max(ties, key=lambda k: (rob[k], -total[k]))
    return int(best), rob


def checkpoint_name(gait: str) -> str:
    return f"{gait}.checkpoint.pkl"


def optimize_primary(gait: str, rs: RunSettings, out: "str | Path | ResultDir", lo: float = -1.0,
                     hi: float = 1.0, settings: SimSettings = SimSettings(), evaluator=None,
                     progress=None, n_robust: int = 50, stop_after: int | None = None,
                     robust_objective: int = 0, lock_objective: bool = False) -> dict:
    """Run NSGA-II for one primary gait; write DIR/<gait>.json, CSVs and the front PNG.

    ``out`` is a folder (its files are replaced all at once when the run succeeds) or an open
    :class:`cpg.outdir.ResultDir` that the caller commits. The checkpoint lives beside the
    folder: an interrupted run resumes from it; a run that ends, or fails, removes it.
    ``robust_objective`` N > 0 adds the objective 1 - (fraction of N random initial states
    reaching the gait); ``lock_objective`` adds the time to lock (model units)."""
    args = (gait, rs, lo, hi, settings, evaluator, progress, n_robust, stop_after,
            robust_objective, lock_objective)
    if isinstance(out, ResultDir):
        return _optimize_primary(out, *args)
    with ResultDir(out) as rd:
        result = _optimize_primary(rd, *args)
        rd.commit()
    rd.state(checkpoint_name(gait)).unlink(missing_ok=True)
    return result


def _optimize_primary(rd: ResultDir, gait, rs, lo, hi, settings, evaluator, progress, n_robust,
                      stop_after, robust_objective, lock_objective) -> dict:
    problem = PrimaryGaitProblem(gait, lo, hi, settings, evaluator, robust_objective,
                                 lock_objective)
    t0 = time.perf_counter()
    ckpt = rd.state(checkpoint_name(gait))
    res = run(problem, rs, checkpoint=ckpt, on_generation=progress, stop_after=stop_after)
    ok = res.pareto_X
    F_opt = res.pareto_F
    feasible = res.G[:, 0] <= 0
    if not feasible.any():
        ckpt.unlink(missing_ok=True)  # a failed run must not block the next one
        raise InputError(f"no feasible solution for {gait}: widen the bounds or the budget")
    rob_fn = lambda X: robustness(gait, problem.i_app, problem.phi, ml.weight_matrix(X),  # noqa: E731
                                  n_states=20, seed=rs.seed + 1)
    Xf, Ff = res.X[feasible], res.F[feasible]
    k, rob_pop = choose(Xf, Ff[:, :3], rob_fn)
    chosen_x, chosen_f = Xf[k], Ff[k]
    rob_by_x = {tuple(x): r for x, r in zip(Xf, rob_pop)}  # Pareto points are population members
    rob = np.array([rob_by_x.get(tuple(x), np.nan) for x in ok])
    rob_best = float(robustness(gait, problem.i_app, problem.phi, ml.weight_matrix(chosen_x),
                                n_states=n_robust, seed=rs.seed + 2)[0])
    paper_w = np.array(ml.preset(gait).weights)
    ev_paper = evaluate(gait, problem.i_app, problem.phi, ml.weight_matrix(paper_w[None]),
                        problem.y0, settings)
    rob_paper = float(robustness(gait, problem.i_app, problem.phi, ml.weight_matrix(paper_w),
                                 n_states=n_robust, seed=rs.seed + 2)[0])
    wall = time.perf_counter() - t0
    names = problem.objective_names

    def point(x, f, r):
        p = {"weights": np.round(x, 6).tolist(), "errors_deg": np.round(f[:3], 6).tolist(),
             "robustness": None if not np.isfinite(r) else float(r)}
        p.update({n: round(float(v), 6) for n, v in zip(names[3:], f[3:])})
        return p

    result = {
        "format": FORMAT, "gait": gait, "i_app": problem.i_app, "phi": problem.phi,
        "settings": {"pop": rs.pop, "gens": rs.gens, "seed": rs.seed, "bounds": [lo, hi],
                     "sim": settings.__dict__, "robustness_states": n_robust,
                     "objectives": names},
        "chosen": point(chosen_x, chosen_f, rob_best),
        "pareto": [point(x, f, r) for x, f, r in zip(ok, F_opt, rob)],
        "paper": point(paper_w, ev_paper.F[0], rob_paper),
        "n_generations": res.n_gen, "resumed_from_generation": res.resumed_from,
        "wall_s": round(wall, 3),
    }
    # The final population with the reason each member passed or failed.
    ev = evaluate(gait, problem.i_app, problem.phi, ml.weight_matrix(res.X), problem.y0, settings)
    head = ["w_a", "w_b", "w_c", "z_RF", "z_LE", "z_RE", "constraint", "status", "classified"]
    write_csv(rd.path(f"{gait}_population.csv"), head,
         [[*np.round(x, 6), *np.round(f, 6), round(float(g), 6), r, c]
          for x, f, g, r, c in zip(res.X, ev.F, ev.G, ev.reasons, ev.classified)])
    write_csv(rd.path(f"{gait}_pareto.csv"), ["w_a", "w_b", "w_c", *names, "robustness"],
         [[*np.round(x, 6), *np.round(f, 6), "" if not np.isfinite(r) else r]
          for x, f, r in zip(ok, F_opt, rob)])
    plot_front(rd.path(f"{gait}_pareto.png"), res.F[:, :3], F_opt[:, :3],
               f"{gait}: NSGA-II pop {rs.pop}, {res.n_gen} generations, seed {rs.seed}",
               ("z_RF (deg)", "z_LE (deg)", "z_RE (deg)"))
    write_json(rd.path(f"{gait}.json"), result)
    return result


# ------------------------------------------------------------------------------ secondary
LAG_MATCH = 0.03  # cycles: a candidate's extensor lag this close to the target lag counts
WEIGHT_DIGITS = 6  # decimals of the directed weights in secondary.json


def secondary_search(target: str, source: str, keep: str, base_weights, rs: RunSettings,
                     settings: SimSettings = SimSettings(), radius: float = 1.0,
                     evaluator=None, progress=None, n_confirm: int = 10,
                     target_lag: float | None = None, candidates: bool = False) -> dict:
    """Search one symmetry-breaking target; confirm the best point with the classifier.

    ``target_lag``: also pull the extensors' left-right lag towards it (cycles; a fourth
    objective, :class:`SymmetryBreakingProblem`). ``candidates``: also list every Pareto
    point that the classifier names the target from the Table 3 state (and, with a target
    lag, whose lag is within LAG_MATCH of it), as {"directed_weights" (12), "objectives",
    "extensor_lag"}: what ``cpgbiped secondary --physics`` puts through the body."""
    problem = SymmetryBreakingProblem(target, source, keep, base_weights, radius, settings,
                                      evaluator, target_lag=target_lag)
    res = run(problem, rs, on_generation=progress)
    F = res.pareto_F
    best = int(np.argmin(F.sum(axis=1)))
    out = secondary_point(problem, base_weights, problem.directed(res.pareto_X[best])[0],
                          F[best], rs, settings, n_confirm)
    if candidates:  # rounded as the results file stores them: the body sees what is kept
        W = np.round(problem.directed(res.pareto_X), WEIGHT_DIGITS)
        ev = evaluate(target, problem.i_app, problem.phi, ml.directed_matrix(W),
                      np.repeat(problem.y0[None], len(W), axis=0), settings)
        lag = extensor_lag(ev.phases_deg)
        out["candidates"] = [
            {"directed_weights": W[k].tolist(), "objectives": F[k].tolist(),
             "extensor_lag": float(lag[k])}
            for k in range(len(W)) if ev.classified[k] == target
            and (target_lag is None or abs(lag[k] - target_lag) <= LAG_MATCH)]
    return out


def secondary_point(problem: SymmetryBreakingProblem, base_weights, w12, objectives,
                    rs: RunSettings, settings: SimSettings = SimSettings(),
                    n_confirm: int = 10) -> dict:
    """The result entry of one weight set of a symmetry-breaking search: its 12 directed
    weights, objectives, the class the classifier gives it from the Table 3 state, and the
    fraction of ``n_confirm`` random states (seed ``rs.seed + 3``) from which it is named the
    target; "found" when both hold (the target from the Table 3 state, >= 80%).
    ``base_weights``: the source gait's weights the search started from, as given."""
    target = problem.gait
    W = ml.directed_matrix(np.asarray(w12, dtype=float))
    y0 = np.vstack([problem.y0, ml.random_states(n_confirm, rs.seed + 3)])
    ev = evaluate(target, problem.i_app, problem.phi, np.repeat(W[None], len(y0), 0), y0, settings)
    confirmed = float(np.mean([c == target for c in ev.classified]))
    names = ["phase error of same-wave pairs (deg)",
             "180 x waveform distance of same-wave pairs",
             "180 x shortfall of distinctness of y1/y2 pairs"]
    if problem.target_lag is not None:
        names.append(f"360 x |extensor lag - {problem.target_lag:g}| (deg)")
    return {
        "target": target, "source": problem.source, "kept_symmetry": problem.keep,
        "i_app": problem.i_app, "phi": problem.phi,
        "base_weights": list(map(float, base_weights)),
        "directed_weights": dict(zip(ml.DIRECTED_NAMES,
                                     np.round(np.asarray(w12, float), WEIGHT_DIGITS).tolist())),
        "objectives": np.round(np.asarray(objectives, float), 4).tolist(),
        "objective_names": names,
        "classified_from_table3_state": ev.classified[0],
        "confirmed_fraction": confirmed,
        "found": bool(ev.classified[0] == target and confirmed >= 0.8),
    }


def secondary_all(primary_weights: dict[str, list[float]], rs: RunSettings,
                  settings: SimSettings = SimSettings(), evaluator=None, progress=None,
                  targets=SECONDARY_TARGETS) -> list[dict]:
    out = []
    for target, source, keep, paper in targets:
        r = secondary_search(target, source, keep, primary_weights[source], rs, settings,
                             evaluator=evaluator, progress=progress)
        r["paper_reached"] = paper
        out.append(r)
    return out


def comparison_markdown(primary: dict[str, dict], secondary: list[dict] | None) -> str:
    """The comparison table: the paper's Table 2 vs ours; secondary targets reached or not."""
    f = lambda v: ", ".join(f"{x:.3f}" for x in v)  # noqa: E731
    lines = ["## Primary gaits: the paper's Table 2 weights vs NSGA-II here", "",
             "| gait | paper (w_a, w_b, w_c) | paper errors (deg) | paper robustness | "
             "ours (w_a, w_b, w_c) | our errors (deg) | our robustness |",
             "|---|---|---|---|---|---|---|"]
    for g, r in primary.items():
        p, c = r["paper"], r["chosen"]
        lines.append(f"| {g} | {f(p['weights'])} | {f(p['errors_deg'])} | {p['robustness']:.2f} "
                     f"| {f(c['weights'])} | {f(c['errors_deg'])} | {c['robustness']:.2f} |")
    lines += ["", "Robustness: fraction of random initial states that reach the gait "
              "(every phase error < 2 deg, classifier agrees)."]
    if secondary:
        lines += ["", "## Secondary gaits by symmetry breaking", "",
                  "| target | from | kept symmetry | paper reached | found here | confirmed "
                  "from random states | objectives |", "|---|---|---|---|---|---|---|"]
        body = any("physics" in s for s in secondary)
        if body:  # cpgbiped secondary --physics: the body chose among the candidates
            lines[-2] += " target lag | body, selection states |"
            lines[-1] += "---|---|"
        for s in secondary:
            row = (f"| {s['target']} | {s['source']} | {s['kept_symmetry']} | "
                   f"{'yes' if s['paper_reached'] else 'no'} | "
                   f"{'yes' if s['found'] else 'no'} | {s['confirmed_fraction']:.0%} | "
                   f"{f(s['objectives'])} |")
            if body:
                ph = s.get("physics", {})
                lag = ph.get("target_lag")
                row += (f" {'-' if lag is None else f'{lag:g}'} | "
                        + (f"{ph['confirmed_states']} of {len(ph['states'])} confirmed, "
                           f"{ph['falls']} falls ({ph['candidates']} candidates) |"
                           if ph.get("candidates") else "no candidate |"))
            lines.append(row)
        if body:
            lines += ["", "Body, selection states: in how many of the random CPG states the "
                      "body was driven from (seeds in secondary.json, never the Table 3 "
                      "state) both classifiers name the target without a fall."]
    return "\n".join(lines) + "\n"


def write_secondary(path: str | Path, results: list[dict], command: str | None = None) -> Path:
    """The secondary-gait results file (``path``: the file, e.g. DIR/secondary.json), with the
    command that made it when given."""
    data = {"format": SECONDARY_FORMAT, "targets": results}
    if command is not None:
        data["command"] = command
    return write_json(path, data)
