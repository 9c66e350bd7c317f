"""The cooperative system: m arms rigidly holding the contact nodes of the elastic system (docs/model.md s.5)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Sequence

import numpy as np

from plants import _core
from plants.cooperative.contact_point import ContactPoint
from plants.cooperative.control_terms import ControlTerms
from plants.cooperative.plant_args import ARM_CONTACT_POINT, ARM_SERIAL, ARM_SERIAL_OWN_CHART, PlantArgs
from plants.elastic import ElasticSystem
from plants import charts as _charts
from plants.elastic._layout import (
    CHART_OWN,
    CHART_STORED,
    CHART_WORLD,
    NODE_CHART,
    NODE_CHART_KIND,
    NODE_WIDTH_CHARTED,
    PLANAR_SPRING,
    SPATIAL_SPRING,
    STATUS_COINCIDENT_NODES,
    STATUS_EULER_SINGULAR,
    STATUS_OK,
    STATUS_SINGULAR_MASS,
)
from plants._validation import sized_vector
from plants.errors import EulerSingularityError, ParameterError, SingularJacobianError
from plants.frames import body_rate_map_inv, euler_zyx_from_rotation, rotation_zyx

#: How a serial arm's node takes its angles: the book's world ZYX Euler angles, or its own chart.
ARM_CHARTS = ("world", "own")

_POSE_NAMES = {"spatial": ("x", "y", "z", "psi", "theta", "phi"), "planar": ("x", "z", "theta")}
_INPUT_NAMES = {"spatial": ("fx", "fy", "fz", "Qpsi", "Qtheta", "Qphi"), "planar": ("fx", "fz", "n")}


#: The compiled core's functions of a planar and a spatial plant (plants/core: bind_cooperative*.cpp), on the
#: plant's kernel arrays by name (:class:`PlantArgs`).
_CORE = {
    "spatial": SimpleNamespace(rhs=_core.spatial_rhs, node_state=_core.spatial_node_state,
                               control_terms=_core.spatial_control_terms, arm_potentials=_core.spatial_arm_potentials,
                               interconnection_wrenches=_core.spatial_interconnection_wrenches),
    "planar": SimpleNamespace(rhs=_core.planar_rhs, node_state=_core.planar_node_state,
                              control_terms=_core.planar_control_terms, arm_potentials=_core.planar_arm_potentials,
                              interconnection_wrenches=_core.planar_interconnection_wrenches),
}


class CooperativePlant:
    """``Gamma(z) z'' + phi(z, z') = (tau, 0)`` with ``z = (q, Y_0)`` (177, 183).

    .. math::
        \\Gamma = \\mathrm{blockdiag}(N(q), W_0(Y_0)), \\quad N = H + J^T W_c J, \\quad
        \\phi = \\big(h + J^T (W_c \\dot J \\dot q + w_c(Y, \\dot Y)),\\; w_0(Y, \\dot Y)\\big)

    with ``Y_c = Phi(q)`` and ``Y_c' = J q'`` (169-172): each arm is rigidly attached to its
    contact node (4.9). The first-order state is ``x = (z, z')``; the input ``tau`` stacks the
    joint torques [N m] of every arm (or the generalized node forces of a
    :class:`~plants.cooperative.ContactPoint`). A plant is a stateless function of (t, x, tau):
    it owns parameters only.

    Args:
        elastic: The elastic system of nodes 0..m (node 0 = object).
        arms: One arm per contact node, in node order: ``SerialArm`` (spatial),
            ``SerialArm`` or ``ChainArm`` (spatial), ``PlanarArm`` (planar) or ``ContactPoint``
            (no arm dynamics).
        leader: Index (0-based, into ``arms``) of the leader arm ``v`` (4.10); the others are
            the followers ``s``.
        arm_charts: Spatial: ``"world"`` (default) gives every serial arm's node its book
            coordinates (world ZYX Euler angles of the tip, singular at pitch +-90 deg);
            ``"own"`` takes them in the node's own chart at each evaluation (``C = R_tip(q)``,
            ``A = 0``, docs/model.md s.2): the arms never meet the singularity, and the plant's
            node poses, Jacobians and control terms are in those charts (:meth:`book_coordinates`
            gives the book's). ``"own"`` needs an elastic system whose equations depend on no
            chart (:meth:`ElasticSystem.chart_dependence`). The object and contact points take
            their stored charts from ``elastic.charts``.
    """

    def __init__(self, elastic: ElasticSystem, arms: Sequence, leader: int = 0, arm_charts: str = "world"):
        self.elastic = elastic
        self.space = elastic.space
        self.p = p = elastic.p
        self.arms = tuple(arms)
        m = len(self.arms)
        if m != elastic.node_count - 1:
            raise ParameterError("arms", m, f"one arm per contact node: {elastic.node_count - 1}")
        if not 0 <= int(leader) < m:
            raise ParameterError("leader", leader, f"an arm index in 0..{m - 1}")
        self.leader = int(leader)
        self.followers = tuple(i for i in range(m) if i != self.leader)
        kinds, dofs, tables, bases, tools = [], [], [], [], []
        for i, arm in enumerate(self.arms):
            if getattr(arm, "space", None) != self.space:
                raise ParameterError(f"arms[{i}]", type(arm).__name__, f"a {self.space} arm or ContactPoint")
            dofs.append(arm.dof)
            if isinstance(arm, ContactPoint):
                kinds.append(ARM_CONTACT_POINT)
            else:
                kinds.append(ARM_SERIAL)
                # spatial arms: the general-chain joint table (n, 32) and the node frame in the
                # last link frame (plants.arms.chain_table); planar arms: their link table
                tables.append(np.asarray(arm.kernel_table() if self.space == "spatial" else arm.dh_array(), dtype=float))
            if self.space == "spatial":
                bases.append(np.eye(4) if isinstance(arm, ContactPoint) else np.asarray(arm.base, dtype=float))
                tools.append(np.eye(4) if isinstance(arm, ContactPoint) else np.asarray(arm.kernel_tool(), dtype=float))
            else:
                bases.append(np.zeros(3) if isinstance(arm, ContactPoint) else np.asarray(arm.base, dtype=float))
                tools.append(np.zeros(3) if isinstance(arm, ContactPoint) else np.asarray(arm.tool, dtype=float))
        width = 32 if self.space == "spatial" else 7
        self._arm_kind = np.array(kinds, dtype=np.int64)
        self._arm_dof = np.array(dofs, dtype=np.int64)
        self._q_off = np.concatenate([[0], np.cumsum(dofs)[:-1]]).astype(np.int64)
        serial_dofs = [d for d, k in zip(dofs, kinds) if k == ARM_SERIAL]
        offs = np.concatenate([[0], np.cumsum(serial_dofs)]).astype(np.int64) if serial_dofs else np.zeros(1, np.int64)
        dh_off = np.zeros(m, dtype=np.int64)
        s = 0
        for i, k in enumerate(kinds):
            if k == ARM_SERIAL:
                dh_off[i] = offs[s]
                s += 1
        self._dh_off = dh_off
        self._dh_all = np.ascontiguousarray(np.vstack(tables)) if tables else np.zeros((1, width))
        self._bases = np.ascontiguousarray(np.array(bases, dtype=float))
        self._tools = np.ascontiguousarray(np.array(tools, dtype=float))
        self._gravity = np.ascontiguousarray(elastic.gravity, dtype=float)
        self._node_params = np.ascontiguousarray(elastic.node_params)
        self._edge_index = np.ascontiguousarray(elastic.edge_index)
        self._edge_params = np.ascontiguousarray(elastic.edge_params)
        self._Y_ref = np.ascontiguousarray(elastic.Y_ref)
        self._immobile = bool(elastic.immobile)
        self._compiled = _CORE[self.space]
        self.arm_dofs = tuple(int(d) for d in dofs)
        self.nz = int(sum(dofs)) + p
        self._set_charts(arm_charts)
        self._pack_args()

    # ------------------------------------------------------------------ charts
    def _set_charts(self, arm_charts: str) -> None:
        """Validate ``arm_charts`` against the elastic system's charts; pack the node rows and arm kinds."""
        if arm_charts not in ARM_CHARTS:
            raise ParameterError("arm_charts", arm_charts, f"one of {ARM_CHARTS}")
        if arm_charts == "own":
            if self.space != "spatial":
                raise ParameterError("arm_charts", arm_charts, "'world' for a planar plant (charts are for spatial rotations)")
            why = self.elastic.chart_dependence()
            if why is not None:
                raise ParameterError("arm_charts", arm_charts, f"'world' (the book's world angles): {why}")
        self.arm_charts = arm_charts
        serial = [not isinstance(a, ContactPoint) for a in self.arms]
        if self.space == "spatial":
            for i, is_serial in enumerate(serial):
                if is_serial and not _charts.is_identity(self.elastic.charts[i + 1]):
                    raise ParameterError(f"elastic.charts[{i + 1}]", self.elastic.charts[i + 1].tolist(),
                                         "the identity for an arm's node (an arm's node takes its chart from arm_charts)")
        kinds = self._arm_kind.copy()
        for i, is_serial in enumerate(serial):
            if is_serial and self.space == "spatial":
                kinds[i] = ARM_SERIAL_OWN_CHART if arm_charts == "own" else ARM_SERIAL
        self._arm_kind = kinds
        if self.space == "spatial" and (self.elastic.charted or arm_charts == "own"):
            rows = np.zeros((self.node_count, NODE_WIDTH_CHARTED))
            rows[:, :4] = self.elastic.node_params
            for k in range(self.node_count):
                own = k > 0 and serial[k - 1] and arm_charts == "own"
                C = self.elastic.charts[k]
                rows[k, NODE_CHART_KIND] = CHART_OWN if own else (CHART_WORLD if _charts.is_identity(C) else CHART_STORED)
                rows[k, NODE_CHART:NODE_CHART + 9] = C.reshape(-1)
            self._node_params = np.ascontiguousarray(rows)
        else:
            self._node_params = np.ascontiguousarray(self.elastic.node_params)
        self._charted = self._node_params.shape[1] > NODE_CHART_KIND

    def _pack_args(self) -> None:
        self._plant_args = PlantArgs(self._arm_kind, self._arm_dof, self._q_off, self._dh_all, self._dh_off,
                                     self._bases, self._tools, self._gravity, self._node_params, self._edge_index,
                                     self._edge_params, self._Y_ref, self._immobile)

    @property
    def plant_args(self) -> PlantArgs:
        """The kernel arrays by name (:class:`~plants.cooperative.plant_args.PlantArgs`): what a compiled
        caller passes the packed kernels (``rhs_into_packed``, ``control_terms_packed``); the plant's own
        arrays, not copies."""
        return self._plant_args

    @property
    def charted(self) -> bool:
        """True when some node's angles are taken in a chart other than the book's world chart."""
        return self._charted

    def with_charts(self, charts=None, arm_charts: str | None = None) -> "CooperativePlant":
        """This plant with other stored charts for the object and contact points (``charts``: (m + 1, 3, 3),
        see :class:`ElasticSystem`; ``None`` keeps them) and/or another ``arm_charts``. A shallow copy:
        the packed arm and edge parameters are shared."""
        import copy

        out = copy.copy(self)
        if charts is not None:
            out.elastic = self.elastic.with_charts(charts)
        out._set_charts(self.arm_charts if arm_charts is None else arm_charts)
        out._pack_args()
        return out

    def with_own_world(self) -> "CooperativePlant":
        """This plant with arm bases and gravity of its own, which the caller may turn in place: the
        arrays ``plant_args.bases`` ((m, 4, 4) [m]) and ``plant_args.gravity`` ((3,) [m/s^2]) of the
        copy are its :meth:`rhs`'s. A loop that runs in a world frame turned by ``C`` keeps them as the
        world's turned by ``C^T`` (coopctrl's world chart), so its kernel and a Python integrator's
        :meth:`rhs` see one turned world. A shallow copy: the other packed parameters are shared."""
        import copy

        out = copy.copy(self)
        out._bases = self._bases.copy()
        out._gravity = self._gravity.copy()
        out._pack_args()
        return out

    def _free_nodes(self):
        """``(node, slice of its 6 coordinates in z)`` of the object and every contact point."""
        out = [(0, slice(self.nz - 6, self.nz))]
        for i, arm in enumerate(self.arms):
            if isinstance(arm, ContactPoint):
                out.append((i + 1, self.q_slice(i)))
        return out

    def recentred(self, x):
        """``(plant, x')``: the same physical state with the object's (and every contact point's) chart moved
        onto its current rotation, ``C' = C R(A)``, ``A' = 0``; positions, rates and body angular velocity
        unchanged (:func:`plants.charts.recentre`). Call it between integration steps when the object's
        ``|cos theta|`` gets small; the plant stays a stateless function of ``(t, x, tau)``."""
        if self.space != "spatial":
            raise ParameterError("space", self.space, "'spatial' (charts are for spatial rotations)")
        x = self._state(x).copy()
        nz = self.nz
        C = self.elastic.charts.copy()
        for k, sl in self._free_nodes():
            a = slice(sl.start + 3, sl.stop)
            da = slice(nz + sl.start + 3, nz + sl.stop)
            C[k], x[a], x[da] = _charts.recentre(C[k], x[a], x[da])
        return self.with_charts(C), x

    def chart_cos(self, x) -> float:
        """The smallest ``|cos theta|`` of the object's and contact points' angles in their stored charts
        at ``x`` (arms' nodes in their own charts are always at ``A = 0``): below ~0.7 (45 deg from the
        chart) an integrator calls :meth:`recentred` between steps."""
        x = self._state(x)
        if self.space != "spatial":
            return 1.0
        return float(min(abs(np.cos(x[sl][4])) for _, sl in self._free_nodes()))

    def _frames_state(self, x):
        """``(Y, dY, J, Jdq, frames)`` at ``x`` with every node's frames in its chart (one call of the core)."""
        d = self._compiled.node_state(x, self._plant_args)  # spatial: the frames too
        if d["status"][0]:
            self.check_status(d["status"], x)
        return d["Y"], d["dY"], d["J"], d["Jdq"], d["frames"]

    def book_coordinates(self, x, dx):
        """``(Y, dY, ddY)``: every node's pose, rates and accelerations in the book's coordinates (world ZYX
        Euler angles, (4.9) ``Y_c = Phi(q)``), flat ``((m + 1) p,)`` each, from the state ``x`` and its rate
        ``dx = rhs(t, x, tau)``. Whatever the charts, the same physical motion gives the same book
        coordinates. Raises :class:`~plants.errors.EulerSingularityError` where they do not exist (a node
        at pitch +-90 deg)."""
        x, dx = self._state(x), self._state(dx, "dx")
        nz, p = self.nz, self.p
        ddz = dx[nz:]
        if self.space != "spatial":
            Y, dY, H, h, J, Jdq = self._node_state(x)
            frames = None
        else:
            Y, dY, J, Jdq, frames = self._frames_state(x)
        Y, dY = Y.copy(), dY.copy()
        ddY = np.empty_like(Y)
        ddY[0] = ddz[nz - p:]
        for i, arm in enumerate(self.arms):
            sl = self.q_slice(i)
            if isinstance(arm, ContactPoint):
                ddY[i + 1] = ddz[sl]
            else:
                n = self.arm_dofs[i]
                ddY[i + 1] = J[i, :, :n] @ ddz[sl] + Jdq[i]
        if self.space == "spatial":
            for k in range(self.node_count):
                if k > 0 and self._arm_kind[k - 1] == ARM_SERIAL_OWN_CHART:
                    C = frames[k, 5]
                elif k > 0 and self._arm_kind[k - 1] == ARM_SERIAL:
                    C = np.eye(3)
                else:
                    C = self.elastic.charts[k]
                where = "object" if k == 0 else f"contact node {k} (arms[{k - 1}])"
                Y[k, 3:6], dY[k, 3:6], ddY[k, 3:6] = _charts.world_coordinates(C, Y[k, 3:6], dY[k, 3:6], ddY[k, 3:6], where)
        return Y.reshape(-1), dY.reshape(-1), ddY.reshape(-1)

    # ------------------------------------------------------------------ sizes
    @property
    def node_count(self) -> int:
        """Number of nodes m + 1 (object and contacts)."""
        return self.elastic.node_count

    @property
    def arm_count(self) -> int:
        return len(self.arms)

    @property
    def state_size(self) -> int:
        """Size of ``x = (z, z')``: ``2 (sum n_i + p)``."""
        return 2 * self.nz

    @property
    def input_size(self) -> int:
        """Size of ``tau``: ``sum n_i``."""
        return self.nz - self.p

    @property
    def unloaded_state(self) -> str:
        return self.elastic.unloaded_state

    def q_slice(self, i: int) -> slice:
        """Slice of arm i's coordinates in ``z`` (and of its inputs in ``tau``)."""
        return slice(int(self._q_off[i]), int(self._q_off[i] + self._arm_dof[i]))

    def size_report(self) -> dict:
        """What this model carries: sizes and the elements it pays for."""
        return {
            "space": self.space,
            "unloaded_state": self.unloaded_state,
            "arms": self.arm_count,
            "arm_models": [type(a).__name__ for a in self.arms],
            "dof_per_arm": list(self.arm_dofs),
            "node_count": self.node_count,
            "interconnections": int(self._edge_index.shape[0]),
            "torsion_springs": int(np.count_nonzero(
                self._edge_params[:, (SPATIAL_SPRING if self.space == "spatial" else PLANAR_SPRING)["torsion"]])),
            "state_size": self.state_size,
            "input_size": self.input_size,
        }

    # ------------------------------------------------------------------ dynamics
    def check_status(self, status, x=None):
        """Raise the plant's exception for a kernel status ``(code, node)`` (nothing when it is ok), naming the
        node and, given the state ``x`` it was met at, its angles."""
        code, where = int(status[0]), int(status[1])
        if code == STATUS_OK:
            return
        if code == STATUS_EULER_SINGULAR:
            node = "object" if where == 0 else f"contact node {where} (arms[{where - 1}])"
            theta = float("nan")
            if x is not None:
                if where == 0:
                    theta = float(x[self.nz - 6 + 4])
                elif isinstance(self.arms[where - 1], ContactPoint):
                    theta = float(x[self.q_slice(where - 1)][4])
                else:
                    T = self.arms[where - 1].tip_transform(x[self.q_slice(where - 1)])[0]
                    theta = float(euler_zyx_from_rotation(np.ascontiguousarray(T[:3, :3]))[1])
            raise EulerSingularityError(node, theta, float(np.cos(theta)) if theta == theta else 0.0)
        if code == STATUS_COINCIDENT_NODES:
            raise ParameterError("Y", "coincident nodes",
                                 "distinct positions for the nodes of a central spring with positive rest length")
        if code == STATUS_SINGULAR_MASS:
            raise SingularJacobianError(f"mass matrix N of arm {where - 1}", float("inf"))
        raise RuntimeError(f"unknown kernel status {code}")

    def rhs(self, t: float, x: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """``dx/dt = (z', Gamma^-1 ((tau, 0) - phi))`` at state ``x`` and input ``tau``.

        Raises :class:`~plants.errors.EulerSingularityError` at ``cos(theta) = 0`` of any node;
        ``TypeError``/:class:`~plants.errors.ParameterError` for an ``x`` or ``tau`` of another size.
        """
        nz = self.nz
        if not (type(x) is np.ndarray and x.shape == (2 * nz,) and type(tau) is np.ndarray  # noqa: E721 - exact
                and tau.shape == (nz - self.p,)):  # the sizes only, cheaply (integrators call this per step)
            x, tau = self._state(x), self._input(tau)
        dx = np.empty(2 * nz)
        status = self._compiled.rhs(x, tau, self._plant_args, dx)  # plants/core: one call, the kernel's bits
        if status[0]:
            self.check_status(status, x)
        return dx

    def _state(self, x, name: str = "x") -> np.ndarray:
        """``x`` as a state (``state_size`` floats), checked for its size only (cheap; see
        :func:`plants._validation.sized_vector`)."""
        return sized_vector(name, x, self.state_size, "a state (z, dz/dt) of the plant")

    def _input(self, tau, name: str = "tau") -> np.ndarray:
        """``tau`` as the input (``input_size`` joint torques [N m]), checked for its size only."""
        return sized_vector(name, tau, self.input_size, "the joint torques [N m]")

    def _node_state(self, x):
        """``(Y, dY, H, h, J, Jdq)`` at ``x``, new arrays (one call of the core)."""
        d = self._compiled.node_state(self._state(x), self._plant_args)
        if d["status"][0]:
            self.check_status(d["status"])
        return d["Y"], d["dY"], d["H"], d["h"], d["J"], d["Jdq"]

    def node_poses(self, x) -> np.ndarray:
        """The node vector ``Y = (Y_0, Phi_1(q_1), ..., Phi_m(q_m))`` of state ``x``, flat ``((m+1) p,)``."""
        return self._node_state(x)[0].reshape(-1)

    def node_velocities(self, x) -> np.ndarray:
        """``Y' = (Y_0', J_1 q_1', ..., J_m q_m')``, flat."""
        return self._node_state(x)[1].reshape(-1)

    def arm_terms(self, x):
        """``(Y, dY, H, h, J, Jdq)`` per node/arm at ``x`` (arrays stacked over arms; rows of
        contact points hold zeros). Used by controllers and sensors."""
        return self._node_state(x)

    def mass_matrix(self, x) -> np.ndarray:
        """``Gamma(z) = blockdiag(H_i + J_i^T W_i J_i, ..., W_0)``."""
        Y, dY, H, h, J, Jdq = self._node_state(x)
        W = self.elastic.inertia(Y)
        p = self.p
        G = np.zeros((self.nz, self.nz))
        for i, arm in enumerate(self.arms):
            sl = self.q_slice(i)
            n = self.arm_dofs[i]
            Wi = W[(i + 1) * p:(i + 2) * p, (i + 1) * p:(i + 2) * p]
            if isinstance(arm, ContactPoint):
                G[sl, sl] = Wi
            else:
                Ji = J[i, :, :n]
                G[sl, sl] = H[i, :n, :n] + Ji.T @ Wi @ Ji
        G[-p:, -p:] = W[:p, :p]
        return G

    def control_terms(self, x) -> ControlTerms:
        """:class:`ControlTerms` at state ``x`` (one call of the core; new arrays that the
        returned object keeps)."""
        xc = np.array(self._state(x), dtype=float)
        d = self._compiled.control_terms(xc, self._plant_args)
        if d["status"][0]:
            self.check_status(d["status"], xc)
        nz = self.nz
        return ControlTerms(d["Y"], d["dY"], d["H"], d["h"], d["J"], d["Jdq"], d["W"], d["w_free"], d["S"], d["Fw"],
                            xc[:nz], xc[nz:2 * nz])

    # ------------------------------------------------------------------ energy
    def elastic_potential(self, Y) -> float:
        """``Pi(Y)`` [J] of the interconnections (see :class:`ElasticSystem`), ``Y`` in the elastic system's
        charts (an arm's node in its own chart has none stored: :meth:`energy` takes the state)."""
        return self.elastic.elastic_potential(Y)

    def elastic_force(self, Y) -> np.ndarray:
        """``F_e = dPi/dY`` (exact gradient), flat."""
        return self.elastic.elastic_force(Y)

    def kinetic_energy(self, x) -> float:
        """``T = 1/2 z'^T Gamma(z) z'`` [J]: arms and nodes."""
        x = self._state(x)
        dz = x[self.nz:]
        return 0.5 * float(dz @ self.mass_matrix(x) @ dz)

    def energy(self, x) -> float:
        """Total energy [J]: kinetic (arms and nodes), elastic, and gravitational (nodes and links).

        Conserved by :meth:`rhs` without damping and input (docs/model.md s.3)."""
        x = self._state(x)
        T = self.kinetic_energy(x)
        if self._charted:
            Y, _, _, _, frames = self._frames_state(x)
            Pi, status = self.elastic._kern.elastic_edges_framed(Y, self._edge_index, self._edge_params,
                                                                np.zeros_like(Y), frames)
            self.elastic._raise(status)
            Y = Y.reshape(-1)
            U_arms = self._compiled.arm_potentials(x, self._plant_args)
            return T + float(Pi) + self.elastic.gravity_potential(Y) + float(U_arms)
        Y = self.node_poses(x)
        U_arms = self._compiled.arm_potentials(x, self._plant_args)
        return T + self.elastic_potential(Y) + self.elastic.gravity_potential(Y) + float(U_arms)

    # ------------------------------------------------------------------ forces on the object
    def contact_wrenches(self, x) -> np.ndarray:
        """Wrench each contact's interconnections apply to the object, (m, p).

        Spatial rows are ``(f, n)``: force [N] at the contact node and couple [N m], world
        frame, so that ``sum_i G_i F_i`` is the interconnections' total wrench about the
        object's MC. Planar rows are ``(f_x, f_z, n)``. This is what a wrist force sensor reads.
        Only edges between the object (node 0) and contact i count toward contact i.
        """
        charted = self._charted  # nodes in charts: the frames come from the state
        if charted:
            Y, dY, _, _, frames = self._frames_state(self._state(x))
        else:
            Y, dY = self._node_state(x)[:2]
        p, m = self.p, self.arm_count
        out = np.zeros((m, p))
        kern = self.elastic._kern
        for e in range(self._edge_index.shape[0]):
            i, j = int(self._edge_index[e, 0]), int(self._edge_index[e, 1])
            if 0 not in (i, j):
                continue
            c = j if i == 0 else i
            F = np.zeros_like(Y)
            ei, ep = self._edge_index[e:e + 1], self._edge_params[e:e + 1]
            if charted:
                kern.elastic_edges_framed(Y, ei, ep, F, frames)
                kern.damping_edges_framed(Y, dY, ei, ep, F, frames)
            elif self._immobile:
                kern.linear_edges(Y, dY, self._Y_ref, ei, ep, F)
            else:
                kern.elastic_edges(Y, ei, ep, F)
                kern.damping_edges(Y, dY, ei, ep, F)
            Q = -F[0]  # generalized force on the object from this edge
            d = Y[c] - Y[0]
            if self.space == "spatial":
                A0 = Y[0, 3:6]
                tau_body = body_rate_map_inv(A0, "object").T @ Q[3:6]
                tau_world = (frames[0, 0] if charted else rotation_zyx(A0)) @ tau_body  # R_0 = C_0 R(A_0)
                f = Q[:3]
                couple = tau_world - np.cross(d[:3], f)
                out[c - 1, :3] += f
                out[c - 1, 3:] += couple
            else:
                f = Q[:2]
                couple = Q[2] - (d[0] * f[1] - d[1] * f[0])
                out[c - 1, :2] += f
                out[c - 1, 2] += couple
        return out

    def interconnection_wrenches(self, Y, dY=None):
        """``(S, Fw)`` of the interconnections at node poses ``Y`` and rates ``dY`` (``(m + 1, p)`` or flat;
        ``None``: at rest), the nodes' angles the book's world angles whatever the plant's charts. ``S`` (m + 1, p):
        each node's interconnection terms of ``w``, ``dPi/dY_i + dD/d(dY_i)``; ``Fw`` (m, p): the wrench the edges
        between the object and each contact apply to the object (as :meth:`contact_wrenches`), zero where the
        object's angles are at the Euler singularity. A stack of samples ``Y`` (``(B, m + 1, p)``, ``dY`` the same
        shape) gives ``S`` (B, m + 1, p) and ``Fw`` (B, m, p), each sample as its own call would. One call of the
        compiled core."""
        shape = (self.node_count, self.p)
        Y = np.ascontiguousarray(Y, dtype=float)
        if Y.ndim == 3 and Y.shape[1:] == shape:
            shape = Y.shape
        elif Y.size != shape[0] * shape[1]:
            raise ParameterError("Y", Y.shape, f"{shape[0]} node poses of {shape[1]} coordinates, or a stack of them")
        dY = np.zeros(shape) if dY is None else np.ascontiguousarray(dY, dtype=float)
        if dY.size != Y.size:
            raise ParameterError("dY", dY.shape, f"{shape[-2]} node rates of {shape[-1]} coordinates per pose of Y")
        S, Fw, _ = self._compiled.interconnection_wrenches(Y.reshape(shape), dY.reshape(shape), self._plant_args)
        return S, Fw

    # ------------------------------------------------------------------ regrouping (4.10-4.11)
    def leader_follower(self, x) -> dict:
        """The leader/follower coordinates ``(q_v, Y_s, Y_0)`` of (163-165) and their rates."""
        x = self._state(x)
        Y = self.node_poses(x).reshape(self.node_count, self.p)
        dY = self.node_velocities(x).reshape(self.node_count, self.p)
        sl = self.q_slice(self.leader)
        return {
            "q_v": x[sl].copy(), "dq_v": x[self.nz:][sl].copy(),
            "Y_s": np.concatenate([Y[i + 1] for i in self.followers]) if self.followers else np.zeros(0),
            "dY_s": np.concatenate([dY[i + 1] for i in self.followers]) if self.followers else np.zeros(0),
            "Y_0": Y[0].copy(), "dY_0": dY[0].copy(),
        }

    # ------------------------------------------------------------------ names and linearization
    def state_names(self) -> list[str]:
        names = []
        for i, arm in enumerate(self.arms):
            if isinstance(arm, ContactPoint):
                names += [f"arm{i + 1}_{c}" for c in _POSE_NAMES[self.space]]
            else:
                names += [f"arm{i + 1}_q{k + 1}" for k in range(arm.dof)]
        names += [f"object_{c}" for c in _POSE_NAMES[self.space]]
        return names + ["d" + n for n in names]

    def input_names(self) -> list[str]:
        names = []
        for i, arm in enumerate(self.arms):
            if isinstance(arm, ContactPoint):
                names += [f"arm{i + 1}_{c}" for c in _INPUT_NAMES[self.space]]
            else:
                names += [f"arm{i + 1}_tau{k + 1}" for k in range(arm.dof)]
        return names

    def jacobians(self, x_eq, tau_eq, rel_step: float = 1e-6):
        """``(A, B) = (df/dx, df/dtau)`` by central differences (step ``rel_step * max(1, |v|)``)."""
        x_eq = self._state(x_eq, "x_eq")
        tau_eq = self._input(tau_eq, "tau_eq")
        nx, nu = x_eq.size, tau_eq.size
        A = np.empty((nx, nx))
        B = np.empty((nx, nu))
        for k in range(nx):
            h = rel_step * max(1.0, abs(x_eq[k]))
            xp, xm = x_eq.copy(), x_eq.copy()
            xp[k] += h
            xm[k] -= h
            A[:, k] = (self.rhs(0.0, xp, tau_eq) - self.rhs(0.0, xm, tau_eq)) / (2 * h)
        for k in range(nu):
            h = rel_step * max(1.0, abs(tau_eq[k]))
            up, um = tau_eq.copy(), tau_eq.copy()
            up[k] += h
            um[k] -= h
            B[:, k] = (self.rhs(0.0, x_eq, up) - self.rhs(0.0, x_eq, um)) / (2 * h)
        return A, B

    def linearize(self, x_eq, tau_eq, rel_step: float = 1e-6):
        """Linear model about ``(x_eq, tau_eq)`` as a ``control.StateSpace`` with named signals.

        ``dx/dt = A (x - x_eq) + B (tau - tau_eq)``, output ``y = x - x_eq``. ``(x_eq, tau_eq)``
        should be an equilibrium (``rhs = 0``); the residual ``rhs(x_eq, tau_eq)`` is not part of
        the linear model.
        """
        import control

        A, B = self.jacobians(x_eq, tau_eq, rel_step)
        names = self.state_names()
        return control.ss(A, B, np.eye(A.shape[0]), np.zeros((A.shape[0], B.shape[1])),
                          states=names, inputs=self.input_names(), outputs=names, name="cooperative_plant")

