"""The MJCF model of a scene: its arms, contact nodes and object as MuJoCo bodies (docs/mujoco.md).

:func:`scene_mjcf` writes the XML of a scenario's plant (:func:`coopctrl.scenario.build.build_plant`), so that
MuJoCo's own dynamics run the arms and the object:

- **arms**: every spatial arm (a URDF arm, a named robot, a DH arm such as the Puma 560) is written from the
  joint table the project's arm kernels use (:meth:`chain_joints`: joint origin, axis, link mass, centre of
  mass and inertia, reflected motor inertia as ``armature``, viscous friction as ``damping``), one body per
  moving joint under a fixed base body at the arm's ``base``; planar arms (x-z plane) as hinges about
  ``-y`` (a positive angle turns +x towards +z, as the plant's ``theta``);
- **nodes**: the lumped body of each contact (``node_mass``, principal ``node_inertia``) fixed to the last link
  at the node frame (the arm's tool), a site ``arm{i}_node`` at its origin with a force and a torque sensor;
- **object**: its mass and principal inertia at its mass centre, on a free joint (planar scenes: slide x, slide
  z and a hinge about -y, so it stays in the plane);
- **grasps**: no MuJoCo element carries them. Each grasp element's wrench is computed by the plant's own
  element kernels and applied to the node bodies and the object every step
  (:class:`coopctrl.mujoco.plant.MujocoPlant`); the file draws each element as a zero-stiffness tendon.

Contacts are off (the elastic model has none); the geoms are visual only (no mass: ``inertiafromgeom``
off). A keyframe ``start`` holds the run's start (the loaded state of ``simulation.start``).

MuJoCo's compiler refuses an inertia that breaks the triangle inequality (the Puma 560's link 3, identified
data) or a body without mass: such a body is written with the nearest valid inertia and
:func:`mass_properties` lists the exact ones, which :class:`~coopctrl.mujoco.plant.MujocoPlant` writes into
the compiled model (a comment in the XML says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import numpy as np

#: Name of the object's body (node 0) and of its free joint.
OBJECT_BODY = "object"
OBJECT_JOINT = "object_free"
#: Names of the planar object's three joints (x, z, theta).
OBJECT_PLANAR_JOINTS = ("object_x", "object_z", "object_theta")
#: Smallest moment written for a massless or degenerate body [kg m^2] / mass [kg]; the exact values are
#: restored after compiling (:func:`mass_properties`).
_FLOOR = 1e-9


def link_body(arm: int, k: int) -> str:
    """Name of link ``k`` (0-based, the body moved by joint ``k``) of arm ``arm``."""
    return f"arm{arm}_link{k + 1}"


def joint_name(arm: int, k: int) -> str:
    """Name of joint ``k`` (0-based) of arm ``arm`` (its motor is named the same with ``_motor``)."""
    return f"arm{arm}_joint{k + 1}"


def node_body(arm: int) -> str:
    """Name of arm ``arm``'s contact node body (node ``arm + 1`` of the plant); its site is the same name."""
    return f"arm{arm}_node"


@dataclass(frozen=True)
class MassProperties:
    """The exact mass properties of one body, as the project's arm tables hold them.

    Attributes:
        body: MJCF body name.
        mass: Mass [kg].
        com: Centre of mass in the body frame [m], (3,).
        inertia: Inertia about the centre of mass in the body frame [kg m^2], (3, 3).
    """

    body: str
    mass: float
    com: tuple
    inertia: tuple


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in np.asarray(values, dtype=float).reshape(-1))


def quaternion(R) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of the rotation matrix ``R`` (3x3), ``w >= 0`` (Shepperd's method)."""
    R = np.asarray(R, dtype=float)
    t = np.trace(R)
    if t > 0.0:
        s = 2.0 * math.sqrt(t + 1.0)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


def planar_quaternion(theta: float) -> np.ndarray:
    """Quaternion of the planar angle ``theta`` [rad]: a turn about -y (+x towards +z)."""
    return np.array([math.cos(0.5 * theta), 0.0, -math.sin(0.5 * theta), 0.0])


def _frame(T) -> str:
    """``pos`` and ``quat`` attributes of a 4x4 transform."""
    T = np.asarray(T, dtype=float)
    return f'pos="{_fmt(T[:3, 3])}" quat="{_fmt(quaternion(T[:3, :3]))}"'


def _valid_inertia(inertia, mass: float) -> tuple[np.ndarray, bool]:
    """``(I, exact)``: ``inertia`` if MuJoCo's compiler accepts it, else the nearest inertia it accepts
    (principal moments raised to the triangle inequality and above :data:`_FLOOR`) and ``False``."""
    I = 0.5 * (np.asarray(inertia, dtype=float) + np.asarray(inertia, dtype=float).T)
    w, V = np.linalg.eigh(I)
    a, b, c = np.sort(w)
    exact = mass >= _FLOOR and a >= _FLOOR and a + b >= c * (1.0 + 1e-9)
    if exact:
        return I, True
    w = np.maximum(w, _FLOOR)
    big = int(np.argmax(w))
    others = np.sum(w) - w[big]
    if others < w[big]:  # raise the two smaller moments equally until they sum to the largest
        lift = 0.5 * (w[big] - others) * (1.0 + 1e-6)
        w = w + lift * (np.arange(3) != big)
    return V @ np.diag(w) @ V.T, False


def _inertial(com, mass, inertia) -> tuple[str, bool]:
    I, exact = _valid_inertia(inertia, mass)
    xml = (f'<inertial pos="{_fmt(com)}" mass="{max(float(mass), _FLOOR)!r}" '
           f'fullinertia="{_fmt([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>')
    return xml, exact and mass >= _FLOOR


def chain_joints(arm) -> tuple:
    """The moving joints of a spatial arm (a :class:`~plants.arms.ChainArm`'s own, or a
    :class:`~plants.arms.SerialArm`'s DH links as the same joints, exactly), base to tip."""
    joints = getattr(arm, "joints", None)
    return tuple(joints) if joints is not None else arm.chain_joints()


def _spatial_arm(i: int, arm, out: list, indent: str) -> tuple[str, int]:
    """Append arm ``i`` (a SerialArm or ChainArm) as nested bodies up to its opened node body; returns the
    node body's indentation and the number of bodies to close."""
    joints = chain_joints(arm)
    out.append(f'{indent}<body name="arm{i}_base" {_frame(arm.base)}>')
    out.append(f'{indent}  <geom type="sphere" size="0.05" rgba="0.5 0.5 0.5 1"/>')
    depth = indent + "  "
    for k, j in enumerate(joints):
        out.append(f'{depth}<body name="{link_body(i, k)}" {_frame(j.origin)}>')
        inner = depth + "  "
        inertial, exact = _inertial(j.com, j.mass, j.inertia)
        if not exact:
            out.append(f"{inner}<!-- exact inertia not accepted by MuJoCo's compiler: restored after compiling -->")
        out.append(f"{inner}{inertial}")
        kind = "hinge" if j.kind == "revolute" else "slide"
        out.append(f'{inner}<joint name="{joint_name(i, k)}" type="{kind}" axis="{_fmt(j.axis)}" '
                   f'armature="{j.motor_inertia!r}" damping="{j.viscous!r}"/>')
        # the link drawn from its joint to the next joint's origin (or to the node)
        nxt = joints[k + 1].origin[:3, 3] if k + 1 < len(joints) else np.asarray(arm.kernel_tool())[:3, 3]
        if np.linalg.norm(nxt) > 1e-6:
            out.append(f'{inner}<geom type="capsule" fromto="0 0 0 {_fmt(nxt)}" size="0.03" rgba="0.9 0.55 0.2 1"/>')
        else:
            out.append(f'{inner}<geom type="sphere" size="0.035" rgba="0.9 0.55 0.2 1"/>')
        depth = inner
    out.append(f'{depth}<body name="{node_body(i)}" {_frame(arm.kernel_tool())}>')
    return depth, len(joints) + 2  # the base, the links, the node


def _planar_arm(i: int, arm, out: list, indent: str) -> tuple[str, int]:
    """Append planar arm ``i`` as nested bodies in the x-z plane (as :func:`_spatial_arm`)."""
    bx, bz, bth = (float(v) for v in arm.base)
    out.append(f'{indent}<body name="arm{i}_base" pos="{bx!r} 0 {bz!r}" quat="{_fmt(planar_quaternion(bth))}">')
    out.append(f'{indent}  <geom type="sphere" size="0.04" rgba="0.5 0.5 0.5 1"/>')
    depth = indent + "  "
    previous = 0.0
    for k, link in enumerate(arm.links):
        out.append(f'{depth}<body name="{link_body(i, k)}" pos="{previous!r} 0 0">')
        inner = depth + "  "
        I = np.eye(3) * link.izz  # only the moment about y acts: the body turns about -y alone
        com = (link.rc[0], 0.0, link.rc[1])
        inertial, exact = _inertial(com, link.mass, I)
        if not exact:
            out.append(f"{inner}<!-- exact inertia not accepted by MuJoCo's compiler: restored after compiling -->")
        out.append(f"{inner}{inertial}")
        out.append(f'{inner}<joint name="{joint_name(i, k)}" type="hinge" axis="0 -1 0" '
                   f'armature="{link.motor_inertia!r}" damping="{link.viscous!r}"/>')
        if link.length > 1e-6:
            out.append(f'{inner}<geom type="capsule" fromto="0 0 0 {link.length!r} 0 0" size="0.025" rgba="0.9 0.55 0.2 1"/>')
        previous = link.length
        depth = inner
    dx, dz, dth = (float(v) for v in arm.tool)
    out.append(f'{depth}<body name="{node_body(i)}" pos="{previous + dx!r} 0 {dz!r}" quat="{_fmt(planar_quaternion(dth))}">')
    return depth, len(arm.links) + 2  # the base, the links, the node


def _node(i: int, node, spatial: bool, out: list, indent: str) -> None:
    """The contents of arm ``i``'s node body (opened by the arm): inertia, site, look."""
    I = node.inertia if spatial else (node.inertia[0],) * 3
    out.append(f'{indent}<inertial pos="0 0 0" mass="{node.mass!r}" diaginertia="{_fmt(I)}"/>')
    out.append(f'{indent}<site name="{node_body(i)}" size="0.012" rgba="0.2 0.4 1 1"/>')
    out.append(f'{indent}<geom type="sphere" size="0.025" rgba="0.2 0.4 1 1"/>')


def scene_mjcf(scenario, x_start=None, plant=None) -> str:
    """The MJCF XML of ``scenario`` (see the module docstring).

    Args:
        scenario: A :class:`~coopctrl.scenario.Scenario` whose arms are spatial (URDF, named, DH) or planar arms
            (``contact_point`` arms have no MuJoCo body: :class:`~coopctrl.errors.ScenarioError` naming the arm).
        x_start: The plant state of the keyframe ``start`` (``(q, Y_0, dq, dY_0)``), or ``None`` for none.
        plant: ``build_plant(scenario)`` when the caller has it, else ``None`` to build it here.
    """
    from coopctrl.mujoco.state_map import StateMap
    from coopctrl.scenario.build import build_plant
    from plants.cooperative import ContactPoint

    plant = build_plant(scenario) if plant is None else plant
    from coopctrl.errors import ScenarioError

    for i, arm in enumerate(plant.arms):
        if isinstance(arm, ContactPoint):
            raise ScenarioError(f"arms[{i}].model", "contact_point", "a robot, a DH table or a planar arm for MuJoCo "
                                "(a contact point has no body to simulate)", scenario.source)
    spatial = plant.space == "spatial"
    nodes = plant.elastic.nodes
    g = float(scenario.scene.gravity)
    sim = scenario.simulation
    timestep = mujoco_timestep(sim.control_period)
    out = [f"<mujoco model={quoteattr(str(scenario.name))}>",
           "  <!-- Written by coopctrl export-mjcf. The grasps (the scene's springs) are applied as forces by coopctrl's",
           "       MuJoCo plant every step; here they are drawn as tendons without stiffness. -->",
           '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
           f'  <option timestep="{timestep!r}" gravity="0 0 {-g!r}" integrator="Euler">',
           '    <flag contact="disable"/>', "  </option>",
           '  <visual><global offwidth="1280" offheight="960"/></visual>',
           "  <worldbody>",
           '    <light pos="0 -2 3" dir="0 1 -1.5" directional="true"/>',
           '    <geom name="floor" type="plane" size="2 2 0.01" rgba="0.85 0.85 0.85 1" contype="0" conaffinity="0"/>']
    for i, arm in enumerate(plant.arms):
        if spatial:
            depth, closes = _spatial_arm(i, arm, out, "    ")
        else:
            depth, closes = _planar_arm(i, arm, out, "    ")
        _node(i, nodes[i + 1], spatial, out, depth + "  ")
        for c in range(closes, 0, -1):
            out.append("    " + "  " * (c - 1) + "</body>")
    obj = nodes[0]
    pose = np.asarray(scenario.object.pose, dtype=float)
    if spatial:
        from plants.frames import rotation_zyx

        out.append(f'    <body name="{OBJECT_BODY}" pos="{_fmt(pose[:3])}" quat="{_fmt(quaternion(rotation_zyx(pose[3:])))}">')
        out.append(f'      <freejoint name="{OBJECT_JOINT}"/>')
        I = obj.inertia
    else:
        out.append(f'    <body name="{OBJECT_BODY}">')
        jx, jz, jt = OBJECT_PLANAR_JOINTS
        out.append(f'      <joint name="{jx}" type="slide" axis="1 0 0" ref="0"/>')
        out.append(f'      <joint name="{jz}" type="slide" axis="0 0 1" ref="0"/>')
        out.append(f'      <joint name="{jt}" type="hinge" axis="0 -1 0" ref="0"/>')
        I = (obj.inertia[0],) * 3
    out.append(f'      <inertial pos="0 0 0" mass="{obj.mass!r}" diaginertia="{_fmt(I)}"/>')
    out.append(f'      <site name="{OBJECT_BODY}" size="0.012" rgba="1 0.2 0.2 1"/>')
    out.append('      <geom type="box" size="0.1 0.06 0.04" rgba="0.3 0.7 0.3 0.8"/>')
    out.append("    </body>")
    out.append("  </worldbody>")
    # the grasp elements, drawn (no stiffness, no damping: the plant applies their wrenches)
    out.append("  <tendon>")
    for e, ic in enumerate(plant.elastic.interconnections):
        a, b = (OBJECT_BODY if n == 0 else node_body(n - 1) for n in ic.pair)
        out.append(f'    <spatial name="spring{e}" width="0.004" rgba="0.1 0.1 0.1 1"><site site="{a}"/><site site="{b}"/></spatial>')
    out.append("  </tendon>")
    out.append("  <actuator>")
    for i, arm in enumerate(plant.arms):
        for k in range(arm.dof):
            out.append(f'    <motor name="{joint_name(i, k)}_motor" joint="{joint_name(i, k)}" gear="1"/>')
    out.append("  </actuator>")
    out.append("  <sensor>")
    for i in range(len(plant.arms)):
        out.append(f'    <force name="{node_body(i)}_force" site="{node_body(i)}"/>')
        out.append(f'    <torque name="{node_body(i)}_torque" site="{node_body(i)}"/>')
    out.append("  </sensor>")
    if x_start is not None:
        qpos, qvel = StateMap.from_plant(plant).qpos_qvel(np.asarray(x_start, dtype=float))
        out.append("  <keyframe>")
        out.append(f'    <key name="start" qpos="{_fmt(qpos)}" qvel="{_fmt(qvel)}"/>')
        out.append("  </keyframe>")
    out.append("</mujoco>")
    return "\n".join(out) + "\n"


def mass_properties(scenario, plant=None) -> list[MassProperties]:
    """The exact mass properties of every arm link of ``scenario`` (those :func:`scene_mjcf` may have had to
    write inexactly), by body name."""
    from coopctrl.scenario.build import build_plant

    plant = build_plant(scenario) if plant is None else plant
    props: list = []
    for i, arm in enumerate(plant.arms):
        if plant.space == "spatial":
            for k, j in enumerate(chain_joints(arm)):
                props.append(MassProperties(link_body(i, k), float(j.mass), tuple(map(float, j.com)),
                                            tuple(map(tuple, np.asarray(j.inertia, dtype=float)))))
        else:
            for k, link in enumerate(arm.links):
                props.append(MassProperties(link_body(i, k), float(link.mass), (link.rc[0], 0.0, link.rc[1]),
                                            tuple(map(tuple, np.eye(3) * link.izz))))
    return props


#: MuJoCo's step is the control period divided into this many steps at least, and at most
#: :data:`MAX_TIMESTEP` [s] long: the grasp wrenches are held over one MuJoCo step (explicit in them).
MIN_STEPS_PER_PERIOD = 4
MAX_TIMESTEP = 2.5e-4


def steps_per_period(control_period: float) -> int:
    """MuJoCo steps per control period of ``control_period`` [s]."""
    return max(MIN_STEPS_PER_PERIOD, int(math.ceil(control_period / MAX_TIMESTEP - 1e-9)))


def mujoco_timestep(control_period: float) -> float:
    """MuJoCo's ``timestep`` [s] for the control period ``control_period`` [s]."""
    return control_period / steps_per_period(control_period)
