"""The load-distribution QP, assembled in preallocated arrays (docs/model.md section 6)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ScenarioError
from .config import LoadDistributionConfig
from .grasp_matrix import POSITION_DIM, closest_pair, contact_pairs, identity_grasp_matrix, wrench_dim


def _degenerate_grasp() -> ScenarioError:
    return ScenarioError("r_contacts", "degenerate grasp", "contacts that span every object wrench (G G^T invertible)")


def _spd_solve(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve ``M y = b`` for a small symmetric positive definite ``M`` (LAPACK ``dposv``, about
    1 us; ``np.linalg.solve`` costs 4 to 11 us). Raises ``ScenarioError`` if ``M`` is singular. scipy is imported
    here, by the scenes that split elastically in Python (a run imports it only if its scene needs it)."""
    from scipy.linalg.lapack import dposv

    _, y, info = dposv(M, b)
    if info != 0:
        raise _degenerate_grasp()
    return y


def _stack(out: np.ndarray, per_arm, counts: tuple[int, ...]) -> None:
    """Write each arm's values (one number, or ``counts[i]`` numbers) one after the other into ``out``."""
    row = 0
    for c, v in zip(counts, per_arm):
        out[row:row + c] = v
        row += c


class LoadDistributionProblem:
    """The QP over the stacked contact wrenches ``F`` (n = 6m spatial, 3m planar):

    .. math::

        \\min_F \\; \\tfrac12 (F - F_{pref})^T P (F - F_{pref})
        \\quad \\text{s.t.} \\quad G F = w_N, \\qquad l \\le C F \\le u,

        F_{pref} = A w_N + E s_{des}, \\qquad
        A = W^{-1} G^T (G W^{-1} G^T)^{-1} \\;(P = W) \\quad\\text{or}\\quad
        A_K = K G^T (G K G^T)^{-1} \\;(P = K^{-1}),

    in the solver form ``min 1/2 F^T P F + g^T F`` with ``g = -P F_pref``. ``W`` is diagonal:
    ``W_i = diag(force_weight I, moment_weight I) / share_i``; ``E`` is the virtual-linkage basis of
    :func:`~coopctrl.load_distribution.grasp_matrix.internal_force_basis`.

    The rows of ``C`` are grouped in families; ``rows[name]`` is the slice of each:

    - ``"min_grip"`` (m rows): ``n_i^T f_i >= f_min`` [N], ``n_i`` the unit inward contact normal.
    - ``"friction"`` (N_f rows per contact, N_f = ``friction_facets`` spatial, 2 planar): the
      pyramid inscribed in the Coulomb cone,
      ``(cos(phi_k) t_1 + sin(phi_k) t_2 - mu cos(pi/N_f) n_i)^T f_i <= 0``,
      ``phi_k = 2 pi k / N_f``, ``(t_1, t_2, n_i)`` orthonormal; planar: ``(+-t - mu n_i)^T f_i <= 0``,
      ``t = (-n_z, n_x)``. Its vertices lie on the cone, so it is conservative. Only forces are
      constrained (the grasp is fixed, contact moments are free).
    - ``"torque_limits"`` (n_i rows per arm): ``-tau_max_i - bias_i <= J_i^T F_i <= tau_max_i - bias_i``
      [N m], with ``tau_i = J_i^T F_i + bias_i`` the joint torques arm i needs.

    All arrays are allocated once (the torque rows once the joint counts are known) and filled in
    place by :meth:`update`, so that a solver can take them without copies. The rows are written by
    the C++ core's assembly (``coopctrl._core``, coopctrl/core/qp_assembly.h), the one definition of each
    family, which the compiled tick calls too: ``update`` checks its inputs and calls them.
    """

    def __init__(self, config: LoadDistributionConfig, space: str, m: int):
        self.config = config
        self.space = space
        self.k = k = wrench_dim(space)
        self.p = p = POSITION_DIM[space]
        if isinstance(m, bool) or not isinstance(m, int) or m < 1:
            raise ScenarioError("m", m, "an integer number of arms >= 1")
        self.m = m
        self.n = n = k * m
        self.pairs = contact_pairs(m)
        npairs = len(self.pairs)
        # preferred shares and weights
        shares = config.shares if config.shares is not None else (1.0,) * m
        if len(shares) != m:
            raise ScenarioError("shares", config.shares, f"None or a tuple of {m} positive weights (one per arm)")
        per_contact = np.array([config.force_weight] * p + [config.moment_weight] * (k - p))
        self.W_diag = np.concatenate([per_contact / s for s in shares])  # diag of W
        self.W_inv_diag = 1.0 / self.W_diag
        self._minus_W_diag = -self.W_diag
        # desired squeeze
        sq = config.squeeze
        if isinstance(sq, float):
            self.s_des = np.full(npairs, sq)
        else:
            if len(sq) != npairs:
                raise ScenarioError("squeeze", sq, f"one number or {npairs} numbers (pairs i < j of {m} arms) [N]")
            self.s_des = np.array(sq, dtype=float)
        self.has_squeeze = bool(np.any(self.s_des != 0.0))
        self.elastic = config.split == "elastic"
        # equality: G F = w_N
        #: (k, n) the grasp matrix of the contacts at the object's centre (its rows until the first assembly)
        self.identity_grasp = identity_grasp_matrix(m, space)
        self.E = np.zeros((n, npairs))
        self.external = np.zeros(n)
        self.F_pref = np.zeros(n)
        self.P = np.diag(self.W_diag)
        self.P_changed = True
        self._K = None
        self.g = np.zeros(n)
        # inequality families
        self.families = config.inequality_families
        self.mu = config.friction_coefficient
        if space == "spatial":
            nf = config.friction_facets
            phi = 2.0 * math.pi * np.arange(nf) / nf
            #: the friction pyramid: its facets' directions cos, sin (spatial) and the friction coefficient of the
            #: pyramid inscribed in the cone, mu cos(pi / facets) (planar: mu) [-]
            self.cos_phi = np.cos(phi)
            self.sin_phi = np.sin(phi)
            self.mu_c = float(self.mu or 0.0) * math.cos(math.pi / nf)
            self.n_facets = int(nf)
        else:
            self.n_facets = 2
            self.cos_phi = self.sin_phi = np.zeros(1)  # unused (planar), as in the compiled tick
            self.mu_c = float(self.mu or 0.0)
        # scratch and inputs of the assembly functions (C-contiguous float64, as the compiled tick's)
        self._r = np.zeros((m, p))
        self._r0 = np.zeros(p)
        self._A = np.zeros((k, k))
        self._y = np.zeros(k)
        self.joint_counts: tuple[int, ...] | None = None
        self.rows: dict[str, slice] = {}
        self.allocate(())

    # ------------------------------------------------------------------ structure
    def allocate(self, joint_counts: tuple[int, ...]) -> None:
        """The inequality rows' layout (``rows``, ``n_in``) and the stacked arrays ``M``, ``lo``, ``hi`` for arms of
        ``joint_counts`` joints (the torque rows' count); the grasp rows are kept."""
        m, n = self.m, self.n
        rows, start = {}, 0
        if "min_grip" in self.families:
            rows["min_grip"] = slice(start, start + m)
            start += m
        if "friction" in self.families:
            rows["friction"] = slice(start, start + m * self.n_facets)
            start += m * self.n_facets
        if "torque_limits" in self.families:
            total = sum(joint_counts)
            rows["torque_limits"] = slice(start, start + total)
            start += total
        self.rows = rows
        self.n_in = start
        # one stacked matrix [G; C] and bounds [w; l], [w; u]: G, C, w, l, u are views into them,
        # so that the feasibility check of an answer is one product and two reductions
        G_old = getattr(self, "G", self.identity_grasp)
        self.M = np.zeros((self.k + start, n))
        self.M[:self.k] = G_old
        self.lo = np.full(self.k + start, -np.inf)
        self.hi = np.full(self.k + start, np.inf)
        self.G, self.C = self.M[:self.k], self.M[self.k:]
        self.w, self.l, self.u = self.lo[:self.k], self.lo[self.k:], self.hi[self.k:]
        self.lo[:self.k] = 0.0
        self.hi[:self.k] = 0.0
        if "min_grip" in rows:
            self.l[rows["min_grip"]] = self.config.min_grip
        if "friction" in rows:
            self.u[rows["friction"]] = 0.0
        self.joint_counts = joint_counts
        total = sum(joint_counts)
        self._tau = np.zeros(total)  # tau_max stacked over the arms' joints [N m]
        self._bias = np.zeros(total)  # the biases stacked [N m]
        self._Jg = np.zeros((m, self.k, max(joint_counts, default=1)))  # Jg[i, :, :n_i] = J_i
        self._dofs = np.array(joint_counts, dtype=np.int64)
        self.structure_changed = True

    @property
    def dims(self) -> tuple[int, int, int]:
        """``(n, n_eq, n_in)``: variables, equality rows, inequality rows."""
        return self.n, self.k, self.n_in

    # ------------------------------------------------------------------ per step
    def update(self, r_contacts, r_object, w_N, normals=None, jacobians=None, biases=None, tau_max=None, K=None):
        """Fill every array of the QP for one step (arguments as in ``LoadDistribution.solve``)."""
        from coopctrl import _core as asm  # the C++ assembly (coopctrl/core/qp_assembly.h)

        k, p, m, n = self.k, self.p, self.m, self.n
        r = np.asarray(r_contacts, dtype=float)
        r0 = np.asarray(r_object, dtype=float)
        if r.shape != (m, p):
            raise ScenarioError("r_contacts", r.shape, f"an array of shape ({m}, {p}) [m]")
        if r0.shape != (p,):
            raise ScenarioError("r_object", r0.shape, f"an array of shape ({p},) [m]")
        self._r[:] = r
        self._r0[:] = r0
        r, r0 = self._r, self._r0
        spatial = self.space == "spatial"
        w = self.w
        w[:] = w_N  # raises on a wrong shape
        self.hi[:k] = w
        asm.fill_grasp_rows(self.M, r, r0, spatial)
        G = self.G
        # external part A w_N
        if self.elastic:
            if K is None:
                raise ScenarioError("K", None, f"the grasp stiffness matrix ({n} x {n}) when split='elastic'")
            K = np.asarray(K, dtype=float)
            if K.shape != (n, n):
                raise ScenarioError("K", K.shape, f"an array of shape ({n}, {n})")
            # any K here; the compiled tick's fill_elastic_split (coopctrl/core/qp_elastic_assembly.h) builds a
            # block-diagonal K from the object-frame stiffnesses and exploits its blocks
            KGt = K @ G.T
            y = _spd_solve(G @ KGt, w)
            np.matmul(KGt, y, out=self.external)
            if self._K is None or not np.array_equal(K, self._K):
                self._K = K.copy()
                self.P = np.linalg.inv(K)
                self.P = 0.5 * (self.P + self.P.T)
                self.P_changed = True
        elif not asm.pseudo_inverse_external(self.M, k, self.W_inv_diag, w, self.external, self._A, self._y):
            raise _degenerate_grasp()
        if self.has_squeeze:
            if not asm.fill_squeeze_basis(self.E, r, k):
                raise ScenarioError("r_contacts", closest_pair(r), "distinct contact points (pair coincides)")
            np.add(self.external, self.E @ self.s_des, out=self.F_pref)
        else:
            self.F_pref[:] = self.external
        if self.elastic:
            np.matmul(self.P, self.F_pref, out=self.g)
            np.negative(self.g, out=self.g)
        else:
            np.multiply(self._minus_W_diag, self.F_pref, out=self.g)
        if not self.families:
            return
        rows = self.rows
        if "min_grip" in rows or "friction" in rows:
            if normals is None:
                raise ScenarioError("normals", None, f"inward contact normals, shape ({m}, {p}), for min_grip/friction")
            nrm = np.asarray(normals, dtype=float)
            if nrm.shape != (m, p):
                raise ScenarioError("normals", nrm.shape, f"an array of shape ({m}, {p})")
            length = np.sqrt(np.einsum("ij,ij->i", nrm, nrm))
            if np.any(length < 1e-12):
                raise ScenarioError("normals", normals, "non-zero contact normals")
            nrm = nrm / length[:, None]  # a new C-contiguous array
        if "min_grip" in rows:
            asm.fill_grip_rows(self.M, k + rows["min_grip"].start, nrm, k)
        if "friction" in rows:
            asm.fill_friction_rows(self.M, k + rows["friction"].start, nrm, k, self.n_facets, self.mu_c,
                                   self.cos_phi, self.sin_phi, spatial)
        if "torque_limits" in rows:
            if jacobians is None or tau_max is None:
                raise ScenarioError("jacobians", jacobians, "per-arm J_i and tau_max when torque_limits=True")
            if len(jacobians) != m:
                raise ScenarioError("jacobians", len(jacobians), f"{m} Jacobians ({k} x n_i each)")
            try:
                counts = tuple(J.shape[1] for J in jacobians)
                ok = all(J.ndim == 2 and J.shape[0] == k for J in jacobians)
            except AttributeError:
                ok = False
            if not ok:
                for i, J in enumerate(jacobians):
                    if np.ndim(J) != 2 or np.shape(J)[0] != k:
                        raise ScenarioError(f"jacobians[{i}]", np.shape(J), f"an array of shape ({k}, n_i)")
                jacobians = [np.asarray(J, dtype=float) for J in jacobians]
                counts = tuple(J.shape[1] for J in jacobians)
            if counts != self.joint_counts:
                self.allocate(counts)
                return self.update(r, r0, w_N, normals, jacobians, biases, tau_max, K)
            Jg = self._Jg
            for i, J in enumerate(jacobians):
                Jg[i, :, :counts[i]] = J
            tau = self._tau
            if isinstance(tau_max, (int, float, np.number)) or (isinstance(tau_max, np.ndarray) and tau_max.ndim == 0):
                tau[:] = tau_max  # (np.ndim of a list of arms with different joint counts raises)
            else:
                if len(tau_max) != m:
                    raise ScenarioError("tau_max", tau_max, f"one number, or {m} per-arm limits [N m]")
                _stack(tau, tau_max, counts)
            bias = self._bias
            if biases is None:
                bias[:] = 0.0
            else:
                if len(biases) != m or any(np.shape(b) != (counts[i],) for i, b in enumerate(biases)):
                    raise ScenarioError("biases", biases, f"None or {m} per-arm bias torques of {counts} joints [N m]")
                _stack(bias, biases, counts)
            asm.fill_torque_rows(self.M, self.lo, self.hi, k + rows["torque_limits"].start, Jg, self._dofs, k, tau, bias)

    # ------------------------------------------------------------------ checks
    def violations(self, F: np.ndarray) -> dict[str, float]:
        """Largest violation per family for the stacked wrenches ``F``: ``"balance"`` is
        ``max |G F - w_N|`` [N, N m]; the inequality families give ``max(l - C F, C F - u, 0)``."""
        out = {"balance": float(np.max(np.abs(self.G @ F - self.w)))}
        if self.n_in:
            CF = self.C @ F
            viol = np.maximum(self.l - CF, CF - self.u)
            for name, sl in self.rows.items():
                out[name] = max(0.0, float(np.max(viol[sl]))) if sl.stop > sl.start else 0.0
        return out

    def max_violation(self, F: np.ndarray) -> tuple[float, float]:
        """``(violation, scale)``: the largest violation of ``G F = w_N`` and ``l <= C F <= u``
        together, and ``max(|G F|, |C F|)``, the size a tolerance is relative to: the C++ core's
        ``answer_violation`` (coopctrl/core/qp_answer_check.h), the loop's own."""
        from coopctrl._core import answer_violation

        F = np.ascontiguousarray(F, dtype=float)
        if F.shape != (self.n,):
            raise ValueError(f"F: shape {F.shape}; expected ({self.n},), the stacked contact wrenches [N, N m]")
        viol, scale = answer_violation(self.M, self.lo, self.hi, F, self.n)
        return float(viol), float(scale)

    def objective(self, F: np.ndarray) -> float:
        """``1/2 (F - F_pref)^T P (F - F_pref)``."""
        d = F - self.F_pref
        return 0.5 * float(d @ (self.P @ d))
