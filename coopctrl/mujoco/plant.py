"""The MuJoCo plant of a scene: MuJoCo's arms and object, the scene's grasp elements applied as wrenches.

:class:`MujocoPlant` compiles :func:`coopctrl.mujoco.mjcf.scene_mjcf` and advances it with the arm torques held
over a control period. Each MuJoCo step, before :func:`mujoco.mj_step`:

1. the plant state ``x = (q, Y_0, dq, dY_0)`` is read from ``qpos``, ``qvel`` (:class:`StateMap`);
2. the nodes ``Y = (Y_0, Phi_1(q_1), ...)`` and their rates ``dY`` come from the plant's own kinematics
   kernel (:meth:`CooperativePlant.arm_terms`), the same as the loop's;
3. each grasp element's generalized force ``F = dPi/dY + dD/d(dY)`` (120, 121, 111) comes from the elastic
   system's own element kernels (:meth:`ElasticSystem.elastic_force` and ``damping_force``: ``elastic_edges``,
   ``damping_edges``, or the linear elements of an immobile unloaded state); node ``k`` receives ``Q_k = -F_k``;
4. ``Q_k`` becomes a world wrench at node ``k``'s mass centre: spatial ``f = Q[0:3]``,
   ``n = R(A_k) L(A_k)^-T Q[3:6]`` (``omega_body = L dA``, so ``Q_A = L^T n_body``); planar
   ``f = (Q_x, 0, Q_z)``, ``n = (0, -Q_theta, 0)`` (theta turns about -y); it is written into
   ``xfrc_applied`` of the node's body (the object for node 0), whose mass centre is the node;
5. the joints get ``qfrc_applied = tau - coulomb tanh(dq / COULOMB_SMOOTHING)`` (the arm kernels' smoothed
   Coulomb friction; viscous friction and motor inertia are MuJoCo's ``damping`` and ``armature``).

MuJoCo then integrates the arms and the object (semi-implicit Euler, its ``timestep`` a fraction of the
control period: :func:`coopctrl.mujoco.mjcf.steps_per_period`). The grasp wrench is held over one MuJoCo
step, the torques over the period.
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.mujoco import mjcf
from coopctrl.mujoco.requirement import import_mujoco
from coopctrl.mujoco.state_map import StateMap
from plants.arms.chain_table import COULOMB_SMOOTHING


def _charted(plant) -> bool:
    return bool(getattr(plant, "_charted", False)) or bool(getattr(plant.elastic, "charted", False))


class MujocoPlant:
    """A scene's model in MuJoCo, stepped with held joint torques.

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario`.
        plant: ``build_plant(scenario)`` when the caller has it (the loop's plant), else ``None``.

    Attributes:
        model, data: MuJoCo's ``MjModel`` and ``MjData``.
        state_map: The :class:`StateMap` of the plant state.
        timestep: MuJoCo's step [s].
    """

    def __init__(self, scenario, plant=None):
        mujoco = import_mujoco()
        from coopctrl.scenario.build import build_plant

        self._mujoco = mujoco
        self.plant = plant = build_plant(scenario) if plant is None else plant
        if _charted(plant):  # the nodes in charts of their own (not the loop's world chart, which stepper guards)
            raise ValueError("the mujoco plant needs the plant's nodes in the book's world angles, not in charts")
        self.xml = mjcf.scene_mjcf(scenario, plant=plant)
        self.model = model = mujoco.MjModel.from_xml_string(self.xml)
        restore_mass_properties(model, mjcf.mass_properties(scenario, plant))
        self.data = mujoco.MjData(model)
        self.state_map = sm = StateMap.from_plant(plant)
        if model.nq != sm.nq_mujoco or model.nv != sm.nv_mujoco:
            raise AssertionError(f"MJCF of {scenario.name!r}: nq = {model.nq}, nv = {model.nv}, expected "
                                 f"{sm.nq_mujoco}, {sm.nv_mujoco}")
        self.timestep = float(model.opt.timestep)
        self.spatial = sm.spatial
        self.p = sm.p
        m = plant.arm_count
        name = mujoco.mjtObj.mjOBJ_BODY
        self.node_bodies = np.array([mujoco.mj_name2id(model, name, mjcf.OBJECT_BODY)]
                                    + [mujoco.mj_name2id(model, name, mjcf.node_body(i)) for i in range(m)])
        coulomb = []
        for arm in plant.arms:
            joints = mjcf.chain_joints(arm) if sm.spatial else ()
            coulomb.extend([j.coulomb for j in joints] if joints else [0.0] * arm.dof)
        self.coulomb = np.array(coulomb, dtype=float)
        self.x = None  # the plant state of MuJoCo's state (None until set)

    # ---------------------------------------------------------------- state
    def set_state(self, x) -> None:
        """Set MuJoCo's state to the plant state ``x`` (velocities included) and run its forward kinematics."""
        qpos, qvel = self.state_map.qpos_qvel(x)
        self.data.qpos[:] = qpos
        self.data.qvel[:] = qvel
        self.data.qacc_warmstart[:] = 0.0
        self._mujoco.mj_forward(self.model, self.data)
        self.x = np.array(x, dtype=float)

    def read_state(self) -> np.ndarray:
        """The plant state of MuJoCo's ``qpos``, ``qvel`` (the object's angles on the branch of the last state)."""
        return self.state_map.state(self.data.qpos, self.data.qvel, reference=self.x)

    def readings(self) -> dict:
        """What a robot's sensors would give at MuJoCo's current state, by name (the fields of
        ``coopctrl.Measurement``): ``q``, ``dq`` per arm (n_i,) [rad, rad/s]; ``wrench`` (m, p) per grasp, the
        wrench its elements apply to the object (world frame, force at the contact point [N], couple [N m]: what
        a wrist force-torque sensor reads, as :meth:`CooperativePlant.contact_wrenches`); ``object_pose`` ``Y_0``
        (p,) [m, rad] and ``object_twist`` ``dY_0`` (p,) [m/s, rad/s] (Euler-angle rates)."""
        x = self.read_state()
        plant, sm = self.plant, self.state_map
        n, nz = sm.n_q, sm.nz
        q, dq = [], []
        for i in range(plant.arm_count):
            sl = plant.q_slice(i)
            q.append(x[sl].copy())
            dq.append(x[nz + sl.start:nz + sl.stop].copy())
        return {"q": tuple(q), "dq": tuple(dq), "wrench": plant.contact_wrenches(x),
                "object_pose": x[n:nz].copy(), "object_twist": x[nz + n:].copy()}

    # ---------------------------------------------------------------- grasp wrenches
    def node_forces(self, x) -> np.ndarray:
        """The generalized forces ``Q`` (m + 1, p) the grasp elements apply to the nodes at state ``x``
        [N, N m/rad]: ``-(dPi/dY + dD/d(dY))`` (120, 121, 111) by the elastic system's own element kernels
        (:meth:`ElasticSystem.elastic_force`, :meth:`ElasticSystem.damping_force`; the linear elements of an
        immobile unloaded state included)."""
        Y, dY = self.plant.arm_terms(x)[:2]
        el = self.plant.elastic
        F = el.elastic_force(Y) + el.damping_force(Y, dY)
        self._Y = Y
        return -F.reshape(Y.shape)

    def node_wrenches(self, x) -> np.ndarray:
        """The world wrenches ``(f, n)`` (m + 1, 6) [N, N m] at the nodes' mass centres of :meth:`node_forces`."""
        Q = self.node_forces(x)
        Y = self._Y
        out = np.zeros((Q.shape[0], 6))
        if self.spatial:
            out[:, :3] = Q[:, :3]
            out[:, 3:] = world_couples(Y[:, 3:6], Q[:, 3:6])
        else:
            out[:, 0] = Q[:, 0]
            out[:, 2] = Q[:, 1]
            out[:, 4] = -Q[:, 2]
        return out

    def apply(self, tau) -> None:
        """Write the grasp wrenches of MuJoCo's current state into ``xfrc_applied`` and the joint torques
        ``tau`` [N m] (less the arms' smoothed Coulomb friction) into ``qfrc_applied``."""
        x = self.read_state()
        self.x = x
        d = self.data
        d.xfrc_applied[self.node_bodies] = self.node_wrenches(x)
        n = self.state_map.n_q
        d.qfrc_applied[:n] = tau
        if self.coulomb.any():
            d.qfrc_applied[:n] -= self.coulomb * np.tanh(d.qvel[:n] / COULOMB_SMOOTHING)

    def advance(self, tau, duration: float) -> np.ndarray:
        """Advance ``duration`` [s] (a whole number of MuJoCo steps) with the joint torques ``tau`` held; return
        the plant state at the end."""
        steps = int(round(duration / self.timestep))
        step = self._mujoco.mj_step
        tau = np.asarray(tau, dtype=float)
        for _ in range(steps):
            self.apply(tau)
            step(self.model, self.data)
        self.x = self.read_state()
        return self.x


def world_couples(A, Q_A) -> np.ndarray:
    r"""World couples ``n = R(A) L(A)^-T Q_A`` [N m] of the generalized forces ``Q_A`` [N m] on the ZYX angles ``A``
    [rad], row by row ((k, 3) each): ``omega_body = L dA`` makes ``Q_A = L^T n_body`` (105).

    .. math::
        L^{-T} Q = (Q_2,\; s_\phi Q_0 / c_\theta + c_\phi Q_1 + s_\phi t_\theta Q_2,\;
                    c_\phi Q_0 / c_\theta - s_\phi Q_1 + c_\phi t_\theta Q_2)
    """
    out = np.empty((len(A), 3))
    cos, sin = math.cos, math.sin
    for k in range(len(A)):  # scalar arithmetic: a few nodes, where numpy's per-call cost would dominate
        psi, th, ph = A[k, 0], A[k, 1], A[k, 2]
        q0, q1, q2 = Q_A[k, 0], Q_A[k, 1], Q_A[k, 2]
        cps, sps, cth, sth, cph, sph = cos(psi), sin(psi), cos(th), sin(th), cos(ph), sin(ph)
        b0 = q2
        b1 = (sph * q0 + sth * sph * q2) / cth + cph * q1
        b2 = (cph * q0 + sth * cph * q2) / cth - sph * q1
        y1 = cph * b1 - sph * b2  # R = Rz(psi) Ry(theta) Rx(phi) applied to b
        z1 = sph * b1 + cph * b2
        x2 = cth * b0 + sth * z1
        out[k, 0] = cps * x2 - sps * y1
        out[k, 1] = sps * x2 + cps * y1
        out[k, 2] = -sth * b0 + cth * z1
    return out


def restore_mass_properties(model, props) -> None:
    """Write the exact mass properties ``props`` (:func:`coopctrl.mujoco.mjcf.mass_properties`) into the compiled
    ``model``: mass, centre of mass, principal moments and their axes (``body_iquat``)."""
    mujoco = import_mujoco()
    for prop in props:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, prop.body)
        I = np.asarray(prop.inertia, dtype=float)
        w, V = np.linalg.eigh(0.5 * (I + I.T))
        if np.linalg.det(V) < 0.0:
            V[:, 0] = -V[:, 0]
        model.body_mass[b] = prop.mass
        model.body_ipos[b] = prop.com
        model.body_inertia[b] = np.maximum(w, 0.0)
        model.body_iquat[b] = mjcf.quaternion(V)
    mujoco.mj_setConst(model, mujoco.MjData(model))
