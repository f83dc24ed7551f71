"""`cpgbiped`: the command-line front end. Parses, calls the library, prints; no logic of its own.

Every user error becomes one line on stderr ("cpgbiped: error: ...") and exit status 2.
"""
from __future__ import annotations

import argparse
import os
import shlex
import signal
import sys
import textwrap
import time

# MuJoCo reads MUJOCO_GL when it is imported: set it once, before anything imports it.
os.environ.setdefault("MUJOCO_GL", "osmesa")
if os.environ.get("PYOPENGL_PLATFORM") not in (None, os.environ["MUJOCO_GL"]):
    os.environ["PYOPENGL_PLATFORM"] = os.environ["MUJOCO_GL"]

DESCRIPTION = """\
cpgbiped takes a central pattern generator (CPG) from equations to a walking, running,
jumping and hopping planar biped in MuJoCo, with numbers that show the gait is real.

The heart is the 4-cell Morris-Lecar network of Farshbaf Rashidi, Sayyed Noorani and
Shoaran (2016): cells LF, RF, LE, RE (left/right ankle flexor/extensor) coupled by the
weights w_a (left-right), w_b (flexor-extensor) and w_c (diagonal). Time in the CPG is in
dimensionless model units; physics is in seconds.
"""

EPILOG = """\
examples:
  cpgbiped demo                          the main job: everything below, summarised in out/demo
  cpgbiped reproduce                     the paper's four gaits from its Table 2 weights
  cpgbiped reproduce --json --plot       machine-readable, plus a PNG like Figs. 3-6
  cpgbiped matsuoka                      what the printed 12-neuron network does, and the calibration
  cpgbiped hopf --gait walk              the Hopf network's version of a gait

Outputs go under out/ unless told otherwise. Exit status: 0 ok, 2 bad input, 1 internal
error (one line; add --debug anywhere for the traceback), 130 interrupted.
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2
        raise SystemExit(_fail(f"{message} (see '{self.prog} --help')"))


def _fail(msg: str) -> int:
    print(f"cpgbiped: error: {msg}", file=sys.stderr)
    return 2


# Argument types: checked while parsing, so a bad value costs nothing and argparse's one-line
# error names the option the user typed ("argument --seed: ...").
MAX_SECONDS = 600.0  # longest simulated rollout (envs.rollout.MAX_SECONDS; checked in a test)


def _number(text: str, lo: float, hi: float, lo_open: bool, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what}, got {text!r}") from None
    if not (v == v and abs(v) != float("inf") and (v > lo if lo_open else v >= lo) and v <= hi):
        raise argparse.ArgumentTypeError(f"{what}, got {text}")
    return v


def seconds_arg(text: str) -> float:
    return _number(text, 0.0, MAX_SECONDS, True, f"must be a number of seconds in (0, "
                                                   f"{MAX_SECONDS:g}]")


def positive_arg(text: str) -> float:
    return _number(text, 0.0, 1e6, True, "must be a positive finite number")


def finite_arg(text: str) -> float:
    return _number(text, -1e300, 1e300, False, "must be a finite number")


# A push's duration (envs.simulation.rollout.PUSH_TICK_S, MAX_PUSH_S and
# envs.experiments.robustness.PUSH_S, restated so that parsing needs no MuJoCo; a test checks
# they agree): one control tick up to a second; the default SCONE's (Tutorial 4c: 100 N held
# for 0.2 s).
PUSH_TICK_S, MAX_PUSH_S, PUSH_S = 0.004, 1.0, 0.2
# robustness's push window (envs.experiments.robustness.PUSH_AFTER_S, MAX_PUSH_AFTER_S and
# envs.gaits.criteria.SETTLE_S, restated likewise; checked in the same test)
PUSH_AFTER_S, MAX_PUSH_AFTER_S, SETTLE_S_CLI = 6.0, 120.0, 2.0
# The Morris-Lecar feedback pathways (cpg.feedback.ML_FORMS, restated so that parsing needs
# neither numba nor the feedback choice file; checked in the same test)
ML_FORMS_CLI = ("load", "load_antagonist", "angle", "reset", "angle_alternating")


def settle_arg(text: str) -> float:
    return _number(text, 0.0, MAX_PUSH_AFTER_S, False,
                   f"must be a number of seconds in [0, {MAX_PUSH_AFTER_S:g}]")


def push_after_arg(text: str) -> float:
    return _number(text, SETTLE_S_CLI, MAX_PUSH_AFTER_S, False,
                   f"must be a number of seconds in [{SETTLE_S_CLI:g}, {MAX_PUSH_AFTER_S:g}]")


def push_seconds_arg(text: str) -> float:
    return _number(text, PUSH_TICK_S - 1e-12, MAX_PUSH_S, False,
                   f"must be a number of seconds in [{PUSH_TICK_S:g}, {MAX_PUSH_S:g}] (the push's "
                   f"force is held for at least one control tick)")


def seed_arg(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer, got {text!r}") from None
    if not 0 <= v < 2 ** 63:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer, got {text}")
    return v


def check_workers(a) -> None:
    """--workers at most this machine's cores (more only multiplies memory, about 200 MB a
    process, and slows the run), unless a Dask scheduler's address spreads them elsewhere."""
    n = getattr(a, "workers", None)
    dask = getattr(a, "dask", None)
    cores = os.cpu_count() or 1
    if dask not in (None, "local"):
        from cpgbiped.cpg.optimize import reach_dask_scheduler

        reach_dask_scheduler(dask)  # a malformed or unreachable address fails here, at once
    if n is not None and n > cores and (dask is None or dask == "local"):
        raise _input_error(f"--workers {n} is more than this machine's {cores} cores (each "
                           f"worker is a process of about 200 MB); use at most {cores}, or "
                           f"--dask tcp://HOST:PORT for a cluster")


def feedback_arg(text: str) -> float:
    """A feedback gain K >= 0 (its upper bound depends on the network: checked later)."""
    if text == "recommended":  # --feedback without a value (argparse passes const through)
        return text
    return _number(text, 0.0, 1e300, False, "must be a feedback gain K >= 0 (a finite number)")


FEEDBACK_HELP = ("feed the body's sensors back into the CPG, stepped with the physics "
                 "(cpg.feedback); --feedback alone: the network's recommended gain, "
                 "--feedback K: gain K; without it the network runs open loop (K = 0)")


def feedback_option(sp, note: str = "") -> None:
    """``--feedback [K]`` on a subcommand (``note`` appended to its help)."""
    sp.add_argument("--feedback", type=feedback_arg, nargs="?", const="recommended", default=None,
                    metavar="K", help=FEEDBACK_HELP + note)


def feedback_form_option(sp) -> None:
    """``--feedback-form FORM`` on a subcommand with ``--feedback``: the Morris-Lecar pathway."""
    sp.add_argument("--feedback-form", default=None, metavar="FORM",
                    help="with --feedback, the Morris-Lecar network's pathway: "
                         + ", ".join(ML_FORMS_CLI) + " (default: the recommended one; "
                         "equations in cpg/feedback.py)")


def feedback_form(a, kind: str, K: float) -> str | None:
    """The pathway of --feedback-form (None: the network's recommended one); one-line errors
    for a network without pathways to choose, an unknown form and a form without feedback."""
    form = getattr(a, "feedback_form", None)
    if form is None:
        return None
    if kind != "ml":
        from cpgbiped.cpg.feedback import CHOICE

        raise _input_error(f"--feedback-form chooses among the Morris-Lecar network's pathways; "
                           f"the {kind} network has one, {CHOICE[kind][0]} (cpg/feedback.py)")
    if form not in ML_FORMS_CLI:
        raise _input_error(f"unknown --feedback-form {form!r}: use one of "
                           f"{', '.join(ML_FORMS_CLI)}")
    if not K:
        raise _input_error("--feedback-form needs a feedback gain K > 0 (--feedback [K]); open "
                           "loop, no pathway is used")
    return form


def _with_form(label: str, K: float, form: str | None) -> str:
    return label + (f", feedback K = {K:g}" if K else "") + (f" ({form})" if form else "")


def feedback_gain(a, kind: str) -> float:
    """The gain of --feedback [K] for a network of ``kind`` (0 without the option)."""
    from cpgbiped.cpg.feedback import RECOMMENDED, check_gain

    k = getattr(a, "feedback", None)
    if k is None:
        return 0.0
    return check_gain(kind, RECOMMENDED[kind] if k == "recommended" else k)


MAX_ROBUSTNESS_STATES = 256  # --robustness-objective: random states per individual


def dt_arg(text: str) -> float:
    return _number(text, 1e-3, 0.1, False, "must be an RK4 step in [0.001, 0.1] model units")


def bounded_count_arg(lo: int, hi: int):
    def parse(text: str) -> int:
        v = count_arg(lo)(text)
        if v > hi:
            raise argparse.ArgumentTypeError(f"must be at most {hi}, got {v}")
        return v
    return parse


def count_arg(lo: int):
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer >= {lo}, got {text!r}") from None
        if v < lo:
            raise argparse.ArgumentTypeError(f"must be at least {lo}, got {v}")
        return v
    return parse


def out_file(path: str | None, option: str, suffix: str) -> str | None:
    """An output file the user named: the right extension, not a folder, and a destination
    that can be written (checked before any work; nothing is created here)."""
    if path is None:
        return None
    if not path.endswith(suffix):
        raise _input_error(f"{option} must name a {suffix} file, got {path!r}")
    if os.path.isdir(path):
        raise _input_error(f"{option} names a folder, not a {suffix} file: {path!r}")
    _check_name_length(path, option)
    _check_writable_ancestor(os.path.dirname(os.path.abspath(path)), path, option)
    return path


NAME_ROOM = 40  # characters the temporary and staging names add to an output's name


def _check_name_length(path: str, option: str) -> None:
    """The output's name, and the temporary names written beside it (".<name>.staging-..."),
    must fit the file system's limit: checked before any work, not at the final commit."""
    name = os.path.basename(os.path.normpath(os.path.abspath(path)))
    probe = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    try:
        limit = os.pathconf(probe, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    parts = [p for p in os.path.abspath(path).split(os.sep) if p]
    if any(len(p.encode()) > limit for p in parts[:-1]) or len(name.encode()) + NAME_ROOM > limit:
        raise _input_error(f"{option}: the name {name[:40]!r}... is too long for this file system "
                           f"(at most {limit - NAME_ROOM} bytes, leaving room for the "
                           f"temporary names beside it)")


def _check_writable_ancestor(folder: str, path: str, option: str) -> None:
    """The nearest existing folder at or above ``folder`` must be writable (``path`` is what
    the user typed, for the message)."""
    probe = folder
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    if not os.path.isdir(probe) or not os.access(probe, os.W_OK | os.X_OK):
        raise _input_error(f"{option}: cannot write to {path!r} ({probe!r} is not a writable "
                           f"folder)")


def out_dir(path: str, option: str = "--out") -> str:
    """An output folder the user named: not a file, under a writable folder."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise _input_error(f"{option} names a file, not a folder: {path!r}")
    _check_name_length(path, option)
    _check_writable_ancestor(os.path.abspath(path), path, option)
    return path


# ---------------------------------------------------------------------------------- reproduce
def cmd_reproduce(a) -> int:
    from cpgbiped.cpg import io, morris_lecar as ml
    from cpgbiped.cpg.reproduce import reproduce, table

    if a.plot:
        out_dir(a.out)
    results = reproduce(dt=a.dt)
    summary = {g: r.summary() for g, r in results.items()}
    if a.plot:
        from cpgbiped.cpg.plots import plot_gait_signals

        panels = {g: (r.trajectory.t, r.trajectory.x[0],
                      f"I_app={ml.PRESETS[g].i_app}, phi={ml.PRESETS[g].phi}, "
                      f"(w_a, w_b, w_c)={ml.PRESETS[g].weights}")
                  for g, r in results.items()}
        path = plot_gait_signals(panels, os.path.join(a.out, "reproduce_signals.png"))
        if not a.json:
            print(f"wrote {path}")
    if a.json:
        print(io.to_json(summary))
        return 0
    print("Paper's Table 2 presets from Table 3 states (phases of RF, LE, RE vs LF, degrees):")
    print(table(summary))
    return 0


# ----------------------------------------------------------------------------------- matsuoka
def cmd_matsuoka(a) -> int:
    from dataclasses import replace

    from cpgbiped.cpg import io, matsuoka as mt

    sets = {"printed": mt.PRINTED, "calibrated": mt.CALIBRATED}
    out = {}
    for name, p in sets.items():
        for label, q in ((f"{name}, noise-free", replace(p, L=0.0)),
                         (f"{name}, noise L={p.L}", p)):
            rep = mt.rhythm_report(q, seconds=150.0 if name == "printed" else 40.0, seed=a.seed)
            out[label] = {"tau": q.tau, "T": q.T, "r": q.r, "L": q.L,
                          "oscillating": rep.oscillating, "frequency_hz": rep.frequency_hz,
                          "pair_frequency_hz": dict(zip(mt.JOINTS, rep.pair_frequency_hz)),
                          "lr_phase_deg": dict(zip(("hip", "knee", "ankle"), rep.lr_phase_deg))}
    if a.json:
        print(io.to_json(out))
        return 0
    rows = [[k, f"{v['tau']:.4g}", f"{v['T']:.4g}", f"{v['r']:g}",
             f"{v['frequency_hz']:.4f}",
             " ".join(f"{f:.3f}" for f in v["pair_frequency_hz"].values()),
             " ".join(f"{p:.1f}" for p in v["lr_phase_deg"].values())] for k, v in out.items()]
    print("Matsuoka 12-neuron network (joint pair = extensor - flexor drive):")
    print(io.format_table(rows, ["parameter set", "tau s", "T s", "r", "freq Hz",
                            "pair rates Hz (L hip..R ankle)", "L/R phase hip knee ankle"]))
    return 0


# --------------------------------------------------------------------------------------- hopf
def cmd_hopf(a) -> int:
    from cpgbiped.cpg import hopf, io
    from cpgbiped.cpg.gaits import classify

    p = hopf.HopfParams(beta=a.beta, normalised=a.normalised)
    tr = hopf.primary_gait(a.gait, p, t_end=a.seconds, dt=1e-3, t_record=a.seconds / 2,
                           record_every=2, seed=a.seed)
    name, r = classify(tr.t, tr.x[0])
    out = {"gait": a.gait, "period_s": r.period, "expected_period_s": p.period,
           "phases_deg": dict(zip(("RF", "LE", "RE"), r.phases_deg[1:])),
           "classified_as": name}
    print(io.to_json(out, indent=2 if a.json else None) if a.json else
          "\n".join(f"{k}: {io.to_json(v, indent=None)}" for k, v in out.items()))
    return 0


# ----------------------------------------------------------------------------------- optimize
class _progress:
    """A tqdm bar on stderr that appears with the first finished generation (so that an error
    found before any work stays the only line); (bar, callback) like a pair."""

    def __init__(self, desc: str, total: int, enabled: bool = True):
        self.desc, self.total, self.enabled, self.bar = desc, total, enabled, None

    def __iter__(self):
        return iter((self, self.on_generation))

    def _ensure(self):
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(total=self.total, desc=self.desc, unit="gen", leave=True,
                            disable=not self.enabled, file=sys.stderr)
        return self.bar

    def on_generation(self, gen: int, n: int) -> None:
        bar = self._ensure()
        bar.update(gen - bar.n)

    def reset(self, total):
        self._ensure().reset(total=total)

    def set_description(self, text):
        self._ensure().set_description(text)

    def note(self, text):
        if self.bar is not None:
            self.bar.set_postfix_str(text, refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _evaluator(a):
    if a.dask is None:
        return None
    from cpgbiped.cpg.optimize import DaskEvaluator

    return DaskEvaluator(None if a.dask == "local" else a.dask)


def cmd_optimize_physics(a) -> int:
    from cpgbiped.cpg.optimize import RunSettings
    from cpgbiped.envs.search.physics_optimize import default_settings, optimize_physics
    from cpgbiped.envs.search.physics_search import check_gait
    from cpgbiped.envs.simulation.trials import DaskRunner, PoolRunner, SerialRunner

    out_dir(a.out)
    check_workers(a)
    gait = check_gait(a.gait)
    if a.robustness_objective or a.lock_time_objective or a.bounds != [-1.0, 1.0]:
        raise _input_error("--robustness-objective, --lock-time-objective and --bounds belong "
                           "to the phase search; --physics has its own objectives and box")
    pop = 32 if a.pop is None else a.pop
    gens = 20 if a.gens is None else a.gens
    rs = RunSettings(pop, gens, a.seed, a.checkpoint_every)
    settings = default_settings(gait, a.froude, a.seconds, a.trials, feedback_gain(a, "ml"))
    args = (settings.seconds, settings.settle_s)
    if a.dask is not None:
        runner = DaskRunner(*args, address=None if a.dask == "local" else a.dask)
    elif a.workers == 1:
        runner = SerialRunner(*args)
    else:
        runner = PoolRunner(*args, workers=a.workers)
    bar, cb = _progress(f"NSGA-II in physics, {gait}", rs.gens, not a.quiet)
    try:
        r = optimize_physics(gait, rs, a.out, settings, runner, cb)
    finally:
        bar.close()
        runner.close()
    c, p, f = r["chosen"], r["paper"], r["front"]
    line = lambda name, q: (  # noqa: E731
        f"  {name:7s} w = ({', '.join(f'{w:+.3f}' for w in q['weights'])}), I_app {q['i_app']:.3f}, "
        f"phi {q['phi']:.3f}: Fr {q['metrics']['froude']:.4f}, cost {q['objectives']['cost']:.3f}, "
        f"failed {q['objectives']['failed_fraction']:.2f}, {q['metrics']['physical_gait']}"
        f"{', fell' if q['metrics']['fell'] else ''}"
        f"{'' if q['metrics'].get('passes_criteria') else ', not passing every criterion'}")
    n_pass = sum(bool(q["metrics"].get("passes_criteria")) for q in r["pareto"])
    print(f"{gait} in physics (Froude target {settings.froude:g}): {f['n_points']} Pareto points "
          f"({n_pass} passing every criterion of the {gait}), "
          f"Froude {f['froude_range'][0]:.4f}-{f['froude_range'][1]:.4f}, cost "
          f"{f['cost_range'][0]:.3f}-{f['cost_range'][1]:.3f}")
    print(line("chosen", c))
    print(line("paper", p))
    print(f"results in {a.out}/: {gait}_physics.json, {gait}_physics_population.csv, "
          f"{gait}_physics_pareto.csv, {gait}_physics_pareto.png")
    return 0


def condition_ids_arg(text: str) -> tuple[int, ...]:
    """Numbers and ranges of tuning conditions (29-36, 1,6)."""
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.envs.search.controller_tuning import condition_ids

    try:
        return condition_ids(text)
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def target_froude_arg(text: str) -> tuple[tuple[str, float], ...]:
    """``--target-froude``: GAIT=FR pairs, comma-separated (run=0.26 or walk=0.1,run=0.26)."""
    pairs = []
    for part in str(text).split(","):
        gait, eq, fr = part.partition("=")
        if not eq:
            raise argparse.ArgumentTypeError(
                f"must be GAIT=FR pairs such as run=0.26, got {text!r}")
        pairs.append((gait.strip(), _number(fr, -1e300, 1e300, False,
                                            "must be a finite number")))
    gaits = [g for g, _ in pairs]
    if len(set(gaits)) != len(gaits):
        raise argparse.ArgumentTypeError(f"names a gait twice: {text!r}")
    return tuple(pairs)


def conditions_arg(text: str) -> tuple[int, tuple[int, ...]]:
    """``--conditions``: N (the first N tuning conditions) or numbers and ranges (1-8,21-24);
    returns (how many, their numbers or () for the first N)."""
    from cpgbiped.cpg.errors import InputError
    from cpgbiped.envs.search.controller_tuning import MAX_CONDITIONS, condition_ids

    try:
        if text.strip().isdigit():
            n = int(text)
            if not 1 <= n <= MAX_CONDITIONS:
                raise InputError(f"must be 1-{MAX_CONDITIONS}, got {n}")
            return n, ()
        ids = condition_ids(text)
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return len(ids), ids


def only_arg(text: str) -> tuple[str, ...]:
    """``--only``: comma-separated gain names (empty: every gain the search selects)."""
    return tuple(dict.fromkeys(x.strip() for x in str(text).split(",") if x.strip()))


def cmd_tune(a) -> int:
    from cpgbiped.cpg.optimize import RunSettings
    from cpgbiped.envs.control.controller import GAINS_FILE
    from cpgbiped.envs.search.controller_tuning import (HORIZON, PROGRESS, SHORTFALL, WORST,
                                                          TuneSettings,
                                                          check_gaits, tune, values_of, variables)
    from cpgbiped.envs.simulation.trials import DaskRunner, PoolRunner, SerialRunner

    out_dir(a.out)
    check_workers(a)
    n_cond, ids = a.conditions
    guard = check_gaits(a.guard) if a.guard else ()
    settings = TuneSettings(check_gaits(a.gait), a.search, a.algorithm, a.seconds,
                            n_cond, a.sigma, only_arg(a.only), ids, guard, a.guard_gains or "",
                            SHORTFALL if a.shortfall_weight is None else a.shortfall_weight,
                            WORST if a.worst_weight is None else a.worst_weight,
                            a.survival_only, a.target_froude,
                            PROGRESS if a.progress_weight is None else a.progress_weight)
    rs = RunSettings(a.pop, a.gens, a.seed, a.checkpoint_every)
    start = a.start or str(GAINS_FILE)
    from cpgbiped.envs.control.controller import read_gains

    # a bad starting file, or one without the start-up gains a search names, is refused
    # before any work
    values_of(read_gains(start)[0], [n for n, _, _ in variables(settings)])
    if a.guard_gains:
        read_gains(a.guard_gains)
    args = (settings.seconds, 2.0)
    if a.dask is not None:
        runner = DaskRunner(*args, address=None if a.dask == "local" else a.dask)
    elif a.workers == 1:
        runner = SerialRunner(*args)
    else:
        runner = PoolRunner(*args, workers=a.workers)
    n_var = len(variables(settings))
    name = "CMA-ES" if settings.algorithm == "cmaes" else "NSGA-II"
    bar, cb = _progress(f"{name} over {n_var} gains, {settings.gait}", rs.gens, not a.quiet)
    command = "cpgbiped " + " ".join(shlex.quote(x) for x in a.argv)
    try:
        r = tune(settings, rs, a.out, runner, start=start, command=command, progress=cb,
                 note=bar.note)
    finally:
        bar.close()
        runner.close()
    e = r["entry"]
    print(f"{name} over {n_var} gains ({settings.gait}, search: {settings.search}): "
          f"cost {e['start_cost']:.3f} at the start, {e['cost']:.3f} at the best point "
          f"({e['generations_run']} generations, pop {rs.pop}, seed {rs.seed}, "
          f"{len(e['conditions'])} tuning conditions)")
    for g in settings.gaits:
        print(f"  {g}: the best point's rollouts under each condition: {a.out}/tune_conditions.csv")
    h = e["horizon"]
    print(f"  horizon check: rolled out for {h['seconds']:g} s, {HORIZON:g} times the tuned "
          f"window, the best point falls in {h['fell']} of {h['rollouts']} rollouts"
          + ("" if not h["fell"] else " (fell_at_s_horizon in tune_conditions.csv): a gait "
             "that holds only for the window it was tuned on"))
    print(f"results in {a.out}/: gains.json (copy it to {GAINS_FILE} to make it the controller's "
          f"gains), tune_history.csv, tune_conditions.csv")
    return 0


def cmd_optimize(a) -> int:
    if a.physics:
        return cmd_optimize_physics(a)
    a.pop = 40 if a.pop is None else a.pop
    a.gens = 25 if a.gens is None else a.gens
    for opt in ("froude", "seconds", "trials", "workers", "feedback"):
        if getattr(a, opt) is not None:
            raise _input_error(f"--{opt} belongs to optimize --physics")
    from cpgbiped.cpg.evaluate import SimSettings
    from cpgbiped.cpg.optimize import RunSettings, check_bounds, primary_names
    from cpgbiped.cpg.outdir import ResultDir
    from cpgbiped.cpg.search import checkpoint_name, comparison_markdown, optimize_primary
    from cpgbiped.cpg import io

    out_dir(a.out)
    check_workers(a)
    gaits_ = primary_names(a.gait)
    rs = RunSettings(a.pop, a.gens, a.seed, a.checkpoint_every)
    check_bounds(*a.bounds)
    if a.robustness_objective < 0:
        raise _input_error(f"--robustness-objective must be >= 0, got {a.robustness_objective}")
    results = {}
    started = time.time()
    with ResultDir(a.out) as rd:
        ev = _evaluator(a)
        try:
            for g in gaits_:
                bar, cb = _progress(f"NSGA-II {g}", rs.gens, not a.quiet)
                try:
                    results[g] = optimize_primary(g, rs, rd, *a.bounds, SimSettings(), ev, cb,
                                                  robust_objective=a.robustness_objective,
                                                  lock_objective=a.lock_time_objective)
                finally:
                    bar.close()
        except Exception:
            # A run that fails (not one that is interrupted) must not block the next one: its
            # checkpoints go (not a file this run did not write, such as an unreadable one).
            for g in gaits_:
                ck = rd.state(checkpoint_name(g))
                if ck.exists() and ck.stat().st_mtime >= started:
                    ck.unlink()
            raise
        finally:
            if ev is not None:
                ev.close()
        table = comparison_markdown(results, None)
        if len(results) == 4:
            io.write_text(rd.path("comparison.md"), table)
        rd.commit()
    for g in gaits_:
        rd.state(checkpoint_name(g)).unlink(missing_ok=True)
    print(table)
    print(f"results in {a.out}/: <gait>.json, <gait>_population.csv, <gait>_pareto.csv, "
          f"<gait>_pareto.png" + (", comparison.md" if len(results) == 4 else ""))
    return 0


def cmd_secondary(a) -> int:
    from cpgbiped.cpg import io, morris_lecar as ml
    from cpgbiped.cpg.optimize import SECONDARY_TARGETS, RunSettings
    from cpgbiped.cpg.outdir import ResultDir
    from cpgbiped.cpg.search import comparison_markdown, load_result, secondary_all, write_secondary

    from cpgbiped.envs.search.secondary_physics import MAX_STATES

    if not a.physics and (a.states is not None or a.workers is not None):
        raise _input_error("--states and --workers choose how the body is driven: they need "
                           "--physics")
    if a.physics:
        a.states = 6 if a.states is None else a.states
        a.workers = min(2, os.cpu_count() or 1) if a.workers is None else a.workers
    check_workers(a)  # --workers within the cores, a --dask address reachable
    if a.physics:
        if a.states > MAX_STATES:
            raise _input_error(f"--states must be at most {MAX_STATES}, got {a.states}")
    if a.results is not None and not os.path.isdir(a.results):
        raise _input_error(f"--results {a.results!r} is not a folder of optimiser results")
    a.results = a.results or "out/optimize"
    out_dir(a.out)
    rs = RunSettings(a.pop, a.gens, a.seed)
    primary, weights = {}, {}
    for g in ml.PRIMARY_GAITS:
        path = os.path.join(a.results, f"{g}.json") if a.results else None
        if path and os.path.exists(path):
            primary[g] = load_result(path)
            weights[g] = primary[g]["chosen"]["weights"]
        else:
            weights[g] = list(ml.preset(g).weights)
    print("base weights: " + ", ".join(
        f"{g} {'(optimiser)' if g in primary else '(paper)'}" for g in weights), file=sys.stderr)
    with ResultDir(a.out) as rd:
        ev = _evaluator(a)
        try:
            bar, advance = _progress("symmetry breaking", rs.gens, not a.quiet)
            target = iter(range(1, len(SECONDARY_TARGETS) + 1))

            def prog(gen, n):  # one bar, reset for each target
                if gen == 1:
                    bar.reset(total=n)
                    bar.set_description(f"target {next(target)}/{len(SECONDARY_TARGETS)}")
                advance(gen, n)

            if a.physics:
                from cpgbiped.envs.search.secondary_physics import physics_secondary

                def each_search(gen, n):  # one bar, reset for each network search
                    if gen == 1:
                        bar.reset(total=n)
                    advance(gen, n)

                results = physics_secondary(weights, rs, states=a.states, workers=a.workers,
                                            evaluator=ev, progress=each_search,
                                            note=bar.set_description)
            else:
                results = secondary_all(weights, rs, evaluator=ev, progress=prog)
            bar.close()
        finally:
            if ev is not None:
                ev.close()
        write_secondary(rd.path("secondary.json"), results,
                        command="cpgbiped " + " ".join(shlex.quote(x) for x in a.argv))
        table = comparison_markdown(primary if len(primary) == 4 else {}, results)
        io.write_text(rd.path("comparison.md"), table)
        rd.commit()
    print(table)
    return 0


# ------------------------------------------------------------------------- physical biped
def _network(a):
    """(Network, label) from --network, --preset, --weights and --seed."""
    from cpgbiped.cpg.network import build

    kind = a.network
    preset = a.preset or ("walk" if kind == "matsuoka" else a.gait)  # its only preset
    if a.weights is None:
        net = build(kind, preset, seed=a.seed)
        return net, f"{kind} {preset}" + (f", seed {a.seed}" if a.seed is not None else "")
    if kind != "ml":
        raise _input_error("--weights holds Morris-Lecar weights: use it with --network ml")
    from cpgbiped.cpg.results import load_result, point_cell

    data = load_result(a.weights)
    preset = a.preset or data["gait"]
    i_app, phi = point_cell(data, data["chosen"])
    net = build("ml", preset, weights=data["chosen"]["weights"], i_app=i_app, phi=phi,
                seed=a.seed)
    return net, f"ml {preset} with the weights of {a.weights}"


def _validation(a, stop_on_fall=True, settle_s=None):
    from cpgbiped.envs.gaits.criteria import SETTLE_S
    from cpgbiped.envs.gaits.validate import check_gait, validate

    check_gait(a.gait)
    net, label = _network(a)
    net.period()  # a network without a rhythm cannot drive the body: one line, before any work
    K = feedback_gain(a, net.kind)
    form = feedback_form(a, net.kind, K)
    push, push_s = getattr(a, "push", None), getattr(a, "push_s", None)
    if push is None and push_s is not None:
        raise _input_error("--push-s needs --push T_S IMPULSE_NS (it sets how long that push "
                           "is held)")
    v = validate(net, a.gait, a.seconds, friction_scale=a.friction_scale,
                 push=None if push is None else (*push, PUSH_S if push_s is None else push_s),
                 stop_on_fall=stop_on_fall,
                 settle_s=SETTLE_S if settle_s is None else settle_s,
                 ankle_drive=not a.no_ankle_drive, feedback=K, feedback_form=form)
    return v, _with_form(label, K, form)


def _input_error(msg):
    from cpgbiped.cpg.errors import InputError

    return InputError(msg)


def cmd_validate(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.gaits.validate import biomechanics_text, metrics_table

    out_file(a.rrd, "--rrd", ".rrd")
    from cpgbiped.envs.simulation.rollout import MAX_ROLLOUT_S

    if a.settle + a.seconds > MAX_ROLLOUT_S:
        raise _input_error(f"--settle {a.settle:g} plus --seconds {a.seconds:g} is a rollout of "
                           f"{a.settle + a.seconds:g} s; the longest is {MAX_ROLLOUT_S:g} s")
    v, label = _validation(a, settle_s=a.settle)
    s = v.summary()
    s["source"] = label
    if a.rrd:
        from cpgbiped.envs.media.record import write_rrd

        write_rrd(a.rrd, {a.gait: (v.recording, v.metrics)})
    if a.json:
        print(io.to_json(s))
    else:
        print(f"{label} drives the body; target {a.gait}; {a.seconds:g} s after "
              f"{v.settle_s:g} s settling"
              + (f", friction x{a.friction_scale:g}" if a.friction_scale != 1 else "")
              + (", CPG ankle drive removed" if a.no_ankle_drive else ""))
        print(metrics_table({a.gait: s}))
        print(biomechanics_text(s))
        for f in s["failures"]:
            print(f"  not met: {f}")
        if s["unstable"]:
            print(f"physics: {s['unstable']}")
    return 0


def cmd_render(a) -> int:
    from cpgbiped.envs.media.render import (check_backend, check_video_size, gait_cycle_picture, gait_diagram,
                             render_video, signals_picture)

    check_video_size(a.width, a.height, a.fps, a.seconds)
    out_file(a.out, "--out", ".mp4")
    out_file(a.rrd, "--rrd", ".rrd")
    check_backend()
    v, label = _validation(a, stop_on_fall=False, settle_s=0.0)
    from cpgbiped.cpg import io
    from cpgbiped.envs.media.chrono import chronophotograph, chrono_title

    stem = os.path.splitext(a.out)[0]
    with io.all_or_nothing():  # the video, its pictures and the recording land together
        path = render_video(v.recording, a.out, a.fps, a.width, a.height, a.seconds,
                            signals=not a.no_signals, fancy=a.fancy)
        gait_diagram(v.recording, stem + "_gait.png", v.metrics, label)
        gait_cycle_picture(v.recording, v.metrics, stem + "_cycle.png", label)
        signals_picture(v.recording, stem + "_signals.png", label)
        chronophotograph(v.recording, stem + "_chrono.png", v.metrics, chrono_title(label, v),
                         period_s=v.summary()["cpg_period_s"])
        if a.rrd:
            from cpgbiped.envs.media.record import write_rrd

            write_rrd(a.rrd, {a.gait: (v.recording, v.metrics)}, {a.gait: io.staged(path)})
    print(f"wrote {path}, {stem}_chrono.png, {stem}_gait.png, {stem}_cycle.png, "
          f"{stem}_signals.png"
          + (f", {a.rrd}" if a.rrd else ""))
    return 0


def cmd_log(a) -> int:
    from cpgbiped.envs.media.record import write_rrd

    out_file(a.rrd, "--rrd", ".rrd")
    v, label = _validation(a)
    write_rrd(a.rrd, {a.gait: (v.recording, v.metrics)})
    print(f"wrote {a.rrd} ({label}; physical: {v.metrics.physical_gait}); open it with: "
          f"rerun {a.rrd}")
    return 0


def cmd_matrix(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.gaits.matrix import matrix, matrix_table

    K = feedback_gain(a, a.network)
    check_workers(a)
    res = matrix(a.network, seconds=a.seconds, seed=a.seed, workers=a.workers, feedback=K)
    if a.json:
        print(io.to_json(res))
    else:
        print(f"every {a.network} preset through the one controller ({a.seconds:g} s after "
              f"settling" + (f", random initial CPG state from seed {a.seed}" if a.seed is not None
                            else "") + (f", feedback K = {K:g}" if K else "") + "):")
        print(matrix_table(res))
    return 0


def cmd_check_pareto(a) -> int:
    from cpgbiped.envs.search.pareto import check_pareto

    out_dir(a.out)
    check_workers(a)
    out_file(a.rrd, "--rrd", ".rrd")
    res = check_pareto(a.result, a.out, first=a.first, seconds=a.seconds, render=a.render,
                       rrd=a.rrd, workers=a.workers, progress=not a.quiet)
    print(res["markdown"])
    print(f"wrote {a.out}/pareto_check.md, .csv, .json")
    return 0


def _gains_to_compare(a, kind: str) -> list[float]:
    K = feedback_gain(a, kind)
    return [0.0] if K == 0 else [0.0, K]


def cmd_robustness(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.experiments.robustness import envelope_picture, robustness, table
    from cpgbiped.envs.gaits.validate import check_gait

    check_gait(a.gait)
    out_dir(a.out)
    net, label = _network(a)
    net.period()
    gains = _gains_to_compare(a, net.kind)
    form = feedback_form(a, net.kind, gains[-1])
    res = robustness(net, a.gait, gains, push_s=a.push_s, after_s=a.push_after, form=form)
    res["source"] = label + (f", feedback pathway {form}" if form else "")
    stem = os.path.join(a.out, f"robustness_{net.kind}_{net.preset}")
    with io.all_or_nothing():  # the table and its picture land together
        io.write_json(stem + ".json", res)
        envelope_picture(res, stem + ".png")
    if a.json:
        print(io.to_json(res))
    else:
        print(f"{res['source']}: push envelope (impulse survived, N s, at stride phases from "
              f"{res['push_after_s']:g} s; each push held {res['push_s']:g} s), friction "
              f"x0.5/0.7/1.3/2.0 and 8 random CPG states; target {a.gait}")
        print(table(res))
        print(f"wrote {stem}.json, {stem}.png")
    return 0


def cmd_phase_response(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.experiments.phase_response import phase_response, picture
    from cpgbiped.envs.gaits.validate import check_gait

    check_gait(a.gait)
    out_dir(a.out)
    net, label = _network(a)
    net.period()
    res = [phase_response(net, K, impulse=a.impulse) for K in _gains_to_compare(a, net.kind)]
    stem = os.path.join(a.out, f"phase_response_{net.kind}_{net.preset}")
    with io.all_or_nothing():
        io.write_json(stem + ".json", {"source": label, "by_gain": res})
        picture(res, f"{label}: {a.impulse:g} N s push forwards", stem + ".png")
    if a.json:
        print(io.to_json({"source": label, "by_gain": res}))
    else:
        for r in res:
            f = lambda xs: " ".join("-" if x is None or x != x else f"{x:+.3f}"  # noqa: E731
                                    for x in xs) if xs is not None else r.get("note", "")
            print(f"K = {r['feedback_gain']:g}: CPG phase shift (cycles) at push phases "
                  f"{' '.join(f'{p:g}' for p in r['phases'])}: {f(r['dphi'])}")
            if r["relock_cycles"] is not None:
                print("  cycles to re-lock: " + " ".join(
                    "-" if x is None else f"{x:g}" for x in r["relock_cycles"]))
        print(f"wrote {stem}.json, {stem}.png")
    return 0


def cmd_transition(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.media.render import check_backend, check_video_size, gait_diagram, render_video
    from cpgbiped.envs.experiments.transition import (WINDOW_CYCLES, check_transition,
                                                      default_seconds, transition)

    seconds = (a.seconds if a.seconds is not None
               else default_seconds(getattr(a, "from"), a.to, a.at, a.ramp))
    check_transition(a.network, getattr(a, "from"), a.to, a.at, a.ramp, seconds)
    K = feedback_gain(a, a.network)
    form = feedback_form(a, a.network, K)
    if a.out:
        check_video_size(a.width, a.height, a.fps, seconds)
        out_file(a.out, "--out", ".mp4")
        check_backend()
    out_file(a.rrd, "--rrd", ".rrd")
    src, dst = getattr(a, "from"), a.to
    res, rec, net, to = transition(a.network, src, dst, a.at, a.ramp, seconds, K,
                                   poses=bool(a.out or a.rrd), seed=a.seed, feedback_form=form)
    label = _with_form(f"{a.network} {src} -> {dst} at {a.at:g} s"
                       + (f" over {a.ramp:g} s" if a.ramp else "")
                       + (f", CPG seed {a.seed}" if a.seed is not None else ""), K, form)
    marks = [(a.at, "change")] + ([(a.at + a.ramp, "end of ramp")] if a.ramp else [])
    written = []
    with io.all_or_nothing():  # the video, its gait diagram and the recording land together
        if a.out:
            path = render_video(rec, a.out, a.fps, a.width, a.height, seconds,
                                marks=[m[0] for m in marks])
            stem = os.path.splitext(a.out)[0]
            gait_diagram(rec, stem + "_gait.png", None, label, window_s=None, marks=marks)
            written += [str(path), stem + "_gait.png"]
        if a.rrd:
            from cpgbiped.envs.media.record import write_rrd

            write_rrd(a.rrd, {f"{src}_to_{dst}": (rec, res)}, marks={f"{src}_to_{dst}": marks})
            written.append(a.rrd)
    if a.json:
        print(io.to_json(res))
    else:
        b, f = res["before"], res["after"]
        print(label)
        w = res["before_from_settling"]
        n = res["before_cycles"]
        print(f"  before ({b['start_s']:.2f}-{b['end_s']:g} s, "
              + (f"its last {n} whole CPG cycles" if n else "less than a CPG cycle")
              + f"): physical {b['physical_gait']}, CPG {b['cpg_gait']}, "
              f"{b['speed_mps']:.2f} m/s (from {w['start_s']:g} s: physical "
              f"{w['physical_gait']})")
        print(f"  after  ({f['start_s']:.2f}-{f['end_s']:g} s): physical {f['physical_gait']}, "
              f"CPG {f['cpg_gait']}, {f['speed_mps']:.2f} m/s")
        print(f"  sliding windows of {WINDOW_CYCLES} CPG cycles: "
              + " ".join(w["physical_gait"] for w in res["windows"]))
        print(f"  fell: {'at %.2f s' % res['fell_at_s'] if res['fell'] else 'no'}; switched to "
              f"{dst}: " + (f"after {res['cycles_to_switch']} CPG cycles"
                            if res["cycles_to_switch"] is not None else "no"))
        na = res["network_alone"]["cycles_to_switch"]
        print(f"  the network alone (the same change, no body, open loop): {dst}'s pattern "
              + (f"from {na} CPG cycles after the change" if na is not None else
                 f"not within {len(res['network_alone']['windows'])} CPG cycles"))
        if written:
            print("wrote " + ", ".join(written))
    return 0


def cmd_sweep(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.experiments.sweep import check_pair, picture, schedule, sweep

    check_pair(a.pair)
    out_dir(a.out)
    K = feedback_gain(a, a.network)
    if a.video:
        from cpgbiped.envs.media.render import check_backend

        check_backend()
    res, rec = sweep(a.pair, a.ramp_seconds, a.network, K, poses=a.video)
    stem = os.path.join(a.out, f"sweep_{a.network}_{a.pair}" + (f"_K{K:g}" if K else ""))
    written = [stem + ".json", stem + ".png"]
    with io.all_or_nothing():  # the JSON, the picture and the video land together
        io.write_json(stem + ".json", res)
        picture(res, stem + ".png")
        if a.video:
            from cpgbiped.envs.media.render import render_video

            render_video(rec, stem + ".mp4", 30.0, 640, 480, float(rec.t[-1]),
                         marks=schedule(a.ramp_seconds).t)
            written.append(stem + ".mp4")
    if a.json:
        print(io.to_json(res))
    else:
        f = lambda p: "no switch" if p is None else (  # noqa: E731
            f"d = {p['drive']:.2f} at {p['time_s']:.1f} s, {p['speed_mps']:.2f} m/s, "
            f"Fr {p['froude']:.3f}")
        print(f"{a.network} {a.pair} drive sweep (ramps of {a.ramp_seconds:g} s"
              + (f", feedback K = {K:g}" if K else "") + "):")
        print(f"  switch up to {res['to']}: {f(res['switch_up'])}")
        print(f"  switch down from {res['to']}: {f(res['switch_down'])}")
        hy = res["hysteresis_drive"]
        print("  hysteresis: " + ("not measured (a switch is missing)" if hy is None
                                  else f"{hy:+.2f} in drive"))
        print(f"  fell: {'at %.1f s' % res['fell_at_s'] if res['fell'] else 'no'}")
        print("wrote " + ", ".join(written))
    return 0


def cmd_check_secondary(a) -> int:
    from cpgbiped.cpg import io
    from cpgbiped.envs.experiments.secondary_check import check_secondary, load_secondary, table

    check_workers(a)
    from cpgbiped.envs.experiments.secondary_check import MAX_STATES

    if a.states > MAX_STATES:
        raise _input_error(f"--states must be at most {MAX_STATES}, got {a.states}")
    if a.out is not None:
        out_dir(a.out)
    n = len(load_secondary(a.secondary))  # a malformed file fails here, before any work
    if a.out is None:
        res = check_secondary(a.secondary, a.seconds, a.workers, states=a.states)
    else:
        from cpgbiped.cpg.outdir import ResultDir

        with ResultDir(a.out) as rd:  # the table and every picture land together
            res = check_secondary(a.secondary, a.seconds, a.workers, img_dir=rd.staging,
                                  states=a.states)
            io.write_json(rd.path("check_secondary.json"), res)
            rd.commit()
    if a.json:
        print(io.to_json(res))
    else:
        print(f"{n} secondary weight sets of {a.secondary} through the body ({a.seconds:g} s "
              f"after settling), from the Table 3 state"
              + (f" and from {a.states} random CPG states (seeds 3000 and up)" if a.states else "")
              + ":")
        print(table(res))
        print(f"{sum(r['confirmed'] for r in res.values())} confirmed in the body (both "
              f"classifiers name the target, no fall)")
        if a.out is not None:
            print(f"wrote {a.out}/check_secondary.json, a chronophotograph per weight set "
                  f"(<target>_from_<source>_chrono.png) and all of them in "
                  f"{a.out}/secondary_chrono.png")
    return 0


# --------------------------------------------------------------------------------------- demo
def cmd_demo(a) -> int:
    from cpgbiped.envs.cli.demo import run_demo

    out_dir(a.out)
    run_demo(a.out, seconds=a.seconds, video_seconds=a.video_seconds, progress=not a.quiet)
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="cpgbiped", description=DESCRIPTION, epilog=EPILOG,
                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def add(name, func, help_, desc):
        sp = sub.add_parser(name, help=help_, description=textwrap.dedent(desc),
                            formatter_class=argparse.RawDescriptionHelpFormatter)
        sp.set_defaults(func=func)
        return sp

    sp = add("demo", cmd_demo, "run the main job and summarise it in out/demo", """\
        The main job, end to end: the paper's four gaits reproduced in the 4-cell network;
        then each gait (the optimiser's weights when out/optimize/<gait>.json exists, else
        the paper's) drives the physical biped, is validated from its ground contacts,
        rendered off-screen to video, and logged to one rerun recording. Writes under --out:
        <gait>.mp4, <gait>_gait.png, <gait>_signals.png, <gait>_frame.png, demo.rrd,
        summary.json and README.md with the table and the pictures.""")
    sp.add_argument("--out", default="out/demo", help="output folder (default: out/demo)")
    sp.add_argument("--seconds", type=seconds_arg, default=20.0, help="validated seconds per gait")
    sp.add_argument("--video-seconds", type=seconds_arg, default=8.0, help="seconds of video per gait")
    sp.add_argument("--quiet", action="store_true", help="no progress bar")

    def network_choice(sp, gait_help):
        """--gait (what the command checks), and the network, preset and weights that drive
        the body."""
        sp.add_argument("--gait", default="walk", help=gait_help)
        sp.add_argument("--network", default="ml", choices=("ml", "hopf", "matsuoka"),
                        help="the network that drives the body (default ml: Morris-Lecar)")
        sp.add_argument("--preset", default=None,
                        help="the network's preset (default: the --gait; matsuoka: walk)")
        sp.add_argument("--weights", metavar="FILE",
                        help="optimiser result JSON: its chosen (w_a, w_b, w_c), I_app and phi "
                             "replace the Morris-Lecar preset's")

    def rollout_args(sp, rrd_required=False):
        network_choice(sp, "the target the verdict checks: walk, run, jump or hop (default walk)")
        sp.add_argument("--seconds", type=seconds_arg, default=20.0,
                        help="simulated seconds measured after the settling (2 s; validate: "
                        "--settle) (default 20)")
        sp.add_argument("--seed", type=seed_arg, default=None,
                        help="random initial CPG state from this seed (default: the preset's)")
        sp.add_argument("--friction-scale", type=positive_arg, default=1.0, metavar="F",
                        help="multiply every floor/foot friction coefficient by F")
        sp.add_argument("--no-ankle-drive", action="store_true",
                        help="remove the CPG's ankle drive (the reflexes stay): the ablation")
        sp.add_argument("--rrd", required=rrd_required, metavar="FILE.rrd",
                        help="also write a rerun recording")
        feedback_option(sp)
        feedback_form_option(sp)

    def push_args(sp):
        sp.add_argument("--push", type=finite_arg, nargs=2, metavar=("T_S", "IMPULSE_NS"),
                        help="horizontal impulse on the torso at time T_S s (simulation time "
                             "from the start, settling included) of IMPULSE_NS N s (negative: "
                             "backwards)")
        sp.add_argument("--push-s", type=push_seconds_arg, default=None, metavar="S",
                        help=f"how long the push's force is held, s (default {PUSH_S:g}, as "
                             f"SCONE's perturbed-gait tutorial; {PUSH_TICK_S:g}: one control "
                             f"tick, a blow)")

    sp = add("validate", cmd_validate, "drive the biped with a network and measure the gait", """\
        A network (--network, --preset, --weights; default the Morris-Lecar preset of --gait)
        drives the biped through the one controller, which never sees a gait name. The gait
        is measured from the foot contacts (debounced): duty factor per foot, left-right
        phase lag (fraction of a stride), double support, flight, stride period, distance,
        speed; a physical verdict (walk/run/jump/hop/none) from those numbers alone, next to
        the gait the CPG classifier names from the cell outputs. --gait is only the target:
        PASS when the body did not fall, both verdicts name it and its criteria are met.
        Times (--push, fell_at_s) are simulation time from the start, settling included.""")
    rollout_args(sp)
    push_args(sp)
    sp.add_argument("--settle", type=settle_arg, default=SETTLE_S_CLI, metavar="S",
                    help="seconds of settling before the measured window (default %g, the "
                    "criteria's, which the tests and the README use); a longer one measures "
                    "the gait without its start-up (the JSON's regular_from_s says when its "
                    "strides became regular); --seconds are measured after it, and a --push "
                    "inside it still acts on the body" % SETTLE_S_CLI)
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("matrix", cmd_matrix, "every preset of a network through the one controller", """\
        Drive the body with every preset of a network (ml: walk, run, jump, hop; hopf: the
        same four; matsuoka: walk) through the same controller and print the physical gait
        each one produces, with its metrics. The controller never sees the preset's name:
        the physical gait comes from the CPG alone, so a diagonal matrix (each preset its own
        gait) shows that the CPG, not a label, chooses the gait.""")
    sp.add_argument("--network", default="ml", choices=("ml", "hopf", "matsuoka"))
    sp.add_argument("--seed", type=seed_arg, default=None,
                    help="random initial CPG states from this seed (default: the presets')")
    sp.add_argument("--seconds", type=seconds_arg, default=20.0,
                    help="simulated seconds after 2 s of settling (default 20)")
    sp.add_argument("--workers", type=count_arg(1), default=2, help="parallel processes (default 2)")
    feedback_option(sp)
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("render", cmd_render, "render a rollout off-screen to mp4", """\
        Render a rollout with MuJoCo's off-screen renderer (MUJOCO_GL: osmesa by default,
        egl accepted) to an mp4 (mediapy/ffmpeg), frames taken by simulated time; a side
        camera tracks the torso, foot markers turn green in stance; a strip of the four CPG
        signals runs below unless --no-signals. Also writes FILE_chrono.png (a
        chronophotograph: the body's poses over the last two strides on one picture, feet on
        the ground drawn thick, footprints marked), FILE_gait.png (footfall diagram),
        FILE_cycle.png (joint angles and vertical and horizontal ground reaction forces over
        the gait cycle, mean +- s.d. over strides) and FILE_signals.png beside the video.""")
    rollout_args(sp)
    sp.add_argument("--width", type=count_arg(1), default=640)
    sp.add_argument("--height", type=count_arg(1), default=480)
    sp.add_argument("--fps", type=positive_arg, default=30.0)
    sp.add_argument("--fancy", action="store_true", help="shadows and reflections (slower)")
    sp.add_argument("--no-signals", action="store_true", help="no CPG strip under the video")
    push_args(sp)
    sp.add_argument("--out", required=True, metavar="FILE.mp4")
    sp.set_defaults(seconds=8.0)

    sp = add("log", cmd_log, "write a rerun recording of a rollout", """\
        Write a rerun .rrd of a rollout on the sim_time timeline: CPG outputs, ankle
        activations, joint angles, torso height and pitch, foot contacts and forces,
        touchdown/lift-off events and the gait metrics; the default view shows the gait
        diagram above the CPG signals. Open it with 'rerun FILE.rrd'.""")
    rollout_args(sp, rrd_required=True)
    push_args(sp)

    def network_args(sp):
        network_choice(sp, "the gait checked in the conditions: walk, run, jump or hop "
                           "(default walk)")
        sp.add_argument("--seed", type=seed_arg, default=None,
                        help="random initial CPG state from this seed (default: the preset's)")
        feedback_option(sp)

    sp = add("robustness", cmd_robustness, "push envelope, friction and CPG-state survival",
             """\
        The robustness envelope of a gait, as SCONE's perturbation tutorials measure it:
        horizontal pushes on the torso at four phases of the stride (after 6 s, or
        --push-after S; phase 0 a left touchdown), forwards and backwards, the impulse
        climbing 2.5, 5, 7.5, ... 40 N s until the body falls within 5 s; floor friction
        x0.5, 0.7, 1.3, 2.0; eight random initial CPG states (seeds 20-27). With
        --feedback, open loop (K = 0) and the gain K side by side. Writes
        --out/robustness_<network>_<preset>.json and .png (impulse survived against the
        phase of the push).""")
    network_args(sp)
    feedback_form_option(sp)
    sp.add_argument("--push-s", type=push_seconds_arg, default=PUSH_S, metavar="S",
                    help=f"how long each push's force is held, s (default {PUSH_S:g}, as "
                         f"SCONE's perturbed-gait tutorial; {PUSH_TICK_S:g}: one control tick, "
                         f"a blow of the same impulse)")
    sp.add_argument("--push-after", type=push_after_arg, default=PUSH_AFTER_S, metavar="S",
                    help=f"the pushes' stride starts at the first left touchdown after S "
                         f"seconds of simulation (default {PUSH_AFTER_S:g}, the issue's; later, "
                         f"e.g. 12, pushes a gait that has settled; "
                         f"[{SETTLE_S_CLI:g}, {MAX_PUSH_AFTER_S:g}])")
    sp.add_argument("--out", default="out/robustness", metavar="DIR",
                    help="folder for the JSON and the picture (default out/robustness)")
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("phase-response", cmd_phase_response, "how far a push moves the CPG's phase",
             """\
        Phase response of the coupled CPG and body: a horizontal push on the torso at ten
        phases of the stride; the CPG's phase shift (cycles, + advanced) 4-7 cycles later
        against the unpushed rollout, and the CPG cycles until the body's touchdowns lock
        to the CPG's bursts again. Open loop the CPG's phase cannot move; with --feedback
        it can. Writes --out/phase_response_<network>_<preset>.json and .png.""")
    network_args(sp)
    sp.add_argument("--impulse", type=finite_arg, default=5.0, metavar="NS",
                    help="push impulse, N s forwards (negative: backwards; default 5)")
    sp.add_argument("--out", default="out/robustness", metavar="DIR",
                    help="folder for the JSON and the picture (default out/robustness)")
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("transition", cmd_transition, "change the network's parameters in mid-run", """\
        The network starts as preset --from (Table 3 state, or --seed's random state) and
        its parameters move to --to's at --at s (simulation time from the start, settling included): a step, or a
        linear ramp over --ramp s. The CPG's state carries across; the controller is not
        told. Metrics before the change, and after the physical gait has settled (sliding
        windows of 3 CPG cycles; cycles_to_switch counts the CPG cycles from the change until
        the settled gait is --to). --out writes a video whose CPG strip marks the change,
        with FILE_gait.png (the whole rollout's gait diagram, the change marked); --rrd a
        rerun recording with the change as an event.""")
    sp.add_argument("--from", required=True, metavar="A", help="the starting gait (preset)")
    sp.add_argument("--to", required=True, metavar="B", help="the gait (preset) changed to")
    sp.add_argument("--at", type=finite_arg, default=8.0, metavar="T_S",
                    help="time of the change, s from the start (default 8)")
    sp.add_argument("--ramp", type=finite_arg, default=0.0, metavar="R_S",
                    help="ramp length, s (default 0: a step)")
    sp.add_argument("--seconds", type=seconds_arg, default=None,
                    help="whole rollout, s (default: the change's end + 12 s within a family, "
                         "walk <-> run or jump <-> hop, + 30 s across them, where the network "
                         "takes longer to lock)")
    sp.add_argument("--network", default="ml", choices=("ml", "hopf"))
    sp.add_argument("--seed", type=seed_arg, default=None,
                    help="start --from's network from the random initial CPG state of this "
                         "seed (default: its Table 3 state)")
    feedback_option(sp, " (Morris-Lecar)")
    feedback_form_option(sp)
    sp.add_argument("--width", type=count_arg(1), default=640)
    sp.add_argument("--height", type=count_arg(1), default=480)
    sp.add_argument("--fps", type=positive_arg, default=30.0)
    sp.add_argument("--out", default=None, metavar="FILE.mp4", help="also render a video")
    sp.add_argument("--rrd", default=None, metavar="FILE.rrd", help="also write a rerun recording")
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("sweep", cmd_sweep, "a slow drive sweep walk<->run or jump<->hop, with hysteresis", """\
        One drive d in [0, 1] moves every parameter of the network linearly from preset A
        (d = 0) to preset B (d = 1): 0 until 4 s, a ramp up over --ramp-seconds, 4 s held, a
        ramp down, 4 s at 0; one rollout. The physical gait is named in sliding 3 s windows;
        the drive, speed and Froude number where it switches to B on the way up and leaves
        it on the way down, and their difference (hysteresis). Writes
        --out/sweep_<network>_<pair>.json and .png (speed and gait against the drive), and
        with --video an mp4 whose CPG strip marks the ramps' corners.""")
    sp.add_argument("--pair", default="walk-run", help="walk-run or jump-hop (default walk-run)")
    sp.add_argument("--ramp-seconds", type=finite_arg, default=40.0, metavar="R",
                    help="length of each ramp, s in [5, 200] (default 40)")
    sp.add_argument("--network", default="ml", choices=("ml", "hopf"))
    feedback_option(sp, " (Morris-Lecar)")
    sp.add_argument("--video", action="store_true", help="also render the sweep to mp4")
    sp.add_argument("--out", default="out/sweep", metavar="DIR")
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("check-secondary", cmd_check_secondary,
             "run the secondary gaits found by 'secondary' through the body", """\
        Every weight set of a 'cpgbiped secondary' results file (DIR/secondary.json): the
        12 directed weights with I_app and phi, from the Table 3 state of the gait they were
        broken from, drive the body through the one controller. Prints the gait the CPG
        classifier names and the physical gait (primary patterns, then skip, gallop,
        hesitation walk, asymmetric hop, one-legged hop from the contacts alone). With
        --out DIR, all or nothing: DIR/check_secondary.json, a chronophotograph of each
        rollout (<target>_from_<source>_chrono.png: two strides' poses and the footfalls,
        up to a fall) and all of them in one picture, DIR/secondary_chrono.png.""")
    sp.add_argument("secondary", metavar="SECONDARY.json", help="cpgbiped secondary's result")
    sp.add_argument("--seconds", type=seconds_arg, default=20.0,
                    help="simulated seconds after 2 s of settling (default 20)")
    sp.add_argument("--workers", type=count_arg(1), default=2, help="parallel processes (default 2)")
    sp.add_argument("--states", type=count_arg(0), default=0, metavar="N",
                    help="also drive each weight set from N random initial CPG states (seeds "
                         "3000 and up, never tuned on) and count the confirmations (default 0)")
    sp.add_argument("--out", metavar="DIR", default=None,
                    help="also write DIR/check_secondary.json, a chronophotograph of each "
                         "rollout and all of them in DIR/secondary_chrono.png")
    sp.add_argument("--json", action="store_true", help="print JSON")

    sp = add("check-pareto", cmd_check_pareto, "run an optimiser result's Pareto points in physics",
             """\
        Take an optimiser result (cpgbiped optimize ... --out DIR: DIR/<gait>.json), run
        every Pareto point (or the first N) through the physical validation in parallel
        processes, optionally render each, and write DIR/pareto_check.md, .csv and .json:
        weights, phase errors, physical metrics and PASS/fail per point.""")
    sp.add_argument("result", help="optimiser result JSON")
    sp.add_argument("--first", type=count_arg(1), default=None, metavar="N", help="only the first N points")
    sp.add_argument("--seconds", type=seconds_arg, default=20.0)
    sp.add_argument("--render", action="store_true", help="render each point to video")
    sp.add_argument("--rrd", metavar="FILE.rrd", help="log every point to one recording")
    sp.add_argument("--workers", type=count_arg(1), default=2, help="parallel processes (default 2)")
    sp.add_argument("--out", required=True, metavar="DIR")
    sp.add_argument("--quiet", action="store_true")

    sp = add("reproduce", cmd_reproduce, "the paper's four gaits from its Table 2 weights", """\
        Simulate the 4-cell network for walk, run, jump and hop with the paper's Table 2
        (I_app, phi, w_a, w_b, w_c) from its Table 3 initial states for 500 model time units,
        analyse the second half and print: the period (model time units), the phases of RF,
        LE, RE behind LF (degrees, [0, 360)), whether all four waveforms are equal, and the
        gait the classifier names. Targets: walk 180/180/0, run 180/0/180, jump 0/180/180,
        hop 0/0/0.""")
    sp.add_argument("--json", action="store_true", help="print one JSON object keyed by gait")
    sp.add_argument("--plot", action="store_true",
                    help="write the steady-state signals (PNG) to --out")
    sp.add_argument("--out", default="out", help="folder for --plot (default: out)")
    sp.add_argument("--dt", type=dt_arg, default=0.02,
                    help="RK4 step, model units in [0.001, 0.1] (default 0.02)")

    sp = add("matsuoka", cmd_matsuoka, "the 12-neuron Matsuoka network: printed vs calibrated",
             """\
        Measure what the printed Matsuoka parameters produce (frequency, the repetition rate
        of each joint's extensor-minus-flexor drive, left/right phase) with and without the
        paper's white noise (L = 1.5), next to the calibrated preset that reaches the claimed
        1 Hz. See cpg/matsuoka.py for the calibration and why.""")
    sp.add_argument("--json", action="store_true", help="print JSON")
    sp.add_argument("--seed", type=seed_arg, default=0, help="noise seed (default 0)")

    sp = add("optimize", cmd_optimize, "NSGA-II search of (w_a, w_b, w_c) for primary gaits", """\
        Search the three symmetric coupling weights with NSGA-II (pymoo) for a primary gait,
        with that gait's Table 2 (I_app, phi). Objectives: the wrapped phase errors (degrees)
        of RF, LE, RE vs LF; a weight set that diverges, does not oscillate or settles to
        unequal waveforms is infeasible. The whole population is integrated in one batch.
        Writes DIR/<gait>.json (chosen point, Pareto set, the paper's weights evaluated the
        same way), DIR/<gait>_population.csv, DIR/<gait>_pareto.csv and a PNG of the front;
        with --gait all also DIR/comparison.md. A checkpoint is written every N generations;
        running the same command again after an interrupt resumes from it.
        Defaults (pop 40, 25 generations) reach errors below 1 degree for all four gaits.

        With --physics the search is physical: variables (w_a, w_b, w_c, I_app, phi) in a box
        around Table 2 (weights [-1, 1], I_app [0.18, 0.35], phi [0.12, 0.5]); each point
        drives the biped through the one controller (20 s after 2 s of settling) and meets
        --trials perturbations drawn from the seed (random initial CPG state, friction x0.7-1.3,
        a 2-6 N s push). Objectives: |Fr - Fr*|, cost of transport (walk, run) or work per
        stride / (m g L) (jump, hop), fraction of perturbation trials failed; constraint: the
        unperturbed rollout is the gait, by the contacts and by the CPG classifier, without a
        fall. The first generation holds the
        paper's row. Rollouts run in one process per core (--workers), or on Dask (--dask);
        the same seed gives the same result either way. Writes DIR/<gait>_physics.json (read
        by check-pareto), DIR/<gait>_physics_population.csv, DIR/<gait>_physics_pareto.csv and
        DIR/<gait>_physics_pareto.png.""")
    sp.add_argument("--gait", default="all", help="walk, run, jump, hop or all (default all; "
                    "--physics takes one gait)")
    sp.add_argument("--pop", type=count_arg(4), default=None,
                    help="population size (default 40; 32 with --physics)")
    sp.add_argument("--gens", type=count_arg(1), default=None,
                    help="generations (default 25; 20 with --physics)")
    sp.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    sp.add_argument("--physics", action="store_true",
                    help="score (w_a, w_b, w_c, I_app, phi) by rollouts of the biped: objectives "
                         "|Fr - Fr*|, cost of transport (work per stride for jump and hop), "
                         "fraction of perturbation trials failed; constraint: the gait (by the "
                         "contacts and by the CPG classifier), no fall")
    sp.add_argument("--froude", type=finite_arg, default=None, metavar="FR",
                    help="--physics: target Froude number (default walk 0.25, run 0.5, jump and "
                         "hop 0.02)")
    sp.add_argument("--seconds", type=seconds_arg, default=None,
                    help="--physics: measured seconds per rollout, after 2 s of settling "
                         "(default 20)")
    sp.add_argument("--trials", type=count_arg(0), default=None, metavar="N",
                    help="--physics: perturbation trials per point (default 4)")
    sp.add_argument("--workers", type=count_arg(1), default=None,
                    help="--physics: rollout processes (default: one per core)")
    sp.add_argument("--bounds", type=float, nargs=2, default=[-1.0, 1.0], metavar=("LO", "HI"),
                    help="search box for every weight (default -1 1)")
    sp.add_argument("--checkpoint-every", type=count_arg(1), default=5, metavar="N",
                    help="checkpoint interval in generations (default 5)")
    sp.add_argument("--dask", nargs="?", const="local", default=None, metavar="ADDRESS",
                    help="evaluate on Dask: a LocalCluster, or the scheduler at tcp://host:port")
    sp.add_argument("--robustness-objective", type=bounded_count_arg(0, MAX_ROBUSTNESS_STATES),
                    default=0, metavar="N",
                    help="add the objective 1 - fraction of N random initial states reaching "
                         f"the gait (N+1 integrations per individual; N <= "
                         f"{MAX_ROBUSTNESS_STATES})")
    sp.add_argument("--lock-time-objective", action="store_true",
                    help="add the objective: model time until the phases stay within 2 deg")
    feedback_option(sp, " (--physics only)")
    sp.add_argument("--out", default="out/optimize", help="output folder (default out/optimize)")
    sp.add_argument("--quiet", action="store_true", help="no progress bar")

    sp = add("tune", cmd_tune, "tune the one controller's gains in physics (pymoo)", """\
        Search the one controller's gains with pymoo: CMA-ES (default) or NSGA-II. The
        variables are the blended gains at the corners of the (synchrony, co-activation)
        square that the named gaits' Morris-Lecar presets sit at (--gait walk: the
        alternating corner; --gait jump,hop: both synchronous corners; --gait all: all
        four), or with --search shared the parameters every gait shares (ankle gain, swing
        wiring, contact hold), or both. Each candidate drives each named preset for 2 s of
        settling plus
        --seconds under --conditions tuning conditions (random initial CPG states from
        seeds 1000 and up, other floor frictions, pushes on the torso: disjoint from the
        conditions the tests and the README report). Its cost comes from the criteria of
        envs/criteria.py: seconds upright, distance towards the target Froude number (walk,
        run), the pattern and quality shortfalls, one stride per CPG cycle. The search
        starts from --start (default: the controller's own gains file) and keeps what it
        does not search. Writes DIR/gains.json (the gains file with the best values and a
        provenance entry: command, seed, algorithm, budget, conditions, cost, the SHA-256 of
        the starting file), DIR/tune_history.csv and DIR/tune_conditions.csv. A checkpoint
        is written every N generations; the same command resumes after an interrupt, with
        the result of an uninterrupted run.""")
    sp.add_argument("--gait", required=True,
                    help="walk, run, jump, hop, a comma-separated list, or all")
    sp.add_argument("--search", choices=("corners", "shared", "both"), default="corners",
                    help="what to search: the named gaits' corners (default), the shared "
                         "parameters (ankle gain, swing wiring, contact hold; best with "
                         "--gait all), or both")
    sp.add_argument("--algorithm", choices=("cmaes", "nsga2"), default="cmaes",
                    help="CMA-ES (default) or NSGA-II")
    sp.add_argument("--pop", type=count_arg(4), default=24, help="population size (default 24)")
    sp.add_argument("--gens", type=count_arg(1), default=100, help="generations (default 100)")
    sp.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    sp.add_argument("--seconds", type=seconds_arg, default=10.0,
                    help="measured seconds per rollout after 2 s of settling (2-60, default 10)")
    sp.add_argument("--conditions", type=conditions_arg, default=(6, ()), metavar="N",
                    help="tuning conditions per candidate: the first N (1-56, default 6), "
                         "or numbers and ranges such as 1-8,21-24 (21-24: CPG states "
                         "from which the walk network starts in a jump's rhythm; 25-28: "
                         "pushes of 8 N s; 29-32: a floor of friction x0.4; 33-36: x0.6; "
                         "37-40: 5 N s pushes held 0.2 s at 12.3 and 12.8 s, a settled gait's, "
                         "with --seconds 12 or more; 41-48: the network changed to the gait's "
                         "partner in its family (walk <-> run, jump <-> hop) at 7 or 7.5 s, a "
                         "step or a 2 s ramp, open loop or with feedback, judged as the "
                         "partner from 4 of its cycles after the change for 5 s, whatever "
                         "--seconds; 49-56: pushes held 0.2 s with the feedback on, 10 N s "
                         "forwards and 5 or 15 N s backwards, at 6.3-6.75 s, with --seconds 6 "
                         "or more)")
    sp.add_argument("--sigma", type=finite_arg, default=0.15,
                    help="initial step in units of each gain's range (CMA-ES; NSGA-II's "
                         "first population's spread; default 0.15)")
    sp.add_argument("--only", default="", metavar="GAINS",
                    help="search only these gains (comma-separated names, e.g. "
                         "push_off,knee_hold), at the corners or among the shared parameters "
                         "that --gait and --search select; a name may be one corner's "
                         "(synchronous.theta0) or all of it (synchronous.*), so that "
                         "--gait walk,jump --only 'synchronous.*' searches the jump's corner "
                         "scored on both gaits; land_yield, x_bal, lean_knee, toe_up, capture_place, capture_ankle, force_fb, lift_abort, restart_v, sync_land and pitch_tau_s are "
                         "searched only when named here; startup.<corner>.<gain> or startup.<corner>.* searches "
                         "the start-up gains that hand over to the corners in the first "
                         "seconds (every gait starts on them)")
    sp.add_argument("--start", default=None, metavar="GAINS.json",
                    help="gains file to start from (default: the controller's, envs/control/gains.json)")
    sp.add_argument("--guard", default="", metavar="GAITS",
                    help="gaits (also named in --gait) that may not get worse: in every "
                         "condition a guarded gait's cost above its cost under --guard-gains "
                         "(plus 0.1) counts 10 times, so that a search of one gait's corner "
                         "cannot buy it with another gait's quality")
    sp.add_argument("--guard-gains", default=None, metavar="GAINS.json",
                    help="the gains the guard compares with (default: --start)")
    sp.add_argument("--shortfall-weight", type=finite_arg, default=None, metavar="W",
                    help="weight of the criteria's pattern and quality shortfalls in the cost "
                         "(default 3, against 10 for seconds upright and for progress; 0-100)")
    sp.add_argument("--survival-only", type=condition_ids_arg, default=(), metavar="IDS",
                    help="conditions (numbers and ranges, among --conditions) scored on the "
                         "seconds upright and the fall alone, not the speed or the criteria: "
                         "a floor where staying up is all that is asked (e.g. 29-36)")
    sp.add_argument("--target-froude", type=target_froude_arg, default=(),
                    metavar="GAIT=FR[,GAIT=FR]",
                    help="the progress target's Froude number for walk or run (default walk "
                         "0.11, run 0.33; a target just above the criteria's minimum, e.g. "
                         "run=0.26, asks the search to keep the speed rather than gain more; "
                         "(0, 1])")
    sp.add_argument("--progress-weight", type=finite_arg, default=None, metavar="W",
                    help="weight of the progress term (walk and run: the distance short of "
                         "the target speed's; default 10, as the seconds upright; 0-1000)")
    sp.add_argument("--worst-weight", type=finite_arg, default=None, metavar="W",
                    help="weight of the worst condition's cost beside the mean (CMA-ES "
                         "minimises mean + W max, and the best point is picked so; default "
                         "0.5; 0: the mean alone; 0-10)")
    sp.add_argument("--workers", type=count_arg(1), default=None,
                    help="rollout processes (default: one per core)")
    sp.add_argument("--dask", nargs="?", const="local", default=None, metavar="ADDRESS",
                    help="roll out on Dask: a LocalCluster, or the scheduler at tcp://host:port")
    sp.add_argument("--checkpoint-every", type=count_arg(1), default=5, metavar="N",
                    help="checkpoint interval in generations (default 5)")
    sp.add_argument("--out", default="out/tune", help="output folder (default out/tune)")
    sp.add_argument("--quiet", action="store_true", help="no progress bar")

    sp = add("secondary", cmd_secondary, "secondary gaits by symmetry breaking", """\
        From each primary gait's weights (the optimiser's results in --results when present,
        else the paper's), search perturbations of the 12 directed weights that keep one
        reflection of the network and break the others, for the paper's three transitions
        (skip from walk and from run, gallop from walk, hesitation walk from jump) and the
        four it did not reach (gallop from jump, hesitation walk from run, asymmetric hop,
        one-legged hop). Each best point is re-simulated from the Table 3 state and 10 random
        states; "found" needs the classifier to name the target from the Table 3 state and
        from at least 80% of all states. Writes DIR/secondary.json and DIR/comparison.md.""")
    sp.add_argument("--physics", action="store_true",
                    help="choose each target's weight set by the body: network searches over "
                         "a grid of target lags, every candidate driven through the one "
                         "controller from --states random CPG states (seeds 1000 and up), the "
                         "one both classifiers confirm most often kept")
    sp.add_argument("--states", type=count_arg(1), default=None,
                    help="with --physics: random CPG states per candidate (default 6, at most 32)")
    sp.add_argument("--workers", type=count_arg(1), default=None,
                    help="with --physics: parallel processes for the body (default 2, or 1 on "
                         "one core)")
    sp.add_argument("--results", default=None,
                    help="folder with <gait>.json optimiser results (default out/optimize when "
                         "it exists; the paper's weights for any gait without one)")
    sp.add_argument("--pop", type=count_arg(4), default=40, help="population size (default 40)")
    sp.add_argument("--gens", type=count_arg(1), default=30, help="generations per target (default 30)")
    sp.add_argument("--seed", type=seed_arg, default=0)
    sp.add_argument("--dask", nargs="?", const="local", default=None, metavar="ADDRESS",
                    help="evaluate on Dask: a LocalCluster, or the scheduler at tcp://host:port")
    sp.add_argument("--out", default="out/optimize", help="output folder (default out/optimize)")
    sp.add_argument("--quiet", action="store_true", help="no progress bar")

    sp = add("hopf", cmd_hopf, "a primary gait in the Hopf network", """\
        Four Hopf oscillators (LF, RF, LE, RE) with stance/swing asymmetry and rotation
        coupling set to a primary gait's phase lags, from a random state; prints the period
        (seconds) and the phases the analysis measures.""")
    sp.add_argument("--gait", default="walk", help="walk, run, jump or hop (default walk)")
    sp.add_argument("--beta", type=float, default=0.6, help="duty factor in (0, 1)")
    sp.add_argument("--normalised", action="store_true", help="normalised coupling variant")
    sp.add_argument("--seconds", type=seconds_arg, default=20.0, help="simulated seconds")
    sp.add_argument("--seed", type=seed_arg, default=0)
    sp.add_argument("--json", action="store_true")
    return p


GL_BACKENDS = ("osmesa", "egl")  # off-screen only: glfw needs a display (and warns without)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where Ctrl-C would be, so that it takes the same clean-up paths
    (staging folders removed, worker pools and Dask clusters shut down)."""


_SIGNALLED: list[int] = []  # signals received during this run of main()
_CONSOLE: list[bool] = []  # set while main() runs as the console entry point (its process ends)


def _quiet_unraisable(unraisable) -> None:
    """sys.unraisablehook once the console's run is interrupted: a library object the
    interrupt caught half-built reports its finaliser's error ("Exception ignored in ...")
    when it is freed, after the run's one line (pyparsing's Forward once in a fresh-clone CI:
    its __del__ reads an attribute its interrupted __init__ never set). The run is over and
    its clean-up paths have run; the report is dropped."""


def _signalled(signum) -> None:
    _SIGNALLED.append(signum)
    if _CONSOLE:
        sys.unraisablehook = _quiet_unraisable


# Where an exception raised by a signal handler would be swallowed ("Exception ignored ...")
# or would corrupt a native library's state: numba's compiler and llvmlite's ctypes callbacks
# (sometimes a segfault or exit -2 after), weakref callbacks run by the garbage collector (the
# interrupt lost: the run carried on and ended with exit 0).
_SWALLOWING = (f"{os.sep}numba{os.sep}", f"{os.sep}llvmlite{os.sep}", f"{os.sep}weakref.py",
               f"{os.sep}_weakrefset.py")
RESEND_S = 0.05  # how soon a signal put off is sent again


def _put_off(signum, frame) -> bool:
    """True (and the signal sent to this process again in RESEND_S) when it arrived where an
    exception would be swallowed or would corrupt a library (``_SWALLOWING``, or a finaliser
    ``__del__``). Measured with scripts/check_interrupts.py (seed 3): 9 of 150 Ctrl-Cs sent
    0.5-1.3 s into a render (numba loading its kernels) ended with exit -2 or a "Fatal Python
    error";
    Ctrl-Cs 2.6-3.6 s into it were sometimes lost in a weakref callback."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "__del__" or any(d in code.co_filename for d in _SWALLOWING):
            import threading

            t = threading.Timer(RESEND_S, os.kill, (os.getpid(), signum))
            t.daemon = True
            t.start()
            return True
        frame = frame.f_back
    return False


def _on_sigterm(signum, frame):
    if _put_off(signum, frame):
        return
    _signalled(signum)
    raise Terminated()


def _on_sigint(signum, frame):
    if _put_off(signum, frame):
        return
    _signalled(signum)
    raise KeyboardInterrupt()


def main(argv: list[str] | None = None, *, ignore_signals_after: bool = False) -> int:
    """Run the command line; every failure is one line on stderr: exit 2 for bad input, 1 for
    anything unexpected ("internal error"; the traceback only with --debug), 130 on Ctrl-C,
    143 on SIGTERM (handled like Ctrl-C). The signal handlers it installs are restored on the
    way out, or, with ``ignore_signals_after`` (the console entry point, whose process ends
    next), replaced by SIG_IGN without a moment of the default handlers in between: a second
    Ctrl-C right after the first was handled would otherwise kill the interpreter (exit -2)."""
    import threading

    previous = {}
    _SIGNALLED.clear()
    _CONSOLE[:] = [True] if ignore_signals_after else []
    if threading.current_thread() is threading.main_thread():
        previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _on_sigterm)}
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, _on_sigint)
    try:
        return _main(argv)
    finally:
        for sig, handler in previous.items():
            if ignore_signals_after:
                signal.signal(sig, signal.SIG_IGN)
            elif handler is not None:
                signal.signal(sig, handler)


def _main(argv: list[str] | None) -> int:
    from cpgbiped.cpg.errors import InputError

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    argv = [a for a in argv if a != "--debug"]
    try:
        args = build_parser().parse_args(argv)
        args.argv = argv
        gl = os.environ.get("MUJOCO_GL")
        if gl not in GL_BACKENDS:  # mujoco would refuse to import with a traceback
            return _fail(f"unsupported MUJOCO_GL={gl!r}: use osmesa (default, apt package "
                         f"libosmesa6) or egl (libegl1)")
        return int(args.func(args) or 0)
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else 0
    except InputError as e:
        return _fail(str(e))
    except Terminated:
        print("cpgbiped: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("cpgbiped: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # noqa: BLE001 - the last resort: one line, never a bare traceback
        if _SIGNALLED and not debug:
            # the interrupt reached a library that turned it into an error of its own (seen
            # once in some 55 terminal Ctrl-Cs: matplotlib's "Invalid bounding box"): it is
            # still an interrupt, and the clean-up paths have run on the way out
            term = _SIGNALLED[0] == signal.SIGTERM
            print(f"cpgbiped: {'terminated' if term else 'interrupted'}", file=sys.stderr)
            return 143 if term else 130
        if debug:
            import traceback

            traceback.print_exc()
        msg = " ".join(str(e).split()) or "(no message)"
        print(f"cpgbiped: internal error: {type(e).__name__}: {msg}"
              + ("" if debug else " (run again with --debug for the traceback)"), file=sys.stderr)
        return 1


def run() -> int:
    """The console entry point: :func:`main`, which leaves Ctrl-C and SIGTERM ignored while
    the interpreter shuts down (the run is over and its outputs are in place: an interrupt
    then would only print a traceback and exit -2). An interrupted or terminated run (130,
    143) has already cleaned up on its way out (staging folders removed, worker processes
    shut down), so it leaves without the interpreter's finalization: once in some hundred
    SIGTERMs a native thread still running there (seen in ``optimize --physics``) aborted
    the finalizing interpreter ("PyThreadState_Get: the function must be called with the GIL
    held", exit -6) after the one line had been printed."""
    code = main(ignore_signals_after=True)
    if code in (130, 143):
        import atexit
        import threading

        # what the interpreter's finalization does first, in its order (join the threads and
        # their exit hooks - concurrent.futures' among them - then the atexit functions:
        # multiprocessing's release its semaphores), and then leave before the teardown
        threading._shutdown()
        atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


if __name__ == "__main__":
    sys.exit(run())
