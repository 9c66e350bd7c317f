"""The geometry of a run, frame by frame, for the 3-D replay.

:func:`replay_data` turns a :class:`~coopctrl.results.SimulationResult` and the scenario it ran
into a JSON-ready dict: per frame the arms' link polylines (from their joint frames:
:func:`plants.arms.joint_frames.arm_polyline` for DH, Puma and planar arms,
:func:`coopctrl.replay.chain_frames.chain_polyline` for URDF arms, whose body frames are also
stored per frame to pose their ``<visual>`` shapes, :mod:`coopctrl.replay.urdf_visuals`), the
contact nodes, the object's position and
rotation, each interconnection's two attachment points (it is drawn as a spring between them, so
it stretches) and the contact forces (world frame, on the object, at the contact nodes). Planar
scenes are mapped to the world x-z plane (y = 0). Positions in [m], forces in [N].
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.replay.chain_frames import chain_body_frames, chain_polyline
from coopctrl.replay.urdf_visuals import ArmVisuals, urdf_arm_visuals
from plants.arms.chain_arm import ChainArm
from plants.arms.joint_frames import arm_polyline
from plants.elastic._layout import PLANAR_MATRIX, SPATIAL_MATRIX
from plants.frames import rotation_zyx

#: At most this many frames are stored in the page (the run is subsampled evenly).
MAX_FRAMES = 400

#: Frame spacings preferred by the subsampling, times a power of ten [s]: frames then fall on
#: round times (``#t=1.0`` opens on the sample at 1 s, not at 0.994 s).
ROUND_STEPS = (1.0, 2.0, 2.5, 5.0)


def frame_step(t: np.ndarray, count: int, max_frames: int = MAX_FRAMES) -> int:
    """Samples between stored frames: the smallest ``s >= ceil(count / max_frames)`` whose
    spacing ``s dt`` is a round time (1, 2, 2.5 or 5 times a power of ten, to 1e-9 relative),
    searched up to twice the smallest; else the smallest. ``dt`` is the first sample spacing,
    used only when the samples are evenly spaced."""
    smallest = max(1, math.ceil(count / max_frames)) if count else 1
    if count < 3:
        return smallest
    dt = float(t[1] - t[0])
    spacing = np.diff(np.asarray(t[:count], float))
    if not dt > 0.0 or np.abs(spacing - dt).max() > 1e-9 * max(1.0, abs(float(t[count - 1]))):
        return smallest
    for s in range(smallest, 2 * smallest + 1):
        h = s * dt
        decade = 10.0 ** math.floor(math.log10(h))
        if any(abs(h - r * decade) <= 1e-9 * h for r in (*ROUND_STEPS, 10.0)):
            return s
    return smallest


def _rotation(pose: np.ndarray, space: str) -> np.ndarray:
    if space == "spatial":
        return rotation_zyx(pose[3:6])
    c, s = math.cos(pose[2]), math.sin(pose[2])  # theta from +x towards +z: about -y
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def _position(pose: np.ndarray, space: str) -> np.ndarray:
    return np.asarray(pose[:3], float) if space == "spatial" else np.array([pose[0], 0.0, pose[1]])


def _force3(wrench: np.ndarray, space: str) -> np.ndarray:
    return np.asarray(wrench[:3], float) if space == "spatial" else np.array([wrench[0], 0.0, wrench[1]])


#: Drawn length of an unstretched interconnection, as a fraction of its grasp offset: the spring
#: is drawn from a point this far inside the grasp point to the node, so that it is visible
#: (the true deformations are millimetres) and stretches by the true amount.
SPRING_DRAWN_FRACTION = 0.4


def _grasp3(g: np.ndarray, space: str) -> np.ndarray:
    return np.array(g[:3], float) if space == "spatial" else np.array([g[0], 0.0, g[1]])


def _box_size(grasps: np.ndarray, space: str) -> list[float]:
    """Object box [m]: the springs' inner ends lie on its faces; every side at least 35 % of
    the longest (and 4 cm)."""
    inner = 1.0 - SPRING_DRAWN_FRACTION
    if space == "spatial":
        extent = np.abs(grasps[:, :3]).max(axis=0) * 2.0 * inner
    else:
        g = np.abs(grasps[:, :2]).max(axis=0) * 2.0 * inner
        extent = np.array([g[0], 0.0, g[1]])
    extent = np.maximum(extent, max(0.04, 0.35 * float(extent.max())))
    if space == "planar":
        extent[1] = 0.06  # a slab across the plane, so that it reads as a body
    return [float(v) for v in extent]


#: Points drawn along a beam element.
BEAM_POINTS = 17


def beam_exaggeration(largest_m: float, size_m: float) -> float:
    """The factor (a power of ten, 1 to 1e4) the beams' bending is drawn with: their largest
    deviation from the chord ``largest_m`` [m] drawn as about 10 % of the grasp span ``size_m``."""
    if not largest_m > 0.0:
        return 1.0
    return float(10.0 ** min(4, max(0, round(math.log10(0.1 * size_m / largest_m)))))


def _span(grasps: np.ndarray) -> float:
    """The largest distance of a grasp from the object's centre [m] (1 m without grasps)."""
    g = np.asarray(grasps, float)
    return float(np.max(np.linalg.norm(g[:, :3] if g.shape[1] == 6 else g[:, :2], axis=1))) if len(g) else 1.0


def _beam_tangents(plant, e: int, Y: np.ndarray, space: str) -> tuple[np.ndarray, np.ndarray]:
    """The unit tangents (3-D, world) of beam ``e``'s axis at its two ends: the element's x axis
    as each end node carries it (the packed ``M``, ``N`` of plants.elastic._layout)."""
    el = plant.elastic
    i, j = int(el.edge_index[e, 0]), int(el.edge_index[e, 1])
    row = el.edge_params[e]
    if space == "spatial":
        return (_rotation(Y[i], space) @ row[SPATIAL_MATRIX["frame_in_i"]].reshape(3, 3)[:, 0],
                _rotation(Y[j], space) @ row[SPATIAL_MATRIX["frame_in_j"]].reshape(3, 3)[:, 0])
    alpha, beta = row[PLANAR_MATRIX.col("frame_angle")], row[PLANAR_MATRIX.col("rest_angle")]
    ta, tb = Y[i, 2] + alpha, Y[j, 2] + alpha - beta
    return np.array([math.cos(ta), 0.0, math.sin(ta)]), np.array([math.cos(tb), 0.0, math.sin(tb)])


def _beam_deviation(pa: np.ndarray, pb: np.ndarray, ta: np.ndarray, tb: np.ndarray) -> np.ndarray:
    """(BEAM_POINTS, 3) deviation [m] from the chord of the cubic Hermite curve from ``pa`` to
    ``pb`` with end tangents ``L ta`` and ``L tb`` (``L`` the chord's length)."""
    s = np.linspace(0.0, 1.0, BEAM_POINTS)[:, None]
    L = float(np.linalg.norm(pb - pa))
    curve = ((2 * s**3 - 3 * s**2 + 1) * pa + (s**3 - 2 * s**2 + s) * L * ta
             + (-2 * s**3 + 3 * s**2) * pb + (s**3 - s**2) * L * tb)
    return curve - (pa + s * (pb - pa))


def _r(values, digits: int = 5) -> list:
    return np.round(np.asarray(values, float), digits).reshape(-1).tolist()


def replay_data(result, scenario, max_frames: int = MAX_FRAMES) -> dict:
    """The dict embedded in ``replay.html`` (see the module docstring).

    Per arm: ``arm_labels`` (``"arms[k] MODEL (ROLE)"``, with the file of a ``"urdf"`` arm),
    ``arm_links`` (the URDF link of each body of a URDF arm: ``base_link`` and the child of each
    moving joint, so ``dof + 1`` names; empty for other arms), ``arm_visuals`` (each shape in its
    body frame: ``body``, ``link``, ``shape``, ``size`` [m], ``pose`` 12 numbers: position [m] and
    rotation row by row; meshes with ``vertices`` [m] and ``triangles``); ``bar_arms`` lists the
    arms drawn as one bar (no joint frames known) and ``notes`` what was left out of the drawing.
    Per frame: ``arms`` the polylines through the joint frames (a URDF arm: base, each body
    origin, node: one segment per body) and ``bodies`` the 12-number pose of each body.
    Frames are every :func:`frame_step` samples (and the last finite one)."""
    from coopctrl.scenario import build

    plant = scenario.plant()
    space = scenario.space
    grasps = build.true_grasps(scenario)
    m = len(scenario.arms)
    n_samples = int(result.t.shape[0])
    finite = np.isfinite(result.x).all(axis=1) if n_samples else np.zeros(0, bool)
    last = int(np.nonzero(finite)[0][-1]) if finite.any() else -1
    count = last + 1
    step = frame_step(result.t, count, max_frames)
    picks = list(range(0, count, step))
    if count and picks[-1] != last:
        picks.append(last)  # always show the last finite state (where a failed run stopped)

    p = plant.p
    shapes = [_arm_shapes(scenario, i, arm) for i, arm in enumerate(plant.arms)]
    frames = []
    beams = []  # (frame, spring, end a, end b, deviation from the chord) of each beam in each frame
    for k in picks:
        x = result.x[k]
        Y = plant.node_poses(x).reshape(m + 1, p)
        obj_pos, obj_R = _position(Y[0], space), _rotation(Y[0], space)
        nodes = [_position(Y[i], space) for i in range(1, m + 1)]
        arms, bodies = [], []
        for i, arm in enumerate(plant.arms):
            q = x[plant.q_slice(i)]
            bodies.append([] if shapes[i] is None else _r(_pose12(chain_body_frames(arm, q))))
            pts = chain_polyline(arm, q) if isinstance(arm, ChainArm) else arm_polyline(arm, q)
            if pts is None and scenario.arms[i].model != "contact_point":
                # an arm without joint frames here: one segment from its base to its node
                pts = np.array([_position(np.asarray(scenario.arms[i].base, float), space), nodes[i]])
            arms.append(_r(pts) if pts is not None else [])  # a contact point is its node alone
        springs, stretch = [], []
        for e, sp in enumerate(scenario.springs):
            if sp.element == "beam":  # drawn bent: a cubic through its end nodes, along their frames
                pa, pb = _position(Y[sp.pair[0]], space), _position(Y[sp.pair[1]], space)
                deviation = _beam_deviation(pa, pb, *_beam_tangents(plant, e, Y, space))
                beams.append((len(frames), e, pa, pb, deviation))
                springs.append([])
                stretch.append(float(np.max(np.linalg.norm(deviation, axis=1))))  # its bending, drawn true
                continue
            ends, true_ends = [], []
            for node, other in (sp.pair, sp.pair[::-1]):
                if node == 0:
                    offset = _grasp3(grasps[other - 1], space)
                    true_ends.append(obj_pos + obj_R @ offset)
                    ends.append(obj_pos + obj_R @ (offset * (1.0 - SPRING_DRAWN_FRACTION)))
                else:
                    true_ends.append(nodes[node - 1])
                    ends.append(nodes[node - 1])
            springs.append(_r(np.concatenate(ends)))
            stretch.append(float(np.linalg.norm(true_ends[1] - true_ends[0])) if 0 in sp.pair else 0.0)
        F = result.F_measured[k] if np.isfinite(result.F_measured[k]).all() else np.zeros((m, p))
        frames.append({
            "t": round(float(result.t[k]), 6),
            "arms": arms,
            "bodies": bodies,
            "nodes": _r(np.array(nodes)),
            "object": _r(np.concatenate([obj_pos, obj_R.reshape(-1)]), 6),
            "springs": springs,
            "deformation_mm": round(max(stretch) * 1e3, 4) if stretch else 0.0,
            "forces": _r(np.array([_force3(F[i], space) for i in range(m)]), 3),
        })
    largest = max((float(np.max(np.linalg.norm(b[4], axis=1))) for b in beams), default=0.0)
    exaggeration = beam_exaggeration(largest, _span(grasps))
    for k, e, pa, pb, deviation in beams:
        s = np.linspace(0.0, 1.0, BEAM_POINTS)[:, None]
        frames[k]["springs"][e] = _r(pa + s * (pb - pa) + exaggeration * deviation)
    fmax = max((float(np.abs(np.array(f["forces"])).max()) for f in frames if f["forces"]), default=0.0)
    pts = np.array([v for f in frames for a in f["arms"] for v in np.reshape(a, (-1, 3))] +
                   [v for f in frames for v in np.reshape(f["nodes"], (-1, 3))]) if frames else np.zeros((0, 3))
    bounds = (pts.min(axis=0).tolist(), pts.max(axis=0).tolist()) if len(pts) else ([-1, -1, 0], [1, 1, 1])
    span = float(np.max(np.subtract(bounds[1], bounds[0]))) if len(pts) else 1.0
    fail_t = None
    if result.status != "ok":
        fail_t = float(result.t[last]) if last >= 0 else 0.0
    return {
        "scenario": result.scenario,
        "status": result.status,
        "reason": result.reason,
        "space": space,
        "integrator": result.integrator,
        "duration_s": float(result.duration_s),
        "fail_t": fail_t,
        "box": _box_size(grasps, space) if not beams else [0.08 * _span(grasps)] * 3,  # a beam is the object itself
        "bounds": bounds,
        "force_scale_m_per_N": (0.2 * span / fmax) if fmax > 0 else 0.0,
        "force_max_N": fmax,
        "arm_models": [a.model for a in scenario.arms],
        "arm_labels": [_label(scenario, i) for i in range(m)],
        "arm_links": [[] if s is None else list(s.links) for s in shapes],
        "arm_visuals": [[] if s is None else [_visual_json(v) for v in s.visuals] for s in shapes],
        "bar_arms": [i for i, a in enumerate(plant.arms) if _drawn_as_bar(scenario, i, a)],
        "notes": [f"arms[{i}]: {n}" for i, s in enumerate(shapes) if s is not None for n in s.notes],
        "leader": int(scenario.leader),
        "springs_pairs": [list(s.pair) for s in scenario.springs],
        "beam_exaggeration": exaggeration if beams else None,
        "frames": frames,
    }


def _urdf_of(scenario, k: int):
    """``(path, base_link, tip_link)`` of a URDF arm (named robot or ``model = "urdf"``), or ``None``."""
    from plants.arms.named_robots import NAMED_ROBOTS, urdf_path

    cfg = scenario.arms[k]
    if cfg.model in NAMED_ROBOTS:
        _, base_link, tip_link = NAMED_ROBOTS[cfg.model]
        return urdf_path(cfg.model), base_link, tip_link
    if cfg.model == "urdf":
        return cfg.urdf_path(scenario.source), cfg.base_link, cfg.tip_link
    return None


def _arm_shapes(scenario, k: int, arm):
    """The bodies and visuals of a chain (URDF) arm, or ``None`` for any other arm."""
    if not isinstance(arm, ChainArm):
        return None
    urdf = _urdf_of(scenario, k)
    if urdf is None:
        return None
    shapes = urdf_arm_visuals(*urdf)
    if len(shapes.links) != arm.dof + 1:  # not the chain the arm was built from: no visuals
        names = tuple(f"link {j}" for j in range(arm.dof + 1))
        return ArmVisuals(links=names, notes=shapes.notes or ("its URDF's chain no longer matches the arm: no visuals",))
    return shapes


def _drawn_as_bar(scenario, k: int, arm) -> bool:
    return (scenario.arms[k].model != "contact_point" and not isinstance(arm, ChainArm)
            and arm_polyline(arm, np.zeros(arm.dof)) is None)


def _label(scenario, k: int) -> str:
    cfg = scenario.arms[k]
    what = f"{cfg.model} {cfg.urdf}" if cfg.model == "urdf" else cfg.model
    return f"arms[{k}] {what} ({cfg.role})"


def _pose12(frames: np.ndarray) -> np.ndarray:
    """Per 4x4 frame its 12 numbers: position [m], then the rotation row by row."""
    return np.concatenate([frames[:, :3, 3], frames[:, :3, :3].reshape(-1, 9)], axis=1)


def _visual_json(v) -> dict:
    out = {"body": v.body, "link": v.link, "shape": v.shape, "size": [float(s) for s in v.size],
           "pose": _r(_pose12(v.transform[None]), 6), "dark": bool(v.dark)}
    if v.shape == "mesh":
        out["vertices"] = _r(v.vertices, 4)
        out["triangles"] = [int(i) for i in v.triangles.reshape(-1)]
    return out
