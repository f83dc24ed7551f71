"""rerun recordings of rollouts: the body, the footfalls, the CPG, on a ``sim_time`` timeline.

Entities, per rollout under ``/<name>`` (e.g. ``/walk``):
  world/...                           the body: static geometry from the MuJoCo model, each
                                      body's pose per control tick, the floor, the ground
                                      reaction force arrows while a foot is in contact and the
                                      centre of mass (:mod:`cpgbiped.envs.media.record_body`)
  feet/left, feet/right               StateChange "stance"/"swing" at each debounced touchdown
                                      and lift-off: the footfall diagram, one lane per foot
  contacts                            debounced foot contact (0/1), series left, right
  force                               normal ground reaction force at the tick's last physics
                                      step (N; the one that decides contact), series left, right
  force_x, force_z                    horizontal (N, > 0 forwards) and vertical (N, > 0 up)
                                      ground reaction force, each tick's mean over its physics
                                      steps (the arrows' too), series left, right
  cpg                                 the four CPG cell outputs, series LF, RF, LE, RE
  muscle_activation                   ankle muscle activations, series LF, RF, LE, RE
  joints                              hip, knee, ankle angles (rad), series <leg>_<joint>
  torso                               series height (m), pitch (rad)
  feedback                            closed loop only: the feedback term each cell receives
                                      (cpg.feedback), series LF, RF, LE, RE
  events/<leg>/touchdown|liftoff      1.0 at each event time
  metrics                             the gait metrics as a Markdown document (static)
  video                               the rendered video as an asset (optional)
Time series go out with ``send_columns`` (one call per entity; series that share the timeline
share an entity, since each entity costs rerun a fixed ~0.5 ms). The blueprint gives each
rollout a tab: the body (a side camera following the torso), the footfall lanes, the CPG
cells, the muscle activations and the joint angles over a window of about four strides that
follows the time cursor, the video when there is one, and the metrics. Written to a
temporary file and renamed.
"""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.io import atomic_path, signals_held, to_json

from cpgbiped.envs.gaits.gait_metrics import debounce, edges

CELLS = ("LF", "RF", "LE", "RE")
LEGS = ("left", "right")
FEET = ("left_foot", "right_foot")  # the model's foot bodies, in LEGS order
JOINTS = tuple(f"{leg}_{j}" for leg in LEGS for j in ("hip", "knee", "ankle"))
# Distinct colours (tab10): the cells, the feet (left blue, right orange, as the legs in the
# model), and the joints.
CELL_COLORS = ([31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40])
FOOT_COLORS = {"left": [31, 119, 180], "right": [255, 127, 14]}
JOINT_COLORS = ([31, 119, 180], [44, 160, 44], [148, 103, 189], [255, 127, 14], [214, 39, 40],
                [140, 86, 75])


def _columns(rec_stream, path: str, t: np.ndarray, x: np.ndarray):
    import rerun as rr

    rec_stream.send_columns(path, indexes=[rr.TimeColumn("sim_time", duration=t)],
                            columns=rr.Scalars.columns(scalars=np.asarray(x, dtype=float)))


def _rotate_many(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate the vector v (3,) by each unit quaternion (T, 4) = (w, x, y, z):
    v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)."""
    w, u = wxyz[:, :1], wxyz[:, 1:]
    uv = np.cross(u, v)
    return v + 2.0 * w * uv + 2.0 * np.cross(u, uv)


def _static_entities(xml_path) -> list:
    """The model's geometry as rerun archetypes, built once per file and version."""
    p = Path(xml_path)
    return _static_entities_of(str(p.resolve()), p.stat().st_mtime_ns)


@functools.lru_cache(maxsize=8)
def _static_entities_of(path: str, mtime_ns: int) -> list:
    from cpgbiped.envs.media import record_body
    from cpgbiped.envs.simulation.biped import load_model

    return record_body.static_entities(load_model(path))


def _soles(model, pose: np.ndarray) -> dict:
    """Each foot's sole centre in the world per tick (the centre of its first geom, at z = 0)."""
    out = {}
    for leg, foot in zip(LEGS, FEET):
        try:
            b = model.body(foot).id
        except KeyError:
            raise InputError(f"the model has no body {foot!r}: the recording needs the feet "
                             f"{', '.join(FEET)}") from None
        g = int(np.nonzero(model.geom_bodyid == b)[0][0])
        sole = pose[:, b, :3] + _rotate_many(pose[:, b, 3:], model.geom_pos[g])
        sole[:, 2] = 0.0
        out[leg] = sole
    return out


def log_rollout(rs, name: str, rec, metrics=None, video: str | Path | None = None) -> None:
    """Log one recording under ``/<name>`` to an open ``rr.RecordingStream``."""
    import rerun as rr

    from cpgbiped.envs.media import record_body
    from cpgbiped.envs.simulation.biped import load_model

    t = rec.t
    contact = np.stack([debounce(rec.contact[:, i], rec.dt) for i in range(2)], axis=1)
    torso = np.stack([rec.torso_height, rec.torso_pitch], axis=1)
    for path, names, x, colors in (
            ("contacts", LEGS, contact, [FOOT_COLORS[leg] for leg in LEGS]),
            ("force", LEGS, rec.force, [FOOT_COLORS[leg] for leg in LEGS]),
            ("cpg", CELLS, rec.cpg_v, CELL_COLORS),
            ("muscle_activation", CELLS, rec.muscle_activation, CELL_COLORS),
            ("joints", JOINTS, rec.joints, JOINT_COLORS),
            ("torso", ("height", "pitch"), torso, CELL_COLORS[:2])) + (
            (("feedback", CELLS, rec.feedback, CELL_COLORS),)
            if rec.feedback_gain > 0 and len(rec.feedback) == len(t) else ()) + (
            (("force_x", LEGS, rec.grf_x, [FOOT_COLORS[leg] for leg in LEGS]),)
            if len(rec.grf_x) == len(t) else ()) + (
            (("force_z", LEGS, rec.grf_z, [FOOT_COLORS[leg] for leg in LEGS]),)
            if len(rec.grf_z) == len(t) else ()):
        rs.log(f"/{name}/{path}", rr.SeriesLines(names=list(names), colors=list(colors)),
               static=True)
        _columns(rs, f"/{name}/{path}", t, x)
    for i, leg in enumerate(LEGS):
        td, lo = edges(t, contact[:, i])
        for event, times in (("touchdown", td), ("liftoff", lo)):
            if len(times):
                _columns(rs, f"/{name}/events/{leg}/{event}", times, np.ones(len(times)))
        # The footfall lane: the state at the start, then one change per edge.
        times = np.concatenate([t[:1], td, lo])
        states = np.array(["stance" if contact[0, i] else "swing"] + ["stance"] * len(td)
                          + ["swing"] * len(lo))
        order = np.argsort(times, kind="stable")
        rs.log(f"/{name}/feet/{leg}", rr.StateConfiguration(
            values=["stance", "swing"], labels=[f"{leg} stance", f"{leg} swing"],
            colors=[FOOT_COLORS[leg], [235, 235, 235]], visible=[True, False]), static=True)
        rs.send_columns(f"/{name}/feet/{leg}", indexes=[rr.TimeColumn("sim_time",
                                                                     duration=times[order])],
                        columns=rr.StateChange.columns(state=states[order]))
    if len(rec.body_pose):
        model = load_model(rec.xml_path)
        world = f"/{name}/world"
        pose = rec.body_pose  # one pose per control tick
        record_body.log_static(rs, world, _static_entities(rec.xml_path))
        record_body.log_poses(rs, world, model, t, pose)
        weight = float(model.body_mass.sum() * -model.opt.gravity[2])
        vertical = rec.grf_z if len(rec.grf_z) == len(t) else rec.force
        record_body.log_forces(rs, world, t, _soles(model, pose), contact, vertical, weight,
                               rec.grf_x if len(rec.grf_x) == len(t) else None)
        com = np.stack([rec.com_x, np.zeros_like(rec.com_x), rec.com_z], axis=1)
        record_body.log_com(rs, world, t, com)
    if metrics is not None:
        md = "```json\n" + to_json(metrics.as_dict() if hasattr(metrics, "as_dict") else metrics) + "\n```"
        rs.log(f"/{name}/metrics", rr.TextDocument(md, media_type="text/markdown"), static=True)
    if video is not None:
        asset = rr.AssetVideo(path=str(video))
        rs.log(f"/{name}/video", asset, static=True)
        ts = asset.read_frame_timestamps_nanos()
        rs.send_columns(f"/{name}/video", indexes=[rr.TimeColumn("sim_time", duration=ts * 1e-9)],
                        columns=rr.VideoFrameReference.columns_nanos(ts))


def window_s(metrics) -> float:
    """The time-series window: about four strides (3 s when the stride is unknown)."""
    stride = getattr(metrics, "stride_period_s", None)
    return float(4 * stride) if stride is not None and np.isfinite(stride) and stride > 0 else 3.0


def blueprint(rollouts: dict, videos: dict | None = None):
    """One tab per rollout (see the module docstring); rollouts maps name -> (rec, metrics)."""
    import rerun.blueprint as rrb

    tabs = []
    for n, (rec, metrics) in rollouts.items():
        w = window_s(metrics)
        follow = rrb.VisibleTimeRange("sim_time",
                                      start=rrb.TimeRangeBoundary.cursor_relative(seconds=-w),
                                      end=rrb.TimeRangeBoundary.cursor_relative(seconds=0.1 * w))
        # The viewer opens at the end of the timeline, and the web viewer does not move the eye
        # with tracking_entity until the user touches the view: aim at where the body ends.
        x_end = float(rec.com_x[-1]) if len(rec.com_x) and np.isfinite(rec.com_x[-1]) else 0.0
        body = rrb.Spatial3DView(
            origin=f"/{n}/world", name=f"{n}: body",
            eye_controls=rrb.EyeControls3D(position=[x_end, -3.2, 0.9],
                                           look_target=[x_end, 0.0, 0.6],
                                           eye_up=[0.0, 0.0, 1.0],
                                           tracking_entity=f"/{n}/world/body/torso"))
        left = [body] + ([rrb.Spatial2DView(origin=f"/{n}/video", name=f"{n}: video")]
                         if videos and n in videos else [])
        axis = rrb.TimeAxis(view_range=rrb.TimeRange(
            start=rrb.TimeRangeBoundary.cursor_relative(seconds=-w),
            end=rrb.TimeRangeBoundary.cursor_relative(seconds=0.1 * w)))
        right = [rrb.StateTimelineView(origin=f"/{n}/feet", name=f"{n}: footfalls",
                                       time_ranges=follow, time_view=axis),
                 rrb.TimeSeriesView(origin=f"/{n}/cpg", name=f"{n}: CPG cells",
                                    time_ranges=follow),
                 rrb.TimeSeriesView(origin=f"/{n}/muscle_activation", name=f"{n}: ankle muscles",
                                    time_ranges=follow)] + ([
                 rrb.TimeSeriesView(origin=f"/{n}/feedback", name=f"{n}: feedback into the CPG",
                                    time_ranges=follow)] if rec.feedback_gain > 0 else []) + [
                 rrb.TimeSeriesView(origin=f"/{n}/joints", name=f"{n}: joint angles",
                                    time_ranges=follow),
                 rrb.TextDocumentView(origin=f"/{n}/metrics", name=f"{n}: metrics")]
        tabs.append(rrb.Horizontal(rrb.Vertical(*left), rrb.Vertical(*right),
                                   column_shares=[3, 2], name=n))
    return rrb.Blueprint(rrb.Tabs(*tabs) if len(tabs) > 1 else tabs[0], collapse_panels=True)


def write_rrd(path: str | Path, rollouts: dict, videos: dict | None = None,
              marks: dict | None = None) -> Path:
    """One .rrd holding every rollout: ``rollouts`` maps name -> (Recording, metrics);
    ``marks``: name -> [(time s, label)], logged as events ``/<name>/events/<label>``."""
    import rerun as rr

    path = Path(path)
    if path.suffix != ".rrd":
        raise InputError(f"rerun recordings end in .rrd, got {str(path)!r}")
    with atomic_path(path, suffix=".rrd") as tmp:
        with signals_held():  # a stream interrupted inside its constructor has no native
            # handle, and its finaliser then prints a traceback as the interpreter exits
            rs = rr.RecordingStream("cpgbiped")
        rs.save(str(tmp))
        for name, (rec, metrics) in rollouts.items():
            log_rollout(rs, name, rec, metrics, (videos or {}).get(name))
            for tm, label in (marks or {}).get(name, []):
                _columns(rs, f"/{name}/events/{label.replace(' ', '_')}", np.array([tm]),
                         np.ones(1))
        rs.send_blueprint(blueprint(rollouts, videos))
        rs.flush()
        rs.disconnect()
    return path


def read_rrd(path: str | Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Scalar series of an .rrd: entity path -> (sim_time in s, values (T,) or (T, k) for an
    entity with k series), via rerun's reader."""
    from rerun.chunk import RrdReader

    out: dict[str, list] = {}
    for chunk in RrdReader(str(path)).store().stream():
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if "sim_time" not in names or "Scalars:scalars" not in names:
            continue
        col = batch.column("sim_time")
        t = np.asarray(col.cast("int64").to_numpy(zero_copy_only=False), dtype=float) * 1e-9
        v = np.array(batch.column("Scalars:scalars").to_pylist(), dtype=float)
        v = v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v
        out.setdefault(str(chunk.entity_path), []).append((t, v))
    res = {}
    for k, parts in out.items():
        t = np.concatenate([p[0] for p in parts])
        v = np.concatenate([p[1] for p in parts])
        o = np.argsort(t, kind="stable")
        res[k] = (t[o], v[o])
    return res


def read_component(path: str | Path, entity: str, component: str):
    """Rows of one component of an entity in an .rrd, via rerun's reader: (sim_time s (T,) or
    None for static data, list of T per-row values)."""
    from rerun.chunk import RrdReader

    parts = []
    for chunk in RrdReader(str(path)).store().stream():
        if str(chunk.entity_path) != entity:
            continue
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        rows = batch.column(component).to_pylist()
        if "sim_time" in batch.schema.names:
            t = np.asarray(batch.column("sim_time").cast("int64").to_numpy(zero_copy_only=False),
                           dtype=float) * 1e-9
        else:
            t = None
        parts.append((t, rows))
    if not parts:
        return None, []
    if parts[0][0] is None:
        return None, parts[0][1]
    t = np.concatenate([p[0] for p in parts])
    rows = sum((p[1] for p in parts), [])
    order = np.argsort(t, kind="stable")
    return t[order], [rows[i] for i in order]
