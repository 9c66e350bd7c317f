"""Arms from URDF files: :func:`from_urdf` (docs/model.md s.4).

Parser. The document and its link tree are read by :mod:`plants.urdf_reader` (``defusedxml``, no
DTD or entities, a regular file of at most ``MAX_URDF_BYTES``, a link tree without cycles, at most
:data:`MAX_CHAIN_JOINTS` joints between ``base_link`` and ``tip_link``); this module reads the
numbers on it, each finite and of magnitude at most :data:`MAX_URDF_NUMBER`. The subset the dynamics
needs (``<link>/<inertial>``, ``<joint>`` with ``<origin>``, ``<axis>``, ``<limit>``,
``<dynamics>``) is small and fully specified, so the element tree is walked here. The PyPI URDF parsers were checked and not used:
``urdf-parser-py`` (0.0.4, last release 2021, needs ``lxml`` and ``pyyaml``) is not kept on
PyPI; ``yourdfpy`` and ``urchin`` pull ``trimesh``, ``lxml`` (and ``networkx``, ``pycollada``)
for meshes this project never loads -- too heavy for the user install. Pinocchio
(``pin``, test extra) is the oracle the tests compare with.

What is read, from ``base_link`` down to ``tip_link``:

* the joint chain in order: ``revolute`` and ``continuous`` joints (an angle [rad], a
  continuous joint has no position limits) and ``prismatic`` joints ([m]); ``fixed`` joints
  are folded into the link transforms; any other type is an error;
* each moving link's mass properties from its ``<inertial>`` (origin and ``rpy`` in any frame),
  with every link rigidly attached to it folded in; links hanging beyond the tip (a hand and its
  fingers) are folded into the last moving link as a rigid payload, their joints held at zero;
* ``<limit effort>`` -> ``tau_max`` (absent: unlimited; present on a moving joint, it must be
  > 0), ``<limit lower upper>`` -> ``q_limits``; ``<dynamics damping>`` -> viscous friction [N m s/rad],
  ``<dynamics friction>`` -> Coulomb friction [N m] (smoothed, :data:`COULOMB_SMOOTHING`).
  URDF has no rotor-inertia field: pass ``motor_inertia`` to add reflected rotor inertias.

The node pose is the ``tip_link`` frame (times ``tool``), expressed in the world with the
``base_link`` frame at ``base``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from plants.arms.chain_table import COULOMB_SMOOTHING  # noqa: F401 (documented here)
from plants.arms._validation import MAX_MAGNITUDE, check_pose4
from plants.arms.chain_arm import ChainArm
from plants.arms.chain_joint import ChainJoint
from plants.errors import ParameterError
from plants.frames import rotation_zyx
from plants.urdf_reader import MAX_CHAIN_JOINTS, MAX_URDF_BYTES, kinematic_chain, link_tree, read_urdf

SUPPORTED_JOINTS = ("revolute", "continuous", "prismatic", "fixed")
__all__ = ["MAX_CHAIN_JOINTS", "MAX_URDF_BYTES", "MAX_URDF_NUMBER", "from_urdf", "pose_transform"]
#: Largest magnitude of a number in a URDF, SI units (:data:`plants.arms._validation.MAX_MAGNITUDE`).
MAX_URDF_NUMBER = MAX_MAGNITUDE


def from_urdf(path, base_link: str, tip_link: str, tool=None, *, base=None, name: str | None = None,
              gravity=(0.0, 0.0, -9.81), motor_inertia=None, q_rest=None) -> ChainArm:
    """The arm from ``base_link`` to ``tip_link`` of the URDF file ``path``.

    Args:
        path: URDF file.
        base_link: Link whose frame is the arm base (fixed in the world at ``base``).
        tip_link: Link whose frame is the node frame (with ``tool=None``).
        tool: Node frame in the ``tip_link`` frame: a 4x4 homogeneous transform [m], a pose of 6
            finite numbers (x, y, z [m], ZYX Euler angles psi, theta, phi [rad]), or ``None`` (identity).
        base: World pose of the ``base_link`` frame, 4x4 homogeneous transform [m] (default identity).
        name: Name used in error messages (default: the robot's name).
        gravity: Gravity acceleration in the world [m/s^2].
        motor_inertia: Reflected rotor inertias added to ``H``'s diagonal, (n,), or ``None``.
        q_rest: Rest posture for IK and the null-space posture task, or ``None``.

    Raises:
        ParameterError: (a ``ValueError``) naming ``urdf``, ``base_link``, ``tip_link``, ``tool``,
            ``base`` or the offending joint or link, with what is allowed: a file that is not a
            regular file of at most :data:`MAX_URDF_BYTES`, has a DTD or entities, whose links do
            not form a tree, whose chain has more than :data:`MAX_CHAIN_JOINTS` joints, or whose
            numbers are not finite, out of range (:data:`MAX_URDF_NUMBER`) or unphysical (an
            effort limit <= 0).
    """
    tool_T = None if tool is None else _check_tool(tool)
    if base is not None:
        try:
            base = check_pose4("base", base)
        except (TypeError, ValueError) as exc:
            allowed = exc.allowed if isinstance(exc, ParameterError) else "a 4x4 homogeneous transform [m]"
            raise ParameterError("base", f"an array of shape {np.shape(base)}", allowed) from None
    robot = read_urdf(path)
    links, joints = _index(robot, path)
    chain = kinematic_chain(links, joints, base_link, tip_link, path)
    for j in chain:
        if j["type"] not in SUPPORTED_JOINTS:
            raise ParameterError(f"joint '{j['name']}'.type", j["type"],
                                 f"a joint type in {list(SUPPORTED_JOINTS)} between {base_link} and {tip_link}")
    moving = [j for j in chain if j["type"] != "fixed"]
    if not moving:
        raise ParameterError("tip_link", tip_link, f"a link reached from '{base_link}' through at least one moving joint")
    children = {}
    for j in joints.values():
        children.setdefault(j["parent"], []).append(j)

    # Link frames: body k's frame is the child link of moving joint k.
    out = []
    T_fixed = np.eye(4)  # accumulated fixed transforms since the previous moving body frame
    chain_children = {j["child"] for j in moving}
    for j in chain:
        if j["type"] == "fixed":
            T_fixed = T_fixed @ j["origin"]
            continue
        child = j["child"]
        if links[child] is None:
            raise ParameterError(f"link '{child}'.inertial", None,
                                 "an <inertial> element (mass, origin, inertia) on every link moved by a joint")
        stop = chain_children - {child}
        mass, com, inertia = _composite(child, links, children, stop)
        lim = j["limit"]
        kind = "prismatic" if j["type"] == "prismatic" else "revolute"
        out.append(dict(
            joint=ChainJoint(name=j["name"], kind=kind, origin=T_fixed @ j["origin"], axis=j["axis"], mass=mass, com=com,
                             inertia=inertia, viscous=j["damping"], coulomb=j["friction"]),
            effort=lim["effort"],
            limits=(-np.inf, np.inf) if j["type"] == "continuous" else (lim["lower"], lim["upper"]),
        ))
        T_fixed = np.eye(4)
    tip_T = T_fixed  # tip_link in the last moving body frame (fixed joints only after it)
    n = len(out)
    joints_list = [o["joint"] for o in out]
    if motor_inertia is not None:
        try:
            motor = np.array(motor_inertia, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ParameterError("motor_inertia", motor_inertia, f"{n} finite rotor inertias >= 0 [kg m^2]") from None
        if motor.shape != (n,) or not np.all(np.isfinite(motor)) or np.any(motor < 0.0):
            raise ParameterError("motor_inertia", motor_inertia, f"{n} finite rotor inertias >= 0 [kg m^2]")
        joints_list = [replace(jt, motor_inertia=float(mi)) for jt, mi in zip(joints_list, motor)]
    tau_max = np.array([o["effort"] for o in out], dtype=float)
    q_limits = np.array([o["limits"] for o in out], dtype=float)
    tool_T = np.eye(4) if tool_T is None else tool_T
    return ChainArm(name=name or robot.get("name", "urdf"), joints=tuple(joints_list),
                    base=np.eye(4) if base is None else base, tool=tip_T @ tool_T, gravity=np.asarray(gravity, float),
                    tau_max=tau_max, q_limits=q_limits, q_rest=q_rest)


def pose_transform(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)) -> np.ndarray:
    """4x4 transform of a URDF ``<origin xyz rpy>``: ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(np.array([rpy[2], rpy[1], rpy[0]], dtype=float))
    T[:3, 3] = xyz
    return T


def _check_tool(tool) -> np.ndarray:
    """The tool frame as a 4x4 transform: a pose of 6 finite numbers (x, y, z [m], ZYX Euler
    psi, theta, phi [rad]) or a 4x4 homogeneous transform; ``ParameterError`` naming ``tool`` otherwise."""
    try:
        arr = np.array(tool, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("tool", repr(tool)[:80], "a pose of 6 finite numbers [m, rad] or a 4x4 homogeneous transform") from None
    if arr.shape == (6,):
        if not np.all(np.isfinite(arr)):
            raise ParameterError("tool", arr.tolist(), "a pose of 6 finite numbers [m, rad]")
        return pose_transform(arr[:3], arr[5:2:-1])  # ZYX Euler (psi, theta, phi) = rpy reversed
    if arr.shape == (4, 4):
        try:
            return check_pose4("tool", arr)
        except ParameterError as exc:
            raise ParameterError("tool", arr.tolist(), exc.allowed) from None
    raise ParameterError("tool", f"an array of shape {arr.shape}",
                         "a pose of 6 finite numbers [m, rad] or a 4x4 homogeneous transform")


# ---- parsing -----------------------------------------------------------------------------
def _floats(text, count, where):
    try:
        vals = [float(v) for v in text.split()]
    except (AttributeError, ValueError):
        raise ParameterError(where, text, f"{count} numbers") from None
    if len(vals) != count or not np.all(np.isfinite(vals)):
        raise ParameterError(where, text, f"{count} finite numbers")
    if max(abs(v) for v in vals) > MAX_URDF_NUMBER:
        raise ParameterError(where, text, f"{count} numbers of magnitude <= {MAX_URDF_NUMBER:g} (SI units)")
    return vals


def _origin(el, where):
    o = el.find("origin") if el is not None else None
    if o is None:
        return np.eye(4)
    xyz = _floats(o.get("xyz", "0 0 0"), 3, f"{where}.origin.xyz")
    rpy = _floats(o.get("rpy", "0 0 0"), 3, f"{where}.origin.rpy")
    return pose_transform(xyz, rpy)


def _attr(el, key, default, where):
    if el is None or el.get(key) is None:
        return default
    return _floats(el.get(key), 1, f"{where}.{key}")[0]


def _index(robot, path):
    """``(links, joints)`` of the link tree (:func:`plants.urdf_reader.link_tree`) with their numbers:
    ``links[name] = (mass, inertial origin, inertia)`` or ``None``; ``joints[name]`` with ``origin``,
    ``axis``, ``limit``, ``damping`` and ``friction`` added."""
    tree_links, joints = link_tree(robot, path)
    links = {}
    for name, el in tree_links.items():
        where = f"link '{name}'"
        inert = el.find("inertial")
        if inert is None:
            links[name] = None
            continue
        mass_el = inert.find("mass")
        I_el = inert.find("inertia")
        if mass_el is None or I_el is None:
            raise ParameterError(f"{where}.inertial", None, "<mass value> and <inertia ixx .. izz> in <inertial>")
        m = _attr(mass_el, "value", None, f"{where}.inertial.mass")
        if m is None or m < 0.0:
            raise ParameterError(f"{where}.inertial.mass", m, "a mass >= 0 [kg]")
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        v = {k: _attr(I_el, k, 0.0, f"{where}.inertial.inertia") for k in keys}
        I = np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]], [v["ixz"], v["iyz"], v["izz"]]])
        links[name] = (m, _origin(inert, f"{where}.inertial"), I)
    for name, joint in joints.items():
        el = joint["element"]
        where = f"joint '{name}'"
        axis_el = el.find("axis")
        axis = _floats(axis_el.get("xyz", "1 0 0"), 3, f"{where}.axis") if axis_el is not None else [1.0, 0.0, 0.0]
        lim = el.find("limit")
        jtype = joint["type"]
        effort = _attr(lim, "effort", np.inf, f"{where}.limit")
        if jtype != "fixed" and not effort > 0.0:  # a fixed joint's limits are never read
            raise ParameterError(f"{where}.limit.effort", effort, "an effort limit > 0 [N m or N] (omit it for unlimited)")
        lower = _attr(lim, "lower", 0.0, f"{where}.limit")
        upper = _attr(lim, "upper", 0.0, f"{where}.limit")
        if jtype in ("revolute", "prismatic") and not lower < upper:
            raise ParameterError(f"{where}.limit", [lower, upper], "lower < upper (a revolute or prismatic joint needs <limit lower upper>)")
        dyn = el.find("dynamics")
        joint.update(
            origin=_origin(el, where), axis=axis,
            limit=dict(effort=effort, lower=lower, upper=upper),
            damping=_attr(dyn, "damping", 0.0, f"{where}.dynamics"),
            friction=_attr(dyn, "friction", 0.0, f"{where}.dynamics"),
        )
    return links, joints


def _composite(root, links, children, stop):
    """Mass [kg], COM [m] and inertia about the COM [kg m^2] of ``root`` and every link hanging
    from it (joints held at zero), in ``root``'s frame; the subtrees of links in ``stop`` (the
    next moving bodies of the chain) are left out."""
    parts = []  # (mass, com in root frame, inertia about own com in root frame)
    todo = [(root, np.eye(4))]
    while todo:
        link, T = todo.pop()
        data = links[link]
        if data is not None:
            m, To, I = data
            Tc = T @ To
            R = Tc[:3, :3]
            parts.append((m, Tc[:3, 3], R @ I @ R.T))
        for j in children.get(link, []):
            if j["child"] in stop:
                continue
            # held at zero: only the joint origin
            todo.append((j["child"], T @ j["origin"]))
    M = sum(p[0] for p in parts)
    com = sum(p[0] * p[1] for p in parts) / M if M > 0.0 else np.zeros(3)
    I = np.zeros((3, 3))
    for m, c, Ic in parts:
        d = c - com
        I += Ic + m * (d @ d * np.eye(3) - np.outer(d, d))
    return M, com, I
