"""The README's transition report: every ordered pair of primary gaits, as a step and as a 2 s
ramp, open loop and with the recommended feedback, with the network's own left-right
synchrony after the change; every pair with the Hopf network too (open loop); the drive
sweeps walk<->run and jump<->hop.

    python scripts/report_transitions.py [--out out/report_transitions] [--workers 2]
                                         [--img docs/img]

The change comes at 8 s (after 6 s of the first gait), the rollout ends 12 s after the change
ends within a family (walk <-> run, jump <-> hop) and 30 s after it across the families, where
the network alone takes up to 300 model units (24 s) to lock to the new pattern
(``transition.default_seconds``, the command line's default). The in-family steps and ramps
are repeated with the change at 9-14 s, and so is every cross-family way: the body is
chaotic, and one time of change says little about the next (issue 22's test: no fall, A
named before the change, B within 4 CPG cycles after it). Writes OUT/report.md, OUT/report.json and the sweep
pictures (also into --img).
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from cpgbiped.envs.experiments.transition import IN_FAMILY

GAITS = ("walk", "run", "jump", "hop")
AT_S = (8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0)  # times of the change (the first: every pair;
# all of them: the in-family steps and ramps and every cross-family way)
PASS_CYCLES = 4  # issue 22: B within 4 CPG cycles of the change


def _one(job):
    kind, a, b, ramp, K, at = job
    from cpgbiped.envs.experiments.transition import default_seconds, transition

    res, *_ = transition(kind, a, b, at, ramp, default_seconds(a, b, at, ramp), K)
    return res


def _sync(r) -> str:
    """The network's own extensor synchrony in the 2nd-4th CPG cycles after the change (0: the
    legs' bursts alternate, 1: in phase), from the transition's JSON."""
    xs = [x for x in r["cpg_extensor_synchrony"][1:4] if x is not None]
    return "-" if not xs else f"{min(xs):.2f}-{max(xs):.2f}"


def reached(r) -> bool:
    """The target's physical gait settled without a fall (``cycles_to_switch`` is set only
    then), however long it took."""
    return r["cycles_to_switch"] is not None


def passes(r) -> bool:
    """Issue 22's test: no fall, A named before the change, B within PASS_CYCLES cycles."""
    return (reached(r) and r["before"]["physical_gait"] == r["from"]
            and r["cycles_to_switch"] <= PASS_CYCLES)


def _cell(r) -> str:
    if r["fell"]:
        return "fell %.1f s" % r["fell_at_s"]
    c = r["cycles_to_switch"]
    txt = f"{r['before']['physical_gait']} -> {r['after']['physical_gait']}"
    txt += "" if c is None else f", {c} cycle" + ("" if c == 1 else "s")
    return f"**{txt}**" if passes(r) else txt


def _reached(rows, name) -> str:
    """How many of the 8 cross-family ordered pairs reach their target without a fall in at
    least one of the ways run (step or ramp, open or closed loop), and which."""
    got = sorted({(r["from"], r["to"]) for r in rows
                  if (r["from"], r["to"]) not in IN_FAMILY and reached(r)})
    return (f"{name}: {len(got)} of the 8 cross-family pairs reach their target without a fall "
            "in at least one way" + (": " + ", ".join(f"{a} -> {b}" for a, b in got)
                                     if got else "") + ".")


def _sweep(job):
    pair, K = job
    from cpgbiped.envs.experiments.sweep import sweep

    return sweep(pair, 40.0, "ml", K)[0]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/report_transitions")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--img", default=None)
    a = ap.parse_args(argv)
    from cpgbiped.cpg.feedback import RECOMMENDED
    from cpgbiped.cpg.io import ensure_dir, write_text
    from cpgbiped.envs.experiments.sweep import picture

    out = ensure_dir(a.out)
    K = RECOMMENDED["ml"]
    jobs = [("ml", x, y, r, k, AT_S[0]) for x in GAITS for y in GAITS if x != y for r in (0.0, 2.0)
            for k in (0.0, K)]
    later = [("ml", x, y, r, k, at) for x, y in sorted(IN_FAMILY) for r in (0.0, 2.0)
             for k in (0.0, K) for at in AT_S[1:]]
    cross = [("ml", x, y, r, k, at) for x in GAITS for y in GAITS
             if x != y and (x, y) not in IN_FAMILY for r in (0.0, 2.0) for k in (0.0, K)
             for at in AT_S[1:]]
    hopf = [("hopf", x, y, r, 0.0, AT_S[0]) for x in GAITS for y in GAITS if x != y
            for r in (0.0, 2.0)]
    sweeps = [(p, k) for p in ("walk-run", "jump-hop") for k in (0.0, K)]
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(_one, jobs))
        times = list(ex.map(_one, later))
        cross_times = list(ex.map(_one, cross))
        hopf_rows = list(ex.map(_one, hopf))
        sw = list(ex.map(_sweep, sweeps))
    md = ["### Transitions (Morris-Lecar, change at 8 s)", "",
          "before / after: the physical gait the contacts name before the change and once it "
          "has settled; cycles: CPG cycles from the change until the settled gait is the "
          "target (- never); CPG sync: the network's own extensor synchrony in the 2nd-4th "
          "cycles after the change (share of the bursting time in which both legs' extensors "
          "burst: 0 alternating, as a walk's or run's network; 1 in phase, as a jump's or "
          "hop's).", "",
          "| from -> to | change | K | before | after | fell | cycles | CPG sync | outcome |",
          "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        outcome = ("switched" if r["switched"] else
                   "reached the target" if reached(r) else "fell" if r["fell"] else "not reached")
        fam = "" if (r["from"], r["to"]) in IN_FAMILY else " (cross)"
        md.append(f"| {r['from']} -> {r['to']}{fam} | "
                  f"{'step' if r['ramp_s'] == 0 else 'ramp %g s' % r['ramp_s']} | "
                  f"{r['feedback_gain']:g} | {r['before']['physical_gait']} | "
                  f"{r['after']['physical_gait']} | "
                  f"{'%.1f s' % r['fell_at_s'] if r['fell'] else 'no'} | "
                  f"{'-' if r['cycles_to_switch'] is None else r['cycles_to_switch']} | "
                  f"{_sync(r)} | {outcome} |")
    md += ["", _reached(rows, "Morris-Lecar")]
    md += ["", "### Transitions, Hopf network (open loop, change at 8 s)", "",
           "passes: issue 22's test for an in-family pair; for a cross-family pair, whether "
           "the target is reached without a fall.", "",
           "| from -> to | change | before | after | fell | cycles | CPG sync | passes |",
           "|---|---|---|---|---|---|---|---|"]
    for r in hopf_rows:
        fam = "" if (r["from"], r["to"]) in IN_FAMILY else " (cross)"
        ok = reached(r) if fam else passes(r)
        md.append(f"| {r['from']} -> {r['to']}{fam} | "
                  f"{'step' if r['ramp_s'] == 0 else 'ramp %g s' % r['ramp_s']} | "
                  f"{r['before']['physical_gait']} | {r['after']['physical_gait']} | "
                  f"{'%.1f s' % r['fell_at_s'] if r['fell'] else 'no'} | "
                  f"{'-' if r['cycles_to_switch'] is None else r['cycles_to_switch']} | "
                  f"{_sync(r)} | {'**yes**' if ok else 'no'} |")
    md += ["", _reached(hopf_rows, "Hopf")]
    md += ["", "### In-family transitions against the time of the change", "",
           "before -> after, and the CPG cycles from the change's start to the switch (a 2 s "
           "ramp itself spans 1.9 CPG cycles of the walk, 2.8 of the run, 2.1 of the jump and 3.1 of the "
           "hop); in bold where "
           f"issue 22's test passes (no fall, A before, B within {PASS_CYCLES} cycles).", "",
           "| from -> to | change | K | " + " | ".join(f"{t:g} s" for t in AT_S) + " | passes |",
           "|---|---|---|" + "---|" * len(AT_S) + "---|"]
    by_time = {(r["from"], r["to"], r["ramp_s"], r["feedback_gain"], r["at_s"]): r
               for r in rows + times if (r["from"], r["to"]) in IN_FAMILY}
    for x, y in sorted(IN_FAMILY):
        for ramp in (0.0, 2.0):
            for k in (0.0, K):
                cells = [by_time[x, y, ramp, k, at] for at in AT_S]
                md.append(f"| {x} -> {y} | {'step' if ramp == 0 else 'ramp %g s' % ramp} | "
                          f"{k:g} | " + " | ".join(_cell(r) for r in cells)
                          + f" | {sum(map(passes, cells))}/{len(cells)} |")
    ways = [(r, k) for r in (0.0, 2.0) for k in (0.0, K)]
    md += ["", "### Cross-family pairs against the time of the change (Morris-Lecar)", "",
           "Of the changes at " + ", ".join(f"{t:g}" for t in AT_S) + " s, how many reach the "
           "target without a fall, each way (x: reached, .: not, in the order of the times).",
           "", "| from -> to | " + " | ".join(
               f"{'step' if r == 0 else 'ramp %g s' % r}, K = {k:g}" for r, k in ways)
           + " | best |", "|---|" + "---|" * len(ways) + "---|"]
    by = {}
    for r in rows + cross_times:
        if (r["from"], r["to"]) not in IN_FAMILY:
            by.setdefault((r["from"], r["to"], r["ramp_s"], r["feedback_gain"]), []).append(r)
    for x in GAITS:
        for y in GAITS:
            if x == y or (x, y) in IN_FAMILY:
                continue
            cells = []
            for r, k in ways:
                rs = sorted(by[x, y, r, k], key=lambda q: q["at_s"])
                hit = [reached(q) for q in rs]
                cells.append((sum(hit), len(hit), "".join("x" if h else "." for h in hit)))
            md.append(f"| {x} -> {y} | " + " | ".join(f"{n}/{m} `{t}`" for n, m, t in cells)
                      + f" | {max(c[0] for c in cells)}/{len(AT_S)} |")
    md += ["", "### Drive sweeps (ramps of 40 s)", "",
           "| sweep | K | switch up: drive, speed, Froude | switch down: drive, speed, Froude "
           "| hysteresis (drive) | fell |", "|---|---|---|---|---|---|"]
    img = []
    f = lambda p: "-" if p is None else (  # noqa: E731
        f"{p['drive']:.2f}, {p['speed_mps']:.2f} m/s, {p['froude']:.3f}")
    for (pair, k), res in zip(sweeps, sw):
        hy = res["hysteresis_drive"]
        md.append(f"| {pair} | {k:g} | {f(res['switch_up'])} | {f(res['switch_down'])} | "
                  f"{'-' if hy is None else '%+.2f' % hy} | "
                  f"{'%.1f s' % res['fell_at_s'] if res['fell'] else 'no'} |")
        p = Path(out) / f"sweep_ml_{pair}{'_K%g' % k if k else ''}.png"
        picture(res, p)
        img.append(p)
    text = "\n".join(md) + "\n"
    write_text(Path(out) / "report.md", text)
    (Path(out) / "report.json").write_text(json.dumps({"transitions": rows, "change_times": times,
                                                       "cross_change_times": cross_times,
                                                       "hopf_in_family": hopf_rows,
                                                       "sweeps": sw},
                                                      indent=1, default=float))
    if a.img:
        ensure_dir(a.img)
        for p in img:
            shutil.copy(p, Path(a.img) / p.name)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
