"""The body in a rerun recording: geometry read from the MuJoCo model, poses over time.

Entities, under ``/<name>/world`` (world coordinates, metres; z up):
  body/<body>                 Transform3D per control tick on ``sim_time`` (the body's world
                              pose, from the rollout's recorded xpos/xquat)
  body/<body>/<geom>          static geometry in the body frame: capsules, boxes, spheres,
                              ellipsoids, cylinders and meshes with the model's sizes, poses and
                              colours (``geom_rgba``, or the material's)
  floor                       static: the model's planes as thin boxes
  grf/<foot>                  an arrow per tick while that foot is in contact: the ground
                              reaction force (normal, and horizontal when the recording has
                              it), 0.5 m per body weight, from under the foot
  com                         the centre of mass, a point per tick
Nothing here is specific to the biped except the names of the feet, which the caller passes.
Poses go out with one ``send_columns`` per body; the geometry once, as static data.
"""
from __future__ import annotations

import mujoco
import numpy as np

_GEOM = mujoco.mjtGeom


def _xyzw(wxyz: np.ndarray) -> np.ndarray:
    q = np.asarray(wxyz, dtype=float)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def _rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(wxyz, dtype=float))
    return m.reshape(3, 3) @ v


def _rgba(model: mujoco.MjModel, g: int) -> np.ndarray:
    mat = model.geom_matid[g]
    rgba = model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[g]
    return (np.clip(rgba, 0, 1) * 255).astype(np.uint8)


def geom_archetype(model: mujoco.MjModel, g: int):
    """The rerun archetype of geom g in its body's frame, or None (unsupported or invisible)."""
    import rerun as rr

    t, size = model.geom_type[g], model.geom_size[g]
    pos, quat, color = model.geom_pos[g], model.geom_quat[g], _rgba(model, g)
    if color[3] == 0:
        return None
    q = rr.Quaternion(xyzw=_xyzw(quat))
    if t == _GEOM.mjGEOM_CAPSULE:  # rerun: end caps at z = 0 and z = length
        start = pos + _rotate(quat, np.array([0.0, 0.0, -size[1]]))
        return rr.Capsules3D(lengths=[2 * size[1]], radii=[size[0]], translations=[start],
                             quaternions=[q], colors=[color], fill_mode="solid")
    if t == _GEOM.mjGEOM_BOX:
        return rr.Boxes3D(half_sizes=[size], centers=[pos], quaternions=[q], colors=[color],
                          fill_mode="solid")
    if t in (_GEOM.mjGEOM_SPHERE, _GEOM.mjGEOM_ELLIPSOID):
        half = [size[0]] * 3 if t == _GEOM.mjGEOM_SPHERE else size
        return rr.Ellipsoids3D(half_sizes=[half], centers=[pos], quaternions=[q], colors=[color],
                               fill_mode="solid")
    if t == _GEOM.mjGEOM_CYLINDER:
        return rr.Cylinders3D(lengths=[2 * size[1]], radii=[size[0]], centers=[pos],
                              quaternions=[q], colors=[color], fill_mode="solid")
    if t == _GEOM.mjGEOM_MESH:
        m = model.geom_dataid[g]
        v0, nv = model.mesh_vertadr[m], model.mesh_vertnum[m]
        f0, nf = model.mesh_faceadr[m], model.mesh_facenum[m]
        verts = model.mesh_vert[v0:v0 + nv]
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, quat)
        verts = verts @ R.reshape(3, 3).T + pos
        return rr.Mesh3D(vertex_positions=verts, triangle_indices=model.mesh_face[f0:f0 + nf],
                         albedo_factor=color)
    return None


def _name(model, kind, i: int, prefix: str) -> str:
    n = getattr(model, kind)(i).name
    return n if n else f"{prefix}{i}"


def static_entities(model: mujoco.MjModel) -> list:
    """(path below the root, archetype) of every body geom (in its body's frame) and the
    floor; build once per model and log with :func:`log_static`."""
    import rerun as rr

    out = []
    for g in range(model.ngeom):
        b = model.geom_bodyid[g]
        if b == 0:
            if model.geom_type[g] == _GEOM.mjGEOM_PLANE:
                half = model.geom_size[g].copy()
                half[:2] = np.where(half[:2] > 0, half[:2], 50.0)
                out.append((f"floor/{_name(model, 'geom', g, 'geom')}",
                            rr.Boxes3D(half_sizes=[[half[0], half[1], 0.002]],
                                       centers=[model.geom_pos[g] - [0, 0, 0.002]],
                                       colors=[[90, 100, 110, 255]], fill_mode="solid")))
            continue
        arch = geom_archetype(model, g)
        if arch is not None:
            out.append((f"body/{_name(model, 'body', b, 'body')}/{_name(model, 'geom', g, 'geom')}",
                        arch))
    return out


def log_static(rs, root: str, entities: list) -> None:
    """The geometry of :func:`static_entities`, once, as static data."""
    for path, arch in entities:
        rs.log(f"{root}/{path}", arch, static=True)


def log_poses(rs, root: str, model: mujoco.MjModel, t: np.ndarray, pose: np.ndarray) -> None:
    """Each body's world pose per tick: pose (T, nbody, 7) = xpos (3), xquat (w x y z)."""
    import rerun as rr

    index = [rr.TimeColumn("sim_time", duration=t)]
    xyzw = np.ascontiguousarray(pose[:, :, [4, 5, 6, 3]])  # rerun's quaternion order, all at once
    for b in range(1, model.nbody):
        rs.send_columns(f"{root}/body/{_name(model, 'body', b, 'body')}", indexes=index,
                        columns=rr.Transform3D.columns(translation=pose[:, b, :3],
                                                       quaternion=xyzw[:, b]))


def log_forces(rs, root: str, t: np.ndarray, feet: dict, contact: np.ndarray,
               force: np.ndarray, weight_n: float, force_x: np.ndarray | None = None) -> None:
    """Ground reaction force arrows while each foot is in contact, 0.5 m per body weight: the
    vertical force ``force`` (T, k; N, > 0 up; the recorder passes each tick's mean over its
    physics steps) up and, when given, the horizontal force ``force_x`` (T, k; N, > 0
    forwards) along x, so that an arrow leaning back is a foot pushing the body back.
    feet maps a name to its (T, 3) sole position; contact (T, k) bool, in the same order."""
    import rerun as rr

    for i, (foot, sole) in enumerate(feet.items()):
        on = contact[:, i]
        origins = sole[on]
        vectors = np.zeros_like(origins)
        vectors[:, 2] = 0.5 * force[on, i] / weight_n
        if force_x is not None:
            vectors[:, 0] = 0.5 * force_x[on, i] / weight_n
        cols = rr.Arrows3D.columns(origins=origins, vectors=vectors).partition(on.astype(np.int32))
        rs.send_columns(f"{root}/grf/{foot}", indexes=[rr.TimeColumn("sim_time", duration=t)],
                        columns=cols)
        rs.log(f"{root}/grf/{foot}", rr.Arrows3D.from_fields(colors=[[230, 60, 60]],
                                                            radii=[0.01]), static=True)


def log_com(rs, root: str, t: np.ndarray, com: np.ndarray) -> None:
    import rerun as rr

    rs.send_columns(f"{root}/com", indexes=[rr.TimeColumn("sim_time", duration=t)],
                    columns=rr.Points3D.columns(positions=com))
    rs.log(f"{root}/com", rr.Points3D.from_fields(colors=[[20, 20, 20]], radii=[0.03]),
           static=True)
