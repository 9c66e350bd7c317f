"""The elastic system: m + 1 nodes joined by springs and dampers (docs/model.md s.3, 104-121, 4.5-4.6)."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from plants import _validation as v
from plants.elastic import _compiled_kernels
from plants.elastic._layout import (
    CHART_STORED,
    CHART_WORLD,
    EDGE_HEADER,
    EDGE_WIDTH_PLANAR,
    DAMPING_FORMS,
    EDGE_WIDTH_SPATIAL,
    ELEMENT_MATRIX,
    ELEMENT_OFFSET,
    ELEMENTS,
    CHARTED_NODE,
    NODE_WIDTH_CHARTED,
    PLANAR_MATRIX,
    PLANAR_SPRING,
    ROTATION_FORMS,
    SPATIAL_MATRIX,
    SPATIAL_SPRING,
    STATUS_COINCIDENT_NODES,
    STATUS_EULER_SINGULAR,
    STATUS_OK,
)
from plants.elastic.interconnection import Interconnection
from plants.elastic.node import Node
from plants import charts as _charts
from plants.errors import EulerSingularityError, ParameterError
from plants.frames import EULER_SINGULARITY_COS, rotation_zyx

SPACES = ("spatial", "planar")
UNLOADED_STATES = ("mobile", "immobile")


def _wrap(a):
    """Angles [rad] mapped into [-pi, pi)."""
    return (np.asarray(a, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


def pose_size(space: str) -> int:
    """Size ``p`` of one node pose: 6 in space ``(r, A)``, 3 in the plane ``(x, z, theta)``."""
    return 6 if space == "spatial" else 3


class ElasticSystem:
    """Nodes 0..m (node 0 = the object's mass centre) joined by interconnections on an edge set.

    Equations (113), with ``Y = col(Y_0, ..., Y_m)``:

    .. math::
        W(Y) \\ddot Y + w(Y, \\dot Y) = F, \\qquad
        w = \\text{gyro}(Y, \\dot Y) + \\partial \\Pi / \\partial Y + \\partial D / \\partial \\dot Y - Q_g

    with ``W = blockdiag(m_i I_3, L_i^T I_i L_i)`` (105, 114), the potential ``Pi`` of the
    springs (106-107, 119), the Rayleigh function ``D`` (110), gravity ``Q_g = (m_i g, 0)`` and
    ``F_0 = 0`` (the split (115) is the partition ``Y = (Y_0, Y_c)``).

    ``unloaded_state="immobile"`` gives the linear model of 4.5: ``W(Y_ref) y'' + D y' + K y =
    F + Q_g`` with ``y = Y - Y_ref`` and the constant ``K`` of :meth:`stiffness_matrix`.

    Args:
        space: ``"spatial"`` (poses ``(x, y, z, psi, theta, phi)``) or ``"planar"`` (``(x, z, theta)``).
        nodes: The m + 1 nodes, object first.
        interconnections: The edge set.
        reference_poses: (m + 1, p) node poses of the unloaded state [m, rad]; rest lengths,
            angles and offsets not given explicitly are taken from it.
        gravity: Gravity vector [m/s^2] (3 spatial, 2 planar ``(g_x, g_z)``) or a magnitude
            along -z.
        unloaded_state: ``"mobile"`` (general, 4.6) or ``"immobile"`` (linear, 4.5).
        charts: Spatial only: every node's rotation chart ``C_k`` (N, 3, 3): node k's angles ``A_k``
            are taken in it, ``R_k = C_k R(A_k)`` (:mod:`plants.charts`, docs/model.md s.2); ``None``
            (default) = the identity, the book's world angles. A chart other than the identity
            needs interconnections that depend on no chart (rotation form ``"geodesic"`` wherever
            a central element has torsion, ``damping_form = "frame_invariant"`` wherever there is
            torsion damping) and the mobile model. The reference poses are world poses whatever
            the charts. :meth:`recentred` moves the charts onto the current rotations.
    """

    def __init__(
        self,
        space: str,
        nodes: Sequence[Node],
        interconnections: Sequence[Interconnection],
        reference_poses,
        gravity=9.81,
        unloaded_state: str = "mobile",
        charts=None,
    ):
        if space not in SPACES:
            raise ParameterError("space", space, f"one of {SPACES}")
        if unloaded_state not in UNLOADED_STATES:
            raise ParameterError("unloaded_state", unloaded_state, f"one of {UNLOADED_STATES}")
        self.space = space
        self.unloaded_state = unloaded_state
        self.p = p = pose_size(space)
        self.nodes = tuple(nodes)
        N = len(self.nodes)
        if N < 2:
            raise ParameterError("nodes", N, "at least 2 nodes (the object and one contact)")
        n_inertia = 3 if space == "spatial" else 1
        for k, node in enumerate(self.nodes):
            if not isinstance(node, Node):
                raise ParameterError(f"nodes[{k}]", node, "a plants.elastic.Node")
            if len(node.inertia) != n_inertia:
                raise ParameterError(f"nodes[{k}].inertia", node.inertia, f"{n_inertia} principal moment(s) in a {space} scene")
        self.node_count = N
        self.Y_ref = v.finite_array("reference_poses", reference_poses).reshape(-1)
        if self.Y_ref.size != N * p:
            raise ParameterError("reference_poses", np.shape(reference_poses), f"{N} poses of {p} values")
        self.Y_ref = self.Y_ref.reshape(N, p).copy()
        if space == "spatial":
            for k in range(N):
                c = np.cos(self.Y_ref[k, 4])
                if abs(c) < EULER_SINGULARITY_COS:
                    raise EulerSingularityError(f"reference pose of node {k}", float(self.Y_ref[k, 4]), float(c))
        g = v.finite_array("gravity", gravity)
        if g.ndim == 0:
            g = np.zeros(3 if space == "spatial" else 2)
            g[-1] = -float(gravity)
        if g.shape != ((3,) if space == "spatial" else (2,)):
            raise ParameterError("gravity", gravity, "a magnitude or a vector (3 spatial, 2 planar)")
        self.gravity = g
        self.interconnections = tuple(interconnections)
        if not self.interconnections:
            raise ParameterError("interconnections", [], "at least one interconnection")
        self.node_params = np.array([[nd.mass, *nd.inertia] for nd in self.nodes], dtype=float)
        self.edge_index, self.edge_params = self._pack_edges()
        # the compiled core's kernels (plants/core/elastic_*.h)
        self._kern = _compiled_kernels.spatial if space == "spatial" else _compiled_kernels.planar
        self.immobile = unloaded_state == "immobile"
        self._set_charts(charts)

    # ------------------------------------------------------------------ charts
    def chart_dependence(self) -> str | None:
        """Why this system's equations depend on the angles' chart (a sentence), or ``None`` when they
        do not (then any :attr:`charts` are allowed)."""
        if self.space != "spatial":
            return "a planar system has one angle per node and no charts"
        if self.immobile:
            return "the immobile model (4.5) is linear in the book's world angles (unloaded_state = 'immobile')"
        for e, ic in enumerate(self.interconnections):
            name = ic.name if ic.name != "interconnection" else f"interconnections[{e}]"
            if (ic.element == "central" and ic.rotation_form == "book"
                    and np.any(self.edge_params[e, SPATIAL_SPRING["torsion"]] != 0.0)):
                return (f"{name} has rotation_form = 'book': its torsion springs act on the Euler difference "
                        "A_i - A_j - A0, which changes with the chart; use rotation_form = 'geodesic'")
            if ic.damping_form == "book" and ic.torsion_damping != 0.0:
                return (f"{name} has damping_form = 'book': its torsion dampers act on the Euler rates, which "
                        "change with the chart; use damping_form = 'frame_invariant'")
        return None

    def _set_charts(self, charts) -> None:
        """Validate ``charts`` and pack the node rows the kernels read (:mod:`plants.elastic._layout`)."""
        N = self.node_count
        if self.space != "spatial":
            if charts is not None:
                raise ParameterError("charts", "given", "None for a planar system (charts are for spatial rotations)")
            self.charts = None
            self._node_rows = self.node_params
            return
        C = _charts.chart_array("charts", charts, N)
        identity = [_charts.is_identity(C[k]) for k in range(N)]
        if not all(identity):
            why = self.chart_dependence()
            if why is not None:
                raise ParameterError("charts", "not the identity", f"the identity (the book's world angles): {why}")
            rows = np.zeros((N, NODE_WIDTH_CHARTED))
            rows[:, CHARTED_NODE.col("mass")] = self.node_params[:, 0]
            rows[:, CHARTED_NODE["inertia"]] = self.node_params[:, 1:4]
            for k in range(N):
                rows[k, CHARTED_NODE["chart_kind"]] = CHART_WORLD if identity[k] else CHART_STORED
                rows[k, CHARTED_NODE["chart"]] = C[k].reshape(-1)
            self._node_rows = rows
        else:
            self._node_rows = self.node_params
        C.setflags(write=False)
        self.charts = C

    @property
    def node_rows(self) -> np.ndarray:
        """The node rows the kernels read (:mod:`plants.elastic._layout`): :attr:`node_params` ``(mass, inertia)``,
        or the wider ``CHARTED_NODE`` rows with each node's chart when :attr:`charted`."""
        return self._node_rows

    @property
    def charted(self) -> bool:
        """True when some node's chart is not the identity (its angles are not the book's)."""
        return self._node_rows is not self.node_params

    def with_charts(self, charts) -> "ElasticSystem":
        """This system with other node charts (a shallow copy: the packed parameters are shared)."""
        import copy

        out = copy.copy(self)
        out._set_charts(charts)
        return out

    def recentred(self, x, nodes=None):
        """``(system, x')``: the same physical state with the charts of ``nodes`` (default: every node)
        moved onto their current rotations, ``C_k' = C_k R(A_k)``, ``A_k' = 0``, the same positions,
        rates and body angular velocities (:func:`plants.charts.recentre`). ``x = (Y, dY)`` flat; call
        it between integration steps when a node's ``|cos theta|`` gets small."""
        if self.space != "spatial":
            raise ParameterError("space", self.space, "'spatial' (charts are for spatial rotations)")
        n = self.size
        x = np.array(x, dtype=float).reshape(-1)
        if x.size != 2 * n:
            raise ParameterError("x", x.shape, f"{2 * n} values (Y then dY)")
        Y, dY = x[:n].reshape(self.node_count, 6), x[n:].reshape(self.node_count, 6)
        C = self.charts.copy()
        for k in (range(self.node_count) if nodes is None else nodes):
            C[k], Y[k, 3:6], dY[k, 3:6] = _charts.recentre(C[k], Y[k, 3:6], dY[k, 3:6])
        return self.with_charts(C), x

    def chart_cos(self, x) -> float:
        """The smallest ``|cos theta|`` of the nodes' angles in their charts at ``x = (Y, dY)`` (or ``Y``):
        below ~0.7 (45 deg from the chart) an integrator calls :meth:`recentred` between steps."""
        Y = np.asarray(x, dtype=float).reshape(-1)[:self.size].reshape(self.node_count, self.p)
        if self.space != "spatial":
            return 1.0
        return float(np.min(np.abs(np.cos(Y[:, 4]))))

    def book_coordinates(self, x, dx):
        """``(Y, dY, ddY)`` of every node in the book's coordinates (world ZYX Euler angles), flat
        ``((m + 1) 6,)`` each, from the state ``x = (Y, dY)`` and its rate ``dx = (dY, ddY)`` (as
        :meth:`rhs` returns it) in the nodes' charts. Raises :class:`EulerSingularityError` where
        the world angles do not exist (a node at pitch +-90 deg)."""
        n = self.size
        x, dx = np.asarray(x, dtype=float).reshape(-1), np.asarray(dx, dtype=float).reshape(-1)
        if x.size != 2 * n or dx.size != 2 * n:
            raise ParameterError("x, dx", (x.shape, dx.shape), f"{2 * n} values each")
        Y, dY, ddY = x[:n].reshape(-1, self.p).copy(), x[n:].reshape(-1, self.p).copy(), dx[n:].reshape(-1, self.p).copy()
        if self.space == "spatial":
            for k in range(self.node_count):
                Y[k, 3:6], dY[k, 3:6], ddY[k, 3:6] = _charts.world_coordinates(
                    self.charts[k], Y[k, 3:6], dY[k, 3:6], ddY[k, 3:6], f"node {k}")
        return Y.reshape(-1), dY.reshape(-1), ddY.reshape(-1)

    # ------------------------------------------------------------------ packing
    def _pack_edges(self):
        p, N, Yr = self.p, self.node_count, self.Y_ref
        spatial = self.space == "spatial"
        E = len(self.interconnections)
        idx = np.zeros((E, 4), dtype=np.int64)
        par = np.zeros((E, EDGE_WIDTH_SPATIAL if spatial else EDGE_WIDTH_PLANAR))
        npos = 3 if spatial else 2
        nang = 3 if spatial else 1
        seen = set()
        for e, ic in enumerate(self.interconnections):
            name = ic.name if ic.name != "interconnection" else f"interconnections[{e}]"
            i, j = ic.pair
            if i >= N or j >= N:
                raise ParameterError(f"{name}.pair", list(ic.pair), f"node indices in 0..{N - 1}")
            key = (min(i, j), max(i, j))
            if key in seen:
                raise ParameterError(f"{name}.pair", list(ic.pair), "a pair not already connected")
            seen.add(key)
            c = v.per_axis(f"{name}.stiffness", ic.stiffness, npos)
            cA = v.per_axis(f"{name}.torsion", ic.torsion, nang)
            d_ref = Yr[i, :npos] - Yr[j, :npos]
            dist = float(np.linalg.norm(d_ref))
            l = dist if ic.rest_length is None else float(ic.rest_length)
            if ic.element == "central" and l > 0.0 and dist < 1e-9 * l:
                raise ParameterError(
                    f"{name}.pair", list(ic.pair),
                    f"nodes {i} and {j} coincide in the reference poses while the central spring has rest length {l} m > 0; "
                    "separate the nodes or set rest_length = 0",
                )
            if ic.element in ("matrix", "beam"):
                par[e] = _pack_matrix_element(name, ic, Yr[i], Yr[j], par.shape[1])
                idx[e] = (i, j, ELEMENTS[ic.element], DAMPING_FORMS[ic.damping_form])
                continue
            if ic.rest_angles is None:
                A0 = _wrap(Yr[i, npos:] - Yr[j, npos:])
            else:
                A0 = v.finite_array(f"{name}.rest_angles", np.atleast_1d(ic.rest_angles), (nang,))
            if spatial:
                Ri = rotation_zyx(Yr[i, 3:6])
                Rj = rotation_zyx(Yr[j, 3:6])
                rho = Ri.T @ (Yr[j, :3] - Yr[i, :3]) if ic.rest_offset is None else v.finite_array(
                    f"{name}.rest_offset", ic.rest_offset, (3,))
                # cA is given per Euler axis (psi, theta, phi) = body (z, y, x) at the reference;
                # kappa is per body axis (x, y, z): cA_body = cA[::-1].
                geodesic = ic.rotation_form == "geodesic"
                S = cA.sum() / 2.0
                kappa = S - cA[::-1] if ic.element == "offset" and not geodesic else np.zeros(3)
                if np.any(kappa < 0):
                    raise ParameterError(
                        f"{name}.torsion", ic.torsion,
                        "for the offset element each torsion component must not exceed the sum of the other two",
                    )
                R0 = Ri.T @ Rj
                row, S = par[e], SPATIAL_SPRING
                row[S["stiffness"]] = c
                row[S["torsion"]] = cA
                row[S["rest_length"]] = l
                row[S["rest_angles"]] = A0
                row[S["rest_offset"]] = rho
                row[S["damping"]] = ic.damping
                row[S["torsion_damping"]] = ic.torsion_damping
                row[S["kappa"]] = kappa
                row[S["rest_rotation"]] = R0.reshape(-1)
                if geodesic:
                    # the rest relative rotation R_i0^T R(A_i0 - A0) (= R_i0^T R_j0 without rest_angles)
                    if ic.rest_angles is not None:
                        row[S["rest_rotation"]] = (Ri.T @ rotation_zyx(Yr[i, 3:6] - A0)).reshape(-1)
                    row[S["rotation_form"]] = ROTATION_FORMS["geodesic"]
            else:
                th = Yr[i, 2]
                Rt = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
                rho = Rt @ (Yr[j, :2] - Yr[i, :2]) if ic.rest_offset is None else v.finite_array(
                    f"{name}.rest_offset", ic.rest_offset, (2,))
                row, S = par[e], PLANAR_SPRING
                row[S["stiffness"]] = c
                row[S["torsion"]] = cA[0]
                row[S["rest_length"]] = l
                row[S["rest_angle"]] = A0[0]
                row[S["rest_offset"]] = rho
                row[S["damping"]] = ic.damping
                row[S["torsion_damping"]] = ic.torsion_damping
            idx[e] = (i, j, ELEMENTS[ic.element], DAMPING_FORMS[ic.damping_form])
        return idx, par

    # ------------------------------------------------------------------ helpers
    def _Y(self, Y, name="Y") -> np.ndarray:
        arr = np.asarray(Y, dtype=float)
        if arr.size != self.node_count * self.p:
            raise ParameterError(name, arr.shape, f"{self.node_count * self.p} values ({self.node_count} poses of {self.p})")
        return np.ascontiguousarray(arr.reshape(self.node_count, self.p))

    def _frames(self, Y):
        """Every node's world frames in its chart (``plants._core.spatial_node_frames``)."""
        return self._kern.node_frames_charted(Y, self._node_rows)

    def _raise(self, status, where="elastic system"):
        if status == STATUS_COINCIDENT_NODES:
            raise ParameterError(
                "Y", "coincident nodes",
                "nodes of a central spring with positive rest length at distinct positions "
                "(beta = (1 - l/|r_i - r_j|)^2 is undefined at distance 0)",
            )
        if status == STATUS_EULER_SINGULAR:
            raise EulerSingularityError(where, float("nan"), 0.0)

    @property
    def size(self) -> int:
        """Number of generalized coordinates ``(m + 1) p``."""
        return self.node_count * self.p

    # ------------------------------------------------------------------ energy and forces
    def elastic_potential(self, Y) -> float:
        """Deformation energy ``Pi(Y)`` [J] (106-107, 119), or ``1/2 y^T K y`` when immobile."""
        Y = self._Y(Y)
        F = np.zeros_like(Y)
        if self.immobile:
            return float(self._kern.linear_edges(Y, np.zeros_like(Y), self.Y_ref, self.edge_index, self.edge_params, F))
        if self.charted:
            Pi, status = self._kern.elastic_edges_framed(Y, self.edge_index, self.edge_params, F, self._frames(Y))
            self._raise(status)
            return float(Pi)
        Pi, status = self._kern.elastic_edges(Y, self.edge_index, self.edge_params, F)
        self._raise(status)
        return float(Pi)

    def elastic_force(self, Y) -> np.ndarray:
        """The exact gradient ``F_e = dPi/dY`` (120-121), flat ``((m + 1) p,)`` [N, N m/rad]."""
        Y = self._Y(Y)
        F = np.zeros_like(Y)
        if self.immobile:
            self._kern.linear_edges(Y, np.zeros_like(Y), self.Y_ref, self.edge_index, self.edge_params, F)
        elif self.charted:
            _, status = self._kern.elastic_edges_framed(Y, self.edge_index, self.edge_params, F, self._frames(Y))
            self._raise(status)
        else:
            _, status = self._kern.elastic_edges(Y, self.edge_index, self.edge_params, F)
            self._raise(status)
        return F.reshape(-1)

    def dissipation(self, Y, dY) -> float:
        """Rayleigh dissipation function ``D(Y, dY)`` [W/2] (110)."""
        Y, dY = self._Y(Y), self._Y(dY, "dY")
        if self.immobile:
            return 0.5 * float(dY.reshape(-1) @ self.damping_matrix() @ dY.reshape(-1))
        if self.charted:
            return float(self._kern.damping_edges_framed(Y, dY, self.edge_index, self.edge_params, np.zeros_like(Y),
                                                         self._frames(Y)))
        return float(self._kern.damping_edges(Y, dY, self.edge_index, self.edge_params, np.zeros_like(Y)))

    def damping_force(self, Y, dY) -> np.ndarray:
        """``dD/d(dY)`` (111), flat."""
        Y, dY = self._Y(Y), self._Y(dY, "dY")
        if self.immobile:
            return self.damping_matrix() @ dY.reshape(-1)
        F = np.zeros_like(Y)
        if self.charted:
            self._kern.damping_edges_framed(Y, dY, self.edge_index, self.edge_params, F, self._frames(Y))
        else:
            self._kern.damping_edges(Y, dY, self.edge_index, self.edge_params, F)
        return F.reshape(-1)

    def inertia(self, Y) -> np.ndarray:
        """``W(Y) = blockdiag(m_i I, L_i^T I_i L_i)`` (105, 114), ``((m+1)p, (m+1)p)``; constant when immobile."""
        Y = self._Y(Y)
        if self.immobile:
            Y = self.Y_ref
        N, p = self.node_count, self.p
        W = np.zeros((N * p, N * p))
        for k in range(N):
            m = self.node_params[k, 0]
            o = k * p
            if self.space == "spatial":
                W[o:o + 3, o:o + 3] = m * np.eye(3)
                Wr = np.empty((3, 3))
                _compiled_kernels.spatial.node_rotational_terms(
                    np.ascontiguousarray(Y[k, 3:6]), np.zeros(3), self.node_params[k, 1:4], Wr, np.empty(3))
                W[o + 3:o + 6, o + 3:o + 6] = Wr
            else:
                W[o:o + 3, o:o + 3] = np.diag([m, m, self.node_params[k, 1]])
        return W

    def w(self, Y, dY) -> np.ndarray:
        """``w(Y, dY)`` of (113): gyroscopic + elastic + damping - gravity, flat."""
        Y, dY = self._Y(Y), self._Y(dY, "dY")
        ddY = self.accelerations(Y, dY, np.zeros(self.size))
        return -(self.inertia(Y) @ ddY)

    def accelerations(self, Y, dY, F) -> np.ndarray:
        """Solve (113) ``W Y'' + w = F`` for ``Y''`` (flat); ``F_0`` is ignored (it is 0)."""
        Y, dY, F = self._Y(Y), self._Y(dY, "dY"), self._Y(F, "F")
        ddY, status = self._kern.elastic_accelerations(
            Y, dY, F, self._node_rows, self.edge_index, self.edge_params, self.gravity, self.Y_ref, self.immobile)
        self._raise(status)
        return ddY.reshape(-1)

    def rhs(self, t: float, x, F) -> np.ndarray:
        """First-order form of (113) for the free elastic system: ``x = (Y, dY)``, input ``F`` = contact forces."""
        n = self.size
        return np.concatenate([x[n:], self.accelerations(x[:n], x[n:], F)])

    def gravity_potential(self, Y) -> float:
        """``-sum_i m_i g . r_i`` [J]."""
        Y = self._Y(Y)
        npos = 3 if self.space == "spatial" else 2
        return float(-np.sum(self.node_params[:, 0] * (Y[:, :npos] @ self.gravity)))

    def energy(self, Y, dY) -> float:
        """Kinetic + elastic + gravitational energy [J] of the nodes."""
        dYf = np.asarray(dY, dtype=float).reshape(-1)
        return 0.5 * float(dYf @ self.inertia(Y) @ dYf) + self.elastic_potential(Y) + self.gravity_potential(Y)

    def node_stiffness(self, Y, k: int = 0, step: float = 1e-7) -> np.ndarray:
        """``d F_e,k / d Y_k`` (p x p): the stiffness node k feels with every other node held,
        by central differences of the exact elastic force. A negative eigenvalue means node k
        is statically unstable there (e.g. the squeezed central springs of docs/model.md s.3)."""
        Y = self._Y(Y).copy()
        p = self.p
        Kk = np.empty((p, p))
        for a in range(p):
            Yp, Ym = Y.copy(), Y.copy()
            Yp[k, a] += step
            Ym[k, a] -= step
            Kk[:, a] = (self.elastic_force(Yp)[k * p:(k + 1) * p] - self.elastic_force(Ym)[k * p:(k + 1) * p]) / (2 * step)
        return 0.5 * (Kk + Kk.T)

    # ------------------------------------------------------------------ immobile model (4.5)
    def _laplacian(self, diag_of, linear_block: int = 0) -> np.ndarray:
        N, p = self.node_count, self.p
        K = np.zeros((N * p, N * p))
        for e in range(len(self.interconnections)):
            dofs, block = self._edge_block(e, diag_of, linear_block)
            K[np.ix_(dofs, dofs)] += block
        return K

    def _edge_block(self, e: int, diag_of, linear_block: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """``(dofs, block)``: interconnection ``e``'s (2p x 2p) matrix of the immobile model and the rows of
        its two nodes ``(y_i, y_j)``: a matrix or beam element's packed linearization, else the vector
        spring ``[[k, -k], [-k, k]]`` with ``k = diag(diag_of(params))``."""
        p = self.p
        i, j = self.edge_index[e, :2]
        dofs = np.r_[i * p:(i + 1) * p, j * p:(j + 1) * p]
        if self.edge_index[e, EDGE_HEADER.col("kind")] == ELEMENT_MATRIX:  # its linearization K_lin (D_lin), packed once
            rows = SPATIAL_MATRIX if self.space == "spatial" else PLANAR_MATRIX
            block = self.edge_params[e, rows[("stiffness_linear", "damping_linear")[linear_block]]]
            return dofs, block.reshape(2 * p, 2 * p).copy()
        kd = np.diag(diag_of(self.edge_params[e]))
        return dofs, np.block([[kd, -kd], [-kd, kd]])

    def edge_stiffness(self, e: int) -> tuple[np.ndarray, np.ndarray]:
        """Interconnection ``e``'s stiffness in the immobile model (4.5): ``(dofs, K_e)``, ``K_e`` (2p x 2p)
        [N/m, N, N m/rad] on the rows ``dofs`` of :meth:`stiffness_matrix` (node i's then node j's);
        :meth:`stiffness_matrix` is their sum."""
        return self._edge_block(int(e), self._stiffness_diagonal)

    def stiffness_matrix(self) -> np.ndarray:
        """Constant ``K`` of the immobile unloaded state (4.5): vector springs
        ``K_ij = diag(c^x, c^y, c^z, cA^psi, cA^theta, cA^phi)`` assembled like a graph Laplacian.
        Rank ``p m`` for a connected edge set with positive stiffnesses; ``p`` zero modes (the
        common translation of every coordinate)."""
        return self._laplacian(self._stiffness_diagonal)

    def _stiffness_diagonal(self, r) -> np.ndarray:
        """``diag(K_ij)`` of one interconnection from its packed parameters ``r``."""
        S = SPATIAL_SPRING if self.space == "spatial" else PLANAR_SPRING
        return np.r_[r[S["stiffness"]], r[S["torsion"]]]

    def stiffness_assembly(self):
        """The book's finite-element assembly (47)-(59) of this system (:func:`plants.elastic.fem.stiffness_assembly`),
        in the plant's coordinates ``y = Y - Y_ref``.

        Every interconnection is an element: a beam with its internal nodes (the kinematically
        indeterminate ``k`` of (50), condensed by (53)-(54)), a matrix element in its own frame,
        and a spring with the stiffness ``[[K_ij, -K_ij], [-K_ij, K_ij]]`` of :meth:`stiffness_matrix`.
        ``a_0`` maps the nodes' coordinates to the elements' displacements through each node's
        ``blockdiag(I, R(A) L(A))`` at the reference (world translations and small rotations from
        ``(r, A)``), so ``K = a^T K_e a`` equals :meth:`stiffness_matrix`."""
        from plants.elastic.fem import MatrixElement, stiffness_assembly
        from plants.elastic.fem.elements import line_frame

        p, d = self.p, 3 if self.space == "spatial" else 2
        maps = [self._node_map(k) for k in range(self.node_count)]
        elements = []
        for e, ic in enumerate(self.interconnections):
            i, j = int(self.edge_index[e, EDGE_HEADER.col("i")]), int(self.edge_index[e, EDGE_HEADER.col("j")])
            if ic.element == "beam":
                from dataclasses import replace

                elements.append(replace(ic.beam, nodes=(i, j)))
            elif ic.element == "matrix":
                frame = (np.asarray(ic.frame, float) if ic.frame is not None
                         else line_frame(self.Y_ref[i, :3], self.Y_ref[j, :3]) if d == 3
                         else _line_rotation_2d(self.Y_ref[i, :2], self.Y_ref[j, :2]))
                elements.append(MatrixElement((i, j), np.asarray(ic.matrix, float), frame_rotation=frame))
            else:  # a spring in the plant's coordinates, taken to world displacements
                kd = np.diag(self._stiffness_diagonal(self.edge_params[e]))
                Tinv = np.zeros((2 * p, 2 * p))
                Tinv[:p, :p], Tinv[p:, p:] = np.linalg.inv(maps[i]), np.linalg.inv(maps[j])
                elements.append(MatrixElement((i, j), Tinv.T @ np.block([[kd, -kd], [-kd, kd]]) @ Tinv,
                                              frame_rotation=np.eye(d)))
        return stiffness_assembly(elements, self.Y_ref[:, :d], node_maps=maps)

    def _node_map(self, k: int) -> np.ndarray:
        """``d(world translation, small rotation)/d(r, A)`` of node k at the reference:
        ``blockdiag(I, R(A) L(A))`` (spatial), the identity (planar: theta is the rotation)."""
        if self.space != "spatial":
            return np.eye(3)
        T = np.eye(6)
        A = self.Y_ref[k, 3:6]
        T[3:, 3:] = rotation_zyx(A) @ _body_rate_matrix(A)
        return T

    def damping_matrix(self) -> np.ndarray:
        """Constant ``D`` of the immobile model: ``diag(d I, dA I)`` per edge, Laplacian-assembled (the
        book's vector dampers of 4.5, whatever ``damping_form``: the immobile model is the book's linear
        model; the frame-invariant form of the mobile model couples a node's rotation into the damping of
        the offset, ``rho x omega_i``, which this diagonal form does not have)."""
        S = SPATIAL_SPRING if self.space == "spatial" else PLANAR_SPRING
        npos = 3 if self.space == "spatial" else 2
        return self._laplacian(lambda r: np.r_[np.full(npos, r[S.col("damping")]), np.full(self.p - npos, r[S.col("torsion_damping")])],
                               linear_block=1)


def _body_rate_matrix(A) -> np.ndarray:
    """``L(A)`` of ``omega = L(A) dA`` (body angular velocity from ZYX Euler rates, docs/model.md s.2)."""
    _, th, ph = A
    return np.array([[-np.sin(th), 0.0, 1.0],
                     [np.sin(ph) * np.cos(th), np.cos(ph), 0.0],
                     [np.cos(ph) * np.cos(th), -np.sin(ph), 0.0]])


def _skew(a) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def element_matrix(name: str, ic, Yi, Yj) -> np.ndarray:
    """The stiffness of a matrix or beam interconnection in its own frame (12x12 spatial, 6x6
    planar): a beam's from :mod:`plants.elastic.fem`, internal nodes condensed by (53)-(54), its
    length the distance between the nodes at rest ``Yi``, ``Yj``."""
    if ic.element == "matrix":
        return np.asarray(ic.matrix, dtype=float)
    from dataclasses import replace

    from plants.elastic.fem import stiffness_assembly

    n = 3 if len(Yi) == 6 else 2
    length = float(np.linalg.norm(np.asarray(Yj[:n], float) - np.asarray(Yi[:n], float)))
    if not length > 1e-9:
        raise ParameterError(f"{name}.pair", list(ic.pair), f"two nodes apart at rest for a beam (its length is the "
                             f"distance between them; got {length:.3g} m)")
    ends = np.zeros((2, n))
    ends[1, 0] = length
    return stiffness_assembly([replace(ic.beam, nodes=(0, 1))], ends).K


def _pack_matrix_element(name: str, ic, Yi, Yj, width: int) -> np.ndarray:
    """The packed row of a matrix element (``plants.elastic._layout``, ``MATRIX_*`` columns).

    Node i is clamped in the element frame: ``K_jj`` and ``C_jj`` are the node-j blocks of the
    element's matrices, which hold its whole energy because the matrices leave the element's
    rigid motions free (checked here). ``G0`` maps ``(y_i, y_j)`` (the plant's coordinates) to node
    j's deformation at the reference; ``K_lin = G0^T K_jj G0`` is the element in the immobile model.
    """
    from plants.elastic.fem.elements import line_frame

    spatial = len(Yi) == 6
    K = element_matrix(name, ic, Yi, Yj)
    C = ic.rayleigh_damping * K if ic.matrix_damping is None else np.asarray(ic.matrix_damping, dtype=float)
    if K.shape != ((12, 12) if spatial else (6, 6)):
        raise ParameterError(f"{name}.matrix", K.shape, f"{'12x12' if spatial else '6x6'} in a {'spatial' if spatial else 'planar'} scene")
    row = np.zeros(width)
    if spatial:
        Ri0, Rj0 = rotation_zyx(np.asarray(Yi[3:6], float)), rotation_zyx(np.asarray(Yj[3:6], float))
        Re0 = line_frame(Yi[:3], Yj[:3]) if ic.frame is None else np.asarray(ic.frame, float)
        u0 = Re0.T @ (np.asarray(Yj[:3], float) - np.asarray(Yi[:3], float))
        rigid = np.zeros((12, 6))
        for k in range(3):
            e = np.eye(3)[k]
            rigid[k, k] = rigid[6 + k, k] = 1.0
            rigid[3 + k, 3 + k] = rigid[9 + k, 3 + k] = 1.0
            rigid[6:9, 3 + k] = np.cross(e, u0)
        M, N = Ri0.T @ Re0, Rj0.T @ Re0
        Li, Lj = _body_rate_matrix(Yi[3:6]), _body_rate_matrix(Yj[3:6])
        G0 = np.zeros((6, 12))
        G0[0:3, 0:3], G0[0:3, 6:9] = -Re0.T, Re0.T
        G0[0:3, 3:6] = _skew(u0) @ M.T @ Li
        G0[3:6, 3:6], G0[3:6, 9:12] = -M.T @ Li, N.T @ Lj
        n, rows = 6, SPATIAL_MATRIX
        row[rows["rest_offset"]], row[rows["frame_in_i"]], row[rows["frame_in_j"]] = u0, M.reshape(-1), N.reshape(-1)
    else:
        d = np.asarray(Yj[:2], float) - np.asarray(Yi[:2], float)
        if ic.frame is None:
            length = float(np.hypot(*d))
            if not length > 0.0:
                raise ParameterError(f"{name}.pair", list(ic.pair), "nodes apart in the reference poses (the element's frame is the line between them), or give frame")
            te = float(np.arctan2(d[1], d[0]))
        else:
            R = np.asarray(ic.frame, float)
            te = float(np.arctan2(R[1, 0], R[0, 0]))
        c, s = np.cos(te), np.sin(te)
        u0 = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
        rigid = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 0, -u0[1]], [0, 1.0, u0[0]], [0, 0, 1.0]])
        G0 = np.zeros((3, 6))
        G0[0:2, 0:2] = -np.array([[c, s], [-s, c]])
        G0[0:2, 3:5] = np.array([[c, s], [-s, c]])
        G0[0:2, 2] = (u0[1], -u0[0])
        G0[2, 2], G0[2, 5] = -1.0, 1.0
        n, rows = 3, PLANAR_MATRIX
        row[rows["rest_offset"]] = u0
        row[rows["frame_angle"]] = te - float(Yi[2])
        row[rows["rest_angle"]] = float(Yj[2]) - float(Yi[2])
    for label, A in (("matrix", K), ("matrix_damping", C)):
        scale = float(np.max(np.abs(A))) or 1.0
        if np.max(np.abs(A @ rigid)) > 1e-9 * scale * max(1.0, float(np.linalg.norm(u0))):
            raise ParameterError(f"{name}.{label}", "not free",
                                 "a matrix that leaves the element's rigid motions free (A r = 0 for its translations "
                                 "and rotations; a grounded element cannot be co-rotational)")
    Kjj, Cjj = K[n:, n:], C[n:, n:]
    row[rows["stiffness_jj"]] = Kjj.reshape(-1)
    row[rows["damping_jj"]] = Cjj.reshape(-1)
    row[rows["stiffness_linear"]] = (G0.T @ Kjj @ G0).reshape(-1)
    row[rows["damping_linear"]] = (G0.T @ Cjj @ G0).reshape(-1)
    return row


def _line_rotation_2d(p_a, p_b) -> np.ndarray:
    d = np.asarray(p_b, float) - np.asarray(p_a, float)
    a = float(np.arctan2(d[1], d[0]))
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
