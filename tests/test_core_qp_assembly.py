"""coopctrl/core/qp_* (the compiled core's load-distribution QP assembly and checks, coopctrl._core) on seeded random
inputs, planar and spatial, 1 to 4 arms, including the failure returns, against independent references: the rows'
statements in Python (min grip, friction pyramid, torque limits; the grasp rows and the squeeze basis are checked
against the analytic grasp in tests/test_load_distribution_assembly.py), the answer check's statement in numpy,
numpy's dense algebra for the solves (to rounding: LAPACK's order of operations differs); and the arguments
checked once at the binding. (Each kernel was checked bit for bit against the numba kernel it replaced when it was
ported; the golden records lock the loop's numbers since.)"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.load_distribution.answer_check import FAMILY_FRICTION, FAMILY_MIN_GRIP, FAMILY_TORQUE
from coopctrl.loop import model as loop_model
from plants.frames import body_rate_map, rotation_zyx

SPACES = ("planar", "spatial")


def _dims(space):
    """``(spatial, k, npos)``: wrench entries per contact and position entries."""
    return (True, 6, 3) if space == "spatial" else (False, 3, 2)


def _grasp_rows(rng, space, m):
    """A stacked ``M`` with the balance rows of ``m`` random contacts (identity blocks and moment arms)."""
    spatial, k, npos = _dims(space)
    r = rng.normal(size=(m, npos)) * 0.4
    r0 = rng.normal(size=npos) * 0.1
    M = np.zeros((k + 4 * m, k * m))
    for i in range(m):
        M[:k, k * i:k * i + k] = np.eye(k)
    _core.fill_grasp_rows(M, r, r0, spatial)
    return M, r, r0


# ---------------------------------------------------------------------------- the rows' statements
def grip_rows(M, row0, nrm, k):
    """``min_grip`` rows: row ``row0 + i`` holds the unit normal ``n_i`` on arm i's force entries."""
    for i in range(nrm.shape[0]):
        M[row0 + i, k * i:k * i + nrm.shape[1]] = nrm[i]


def friction_rows(M, row0, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial):
    """``friction`` rows (``nf`` per contact): ``(cos phi t_1 + sin phi t_2 - mu_c n)^T f <= 0`` spatial, with
    ``t_1`` the unit part of ``e_x`` (or ``e_y`` where ``|n_x| >= 0.9``) normal to ``n`` and ``t_2 = n x t_1``;
    ``(+-t - mu_c n)^T f <= 0`` planar, ``t = (-n_z, n_x)``."""
    for i in range(nrm.shape[0]):
        n = nrm[i]
        if spatial:
            e = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            t1 = e - (e @ n) * n
            t1 /= np.linalg.norm(t1)
            t2 = np.cross(n, t1)
            for f in range(nf):
                M[row0 + nf * i + f, k * i:k * i + 3] = cos_phi[f] * t1 + sin_phi[f] * t2 - mu_c * n
        else:
            t = np.array([-n[1], n[0]])
            M[row0 + 2 * i, k * i:k * i + 2] = t - mu_c * n
            M[row0 + 2 * i + 1, k * i:k * i + 2] = -t - mu_c * n


def torque_rows(M, lo, hi, row0, Jg, dofs, k, tau_qp, bias):
    """``torque_limits`` rows: arm i's ``n_i`` rows hold ``J_i^T`` on its wrench entries, with
    ``lo = -tau_qp - bias``, ``hi = tau_qp - bias`` (stacked over the arms' joints) [N m]."""
    row, j = row0, 0
    for i, n in enumerate(dofs):
        M[row:row + n, k * i:k * i + k] = Jg[i, :, :n].T
        hi[row:row + n] = tau_qp[j:j + n] - bias[j:j + n]
        lo[row:row + n] = -tau_qp[j:j + n] - bias[j:j + n]
        row, j = row + n, j + n


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_row_fills_are_the_rows_statements(space, m):
    """fill_grip_rows, fill_friction_rows (normals near and far from the x axis: both branches of the tangent) and
    fill_torque_rows (arms of different joint counts) write their rows, and nothing else: the grip and torque rows
    exactly (copies and one subtraction), the pyramid's rows to 1e-15 (unit vectors: the tangent's normalisation
    rounds differently); the pyramid's facets are normal-ward (``f = n`` inside, by ``mu_c``)."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(300 + 10 * m + spatial)
    nf = 4 if spatial else 2
    cos_phi = np.cos(2 * np.pi * np.arange(nf) / nf) if spatial else np.zeros(1)
    sin_phi = np.sin(2 * np.pi * np.arange(nf) / nf) if spatial else np.zeros(1)
    dofs = rng.integers(k - 1 if spatial else 2, k + 2, size=m).astype(np.int64)
    for _ in range(10):
        rows = k + m + nf * m + int(dofs.sum())
        nrm = rng.normal(size=(m, npos))
        nrm[0, 0] = 5.0 * np.sign(nrm[0, 0])  # |n_x| > 0.9 after normalising: the other tangent branch
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        Jg = rng.normal(size=(m, k, int(dofs.max())))
        tau_qp = rng.uniform(1.0, 50.0, size=int(dofs.sum()))
        bias = rng.normal(size=int(dofs.sum())) * 10
        mu_c = float(rng.uniform(0.2, 1.0))
        Ma = rng.normal(size=(rows, k * m))
        loa, hia = rng.normal(size=rows), rng.normal(size=rows)
        Mb, lob, hib = Ma.copy(), loa.copy(), hia.copy()
        grip_rows(Ma, k, nrm, k)
        _core.fill_grip_rows(Mb, k, nrm, k)
        friction_rows(Ma, k + m, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial)
        _core.fill_friction_rows(Mb, k + m, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial)
        torque_rows(Ma, loa, hia, k + m + nf * m, Jg, dofs, k, tau_qp, bias)
        _core.fill_torque_rows(Mb, lob, hib, k + m + nf * m, Jg, dofs, k, tau_qp, bias)
        fric = slice(k + m, k + m + nf * m)
        np.testing.assert_allclose(Mb[fric], Ma[fric], rtol=0, atol=1e-15)
        Mb[fric] = Ma[fric]
        np.testing.assert_array_equal(Mb, Ma)  # every other entry, the untouched ones included
        np.testing.assert_array_equal(lob, loa)
        np.testing.assert_array_equal(hib, hia)
        for i in range(m):
            f = np.zeros(k * m)
            f[k * i:k * i + npos] = nrm[i]
            assert np.all(Mb[k + m + nf * i:k + m + nf * (i + 1)] @ f == pytest.approx(-mu_c, abs=1e-15))


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_pseudo_inverse_and_squeeze_basis_against_numpy(space, m):
    """The pseudo-inverse split against numpy, ``W^-1 G^T (G W^-1 G^T)^-1 w`` within 1e-12 relative (both are
    backward stable on these well-conditioned k x k systems, condition numbers below 1e3: a few ulps times that),
    and ``G E = 0`` (the squeeze is internal); coincident contacts and a rank-deficient ``G`` give False."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(400 + 10 * m + spatial)
    for trial in range(10):
        M, r, r0 = _grasp_rows(rng, space, m)
        n = k * m
        W_inv = rng.uniform(0.2, 2.0, size=n)
        w = rng.normal(size=k) * 20
        ext = np.zeros(n)
        assert _core.pseudo_inverse_external(M, k, W_inv, w, ext, np.zeros((k, k)), np.zeros(k)) is True
        G = M[:k]
        want = W_inv * (G.T @ np.linalg.solve((G * W_inv) @ G.T, w))
        np.testing.assert_allclose(ext, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
        npairs = m * (m - 1) // 2
        E = np.zeros((n, npairs))
        if trial == 9 and m > 1:
            r[m - 1] = r[0]
        ok = _core.fill_squeeze_basis(E, r, k)
        assert ok == (trial != 9 or m == 1)
        if ok and npairs:
            Mr, _, _ = _grasp_rows(np.random.default_rng(0), space, m)
            _core.fill_grasp_rows(Mr, r, r0, spatial)
            assert np.abs(Mr[:k] @ E).max() <= 1e-14
            np.testing.assert_allclose(np.linalg.norm(E, axis=0), np.sqrt(2.0), rtol=1e-15)  # unit +-t_ij per pair
    # zero weights: G W^-1 G^T = 0 is not positive definite
    M, _, _ = _grasp_rows(rng, space, m)
    assert not _core.pseudo_inverse_external(M, k, np.zeros(k * m), np.ones(k), np.zeros(k * m), np.zeros((k, k)),
                                             np.zeros(k))


def _random_answer(rng, rows, n, k):
    M = rng.normal(size=(rows, n))
    x = rng.normal(size=n) * 3
    y = M @ x
    lo = y - rng.uniform(-1e-7, 1.0, size=rows)
    hi = y + rng.uniform(-1e-7, 1.0, size=rows)
    lo[:k] = hi[:k] = y[:k] + rng.normal(size=k) * 1e-8
    lo[rng.random(rows) < 0.3] = -np.inf
    hi[rng.random(rows) < 0.3] = np.inf
    lo[:k] = hi[:k]
    return M, lo, hi, x


# ---------------------------------------------------------------------------- the answer check's statement
def violation(M, lo, hi, x, n):
    """``(v, s)``: the largest violation of ``lo <= M x <= hi`` and ``s = max |M x|`` (answer_check's docstring)."""
    y = M[:, :n] @ x[:n]
    return (float(np.max(np.maximum(lo - y, y - hi))) if len(y) else -math.inf,
            float(np.max(np.abs(y))) if len(y) else 0.0)


def tolerance(lo, hi, k, viol, scale, eps_abs, rho):
    """``min(100 eps_abs (1 + s), rho L)``, the cap evaluated only when ``v > min(100 eps_abs (1 + s), rho)``;
    ``L = max(1, |w_N|, finite |l|, finite |u|)`` (``l``, ``u`` the inequality rows' bounds)."""
    tol = 100.0 * eps_abs * (1.0 + scale)
    if not viol <= min(tol, rho):
        finite = [abs(v) for v in (*lo[k:], *hi[k:]) if math.isfinite(v)]  # the balance rows' load as it is
        tol = min(tol, rho * max([1.0, *np.abs(lo[:k]), *finite]))
    return tol


def families(g, z, z0, n, n_in, m, row_grip, row_fric, n_fric, row_tau):
    """The mask of the families with a multiplier ``|z_r| > 1e-7 (1 + |g|_inf)`` among the ``n_in`` inequality rows
    from ``z[z0]`` (-1: a family is off)."""
    if n_in <= 0:
        return 0
    thr = 1e-7 * (1.0 + np.abs(g[:n]).max())
    mask = 0
    for r in np.flatnonzero(np.abs(z[z0:z0 + n_in]) > thr):
        if row_grip >= 0 and row_grip <= r < row_grip + m:
            mask |= FAMILY_MIN_GRIP
        elif row_fric >= 0 and row_fric <= r < row_fric + m * n_fric:
            mask |= FAMILY_FRICTION
        elif row_tau >= 0 and r >= row_tau:
            mask |= FAMILY_TORQUE
    return mask


def test_answer_check_is_its_statement():
    """answer_violation, answer_tolerance, answer_ok (accepted and refused answers, the load cap in play, a NaN
    answer) and binding_families (every family on or off, both z offsets) on 400 seeded problems against the numpy
    statement: the violation and scale to 1e-13 relative (sums in another order), the tolerance exactly on the same
    arguments, the verdict wherever the violation is not within rounding of the tolerance, the mask exactly."""
    rng = np.random.default_rng(500)
    verdicts = set()
    masks = set()
    for trial in range(400):
        n, k = int(rng.integers(3, 19)), int(rng.integers(0, 7))
        rows = k + int(rng.integers(0, 25))
        k = min(k, rows)
        M, lo, hi, x = _random_answer(rng, rows, n, k)
        if trial % 50 == 7:
            x[0] = np.nan
        eps_abs, rho = 10.0 ** rng.uniform(-12, -6), 10.0 ** rng.uniform(-9, -3)
        viol, scale = _core.answer_violation(M, lo, hi, x, n)
        want_viol, want_scale = violation(M, lo, hi, x, n)
        if np.isfinite(x).all():
            assert scale == pytest.approx(want_scale, rel=1e-13, abs=1e-300)
            assert viol == pytest.approx(want_viol, rel=1e-13, abs=1e-13 * (1 + scale))
        tol = _core.answer_tolerance(lo, hi, k, viol, scale, eps_abs, rho)
        assert tol == tolerance(lo, hi, k, viol, scale, eps_abs, rho)
        verdict = _core.answer_ok(M, lo, hi, x, n, k, eps_abs, rho)
        if not np.isfinite(x).all():
            assert verdict is False
        elif abs(viol - tol) > 1e-12 * (1 + scale):
            assert verdict == (viol <= tol)
        verdicts.add(verdict)
        m = int(rng.integers(1, 5))
        n_fric = int(rng.integers(2, 5))
        n_in = m + m * n_fric + int(rng.integers(0, 8))
        z = rng.normal(size=k + n_in) * (rng.random(k + n_in) < 0.3)
        g = rng.normal(size=n)
        on = rng.random(3) < 0.7
        row_grip = 0 if on[0] else -1
        row_fric = (m if on[0] else 0) if on[1] else -1
        row_tau = (m if on[0] else 0) + (m * n_fric if on[1] else 0) if on[2] else -1
        for z0 in (0, k):
            args = (g, z, z0, n, min(n_in, z.shape[0] - z0), m, row_grip, row_fric, n_fric, row_tau)
            mask = _core.binding_families(*args)
            assert mask == families(*args)
            masks.add(mask)
    assert verdicts == {True, False}
    assert len(masks) >= 6


def _control_terms(rng, spatial, m, redundant):
    """Seeded random control terms of m arms (ControlTerms's shapes): square, redundant (n_i > p) and contact
    point arms; one square arm with a singular Jacobian (ddq = 0 branch)."""
    p = 6 if spatial else 3
    dof = np.array([p + (redundant and i % 2 == 0) for i in range(m)], dtype=np.int64)
    kind = np.zeros(m, dtype=np.int64)
    if m > 2:
        kind[m - 1] = 1
        dof[m - 1] = p
    nmax = int(max(p, dof.max()))
    Y = rng.uniform(-2, 2, size=(m + 1, p))
    ddYn = rng.normal(size=(m + 1, p))
    A = rng.normal(size=(m + 1, p, p))
    W = np.einsum("kab,kcb->kac", A, A) + np.eye(p)
    w_free = rng.normal(size=(m + 1, p)) * 5
    B = rng.normal(size=(m, nmax, nmax))
    H = np.einsum("kab,kcb->kac", B, B) + 0.5 * np.eye(nmax)
    h = rng.normal(size=(m, nmax))
    J = rng.normal(size=(m, p, nmax))
    if m > 1 and dof[1] == p:
        J[1, :, 1] = J[1, :, 0]  # singular square Jacobian
    Jdq = rng.normal(size=(m, p))
    return Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, nmax


def _torque_work(m, p, nmax, total):
    """``(Jg, bias, Wa, rhs_t, qdd, piv, wv, wm, R3)`` of torque_model_into (wv, wm: control_work's shapes)."""
    return [np.zeros((m, p, nmax)), np.zeros(total), np.zeros(p), np.zeros(p), np.zeros(nmax),
            np.zeros(nmax, np.int64), np.zeros((_core.WORK_VECTORS, nmax)),
            np.zeros((_core.WORK_MATRICES, nmax, nmax)), np.zeros((4, 3, 3))]


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3, 4])
@pytest.mark.parametrize("redundant", [False, True])
def test_contact_model_against_its_statement(space, m, redundant):
    """contact_normals_into: ``R(A_k) e_x`` (spatial), ``(cos th_k, sin th_k)`` (planar), unit, to 1e-15;
    torque_model_into's node map ``Jg_i``: ``J_i`` with the angular rows ``R(A_k) L(A_k) J_i[3:]`` (spatial) to
    1e-13 relative, the identity for a contact point, whose bias is ``W_k ddYn_k + w_free_k``; a singular square
    arm's joint acceleration is zero (bias ``h_i + J_i^T (W_k ddYn_k + w_free_k)``). (The bias of regular square and
    redundant arms: test_torque_model_against_numpy.)"""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(600 + 10 * m + 2 * spatial + redundant)
    for _ in range(8):
        Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, nmax = _control_terms(rng, spatial, m, redundant)
        nrm = np.zeros((m, npos))
        _core.contact_normals_into(Y, spatial, nrm, np.zeros((3, 3)))
        for i in range(m):
            A = Y[i + 1, 3:6] if spatial else Y[i + 1, 2]
            want = rotation_zyx(A)[:, 0] if spatial else np.array([np.cos(A), np.sin(A)])
            np.testing.assert_allclose(nrm[i], want / np.linalg.norm(want), rtol=0, atol=1e-15)
        work = _torque_work(m, k, nmax, int(dof.sum()))
        _core.torque_model_into(spatial, Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, *work)
        Jg, bias = work[0], work[1]
        j0 = 0
        for i in range(m):
            ni, kk = int(dof[i]), i + 1
            wrench = W[kk] @ ddYn[kk] + w_free[kk]
            if kind[i] != 0:
                np.testing.assert_array_equal(Jg[i, :, :k], np.eye(k))
                np.testing.assert_allclose(bias[j0:j0 + ni], wrench, rtol=1e-13, atol=1e-13 * np.abs(wrench).max())
            else:
                want = J[i, :, :ni].copy()
                if spatial:
                    A = Y[kk, 3:6]
                    want[3:] = rotation_zyx(A) @ body_rate_map(A) @ J[i, 3:, :ni]
                np.testing.assert_allclose(Jg[i, :, :ni], want, rtol=0, atol=1e-13 * np.abs(want).max())
                if ni == k and np.linalg.matrix_rank(J[i, :, :ni]) < k:  # the singular arm: ddq = 0
                    want_bias = h[i, :ni] + J[i, :, :ni].T @ wrench
                    np.testing.assert_allclose(bias[j0:j0 + ni], want_bias, rtol=1e-12,
                                               atol=1e-12 * np.abs(want_bias).max())
            j0 += ni


@pytest.mark.parametrize("space", SPACES)
def test_torque_model_against_numpy(space):
    """The redundant arm's ddq = J^# (ddYn - Jdq) with J^# = N^-1 J^T (J N^-1 J^T)^-1, N = H + J^T W J, and the
    square arm's J^-1 (ddYn - Jdq), computed with numpy: the bias H ddq + h + J^T (W ddYn + w_free) within 1e-9
    relative (LU solves of systems with condition numbers up to about 1e4 here, LAPACK's rounding differs)."""
    spatial, k, _ = _dims(space)
    rng = np.random.default_rng(700 + spatial)
    m = 2
    for _ in range(10):
        Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, nmax = _control_terms(rng, spatial, m, True)
        J[1] = rng.normal(size=(k, nmax))  # a regular square arm
        work = _torque_work(m, k, nmax, int(dof.sum()))
        _core.torque_model_into(spatial, Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, *work)
        bias = work[1]
        j0 = 0
        for i in range(m):
            ni, kk = int(dof[i]), i + 1
            Ji, Hi = J[i, :, :ni], H[i, :ni, :ni]
            rhs = ddYn[kk] - Jdq[i]
            if ni == k:
                qdd = np.linalg.solve(Ji, rhs)
            else:
                N = Hi + Ji.T @ W[kk] @ Ji
                X = np.linalg.solve(N, Ji.T)
                qdd = X @ np.linalg.solve(Ji @ X, rhs)
            want = Hi @ qdd + h[i, :ni] + Ji.T @ (W[kk] @ ddYn[kk] + w_free[kk])
            np.testing.assert_allclose(bias[j0:j0 + ni], want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
            j0 += ni


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_pair_tensions_are_the_pseudo_inverse(space, m):
    """pair_tensions_into on the squeeze basis (P <= R) and on its transpose-shaped columns (P > R): against numpy's
    pinv, s = s_des + E^+ (f - E s_des) within 1e-9 relative (an SVD to rounding of |E| on columns of condition number
    below about 10); every case here is well conditioned, so none is NaN."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(800 + 10 * m + spatial)
    P = m * (m - 1) // 2
    for trial in range(10):
        r = rng.normal(size=(m, npos))
        E = np.zeros((k * m, P))
        assert _core.fill_squeeze_basis(E, r, k)
        Ef = np.ascontiguousarray(E[np.arange(k * m) % k < npos])  # the force rows (R = npos m)
        if trial >= 7:  # P > R: random wide columns
            Ef = rng.normal(size=(2, 5))
        R_, P_ = Ef.shape
        npos_ = npos if trial < 7 else 1
        F = rng.normal(size=(R_ // npos_, npos_)) * 10
        desired = rng.uniform(0, 20, size=P_)
        rows, cols = (R_, P_) if P_ <= R_ else (P_, R_)
        s = np.zeros(P_)
        _core.pair_tensions_into(Ef, F, npos_, desired, np.zeros((rows, cols)), np.zeros((cols, cols)), np.zeros(cols),
                                 s)
        want = desired + np.linalg.pinv(Ef) @ (F.ravel() - Ef @ desired)
        np.testing.assert_allclose(s, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3])
def test_elastic_split_against_numpy(space, m):
    """fill_elastic_split along a sequence of poses and stiffnesses (a singular block): against numpy, K the block
    diagonal of ``sym(R_b K_i R_b^T)`` (``R_b`` the object's rotation at Y0 on both halves; planar, the rotation by
    its angle) within 1e-12 relative, P = sym(K^-1) and external = K G^T (G K G^T)^-1 w within 1e-10 relative
    (well-conditioned blocks, condition below 1e3); P is redone only when K changes (a repeated call says so);
    a singular block gives -3."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(900 + 10 * m + spatial)
    n = k * m
    K, Pm, ext = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
    scratch = (np.zeros((n, k)), np.zeros((k, k)), np.zeros(k), np.zeros((k, k)), np.zeros((k, 2 * k)))
    codes = set()
    A = rng.normal(size=(m, k, k))
    K_obj = np.einsum("iab,icb->iac", A, A) + k * np.eye(k)
    for step in range(12):
        M, _, _ = _grasp_rows(rng, space, m)
        Y0 = rng.uniform(-1, 1, size=k)
        w = rng.normal(size=k) * 10
        if step % 4 == 3:
            A = rng.normal(size=(m, k, k))
            K_obj = np.einsum("iab,icb->iac", A, A) + k * np.eye(k)
        K_in = K_obj.copy()
        if step == 10:
            K_in[0] = 0.0  # a singular block
        code, changed = _core.fill_elastic_split(M, k, K_in, Y0, spatial, K, Pm, w, ext, *scratch)
        codes.add(code)
        assert changed  # a new pose: a new K
        if code != 0:
            continue
        Rb = np.zeros((k, k))
        if spatial:
            Rb[:3, :3] = Rb[3:, 3:] = rotation_zyx(Y0[3:6])
        else:
            Rb[:2, :2] = [[np.cos(Y0[2]), -np.sin(Y0[2])], [np.sin(Y0[2]), np.cos(Y0[2])]]
            Rb[2, 2] = 1.0
        want_K = np.zeros((n, n))
        for i in range(m):
            Ki = Rb @ K_in[i] @ Rb.T
            want_K[k * i:k * i + k, k * i:k * i + k] = 0.5 * (Ki + Ki.T)
        np.testing.assert_allclose(K, want_K, rtol=0, atol=1e-12 * np.abs(want_K).max())
        np.testing.assert_allclose(Pm, np.linalg.inv(K), rtol=0, atol=1e-10 * np.abs(np.linalg.inv(K)).max())
        G = M[:k]
        want = K @ G.T @ np.linalg.solve(G @ K @ G.T, w)
        np.testing.assert_allclose(ext, want, rtol=0, atol=1e-10 * np.abs(want).max())
        P_before = Pm.copy()
        assert tuple(_core.fill_elastic_split(M, k, K_in, Y0, spatial, K, Pm, w, ext, *scratch)) == (0, False)
        np.testing.assert_array_equal(Pm, P_before)
    assert 0 in codes and -3 in codes


def test_assembly_bindings_refuse_a_wrong_shape_naming_the_argument():
    with pytest.raises(ValueError, match=r"^M: expected at least \(6, 12\)"):
        _core.fill_grasp_rows(np.zeros((6, 6)), np.zeros((2, 3)), np.zeros(3), True)
    with pytest.raises(ValueError, match="^r: expected 2 columns"):
        _core.fill_grasp_rows(np.zeros((3, 6)), np.zeros((2, 3)), np.zeros(2), False)
    with pytest.raises(ValueError, match="^dofs: expected 0 to the columns of Jg"):
        _core.fill_torque_rows(np.zeros((20, 6)), np.zeros(20), np.zeros(20), 6, np.zeros((1, 6, 3)),
                               np.array([4]), 6, np.ones(4), np.zeros(4))
    with pytest.raises(ValueError, match=r"^W: expected shape \(3, 2\)"):
        _core.pair_tensions_into(np.zeros((3, 2)), np.zeros((3, 1)), 1, np.zeros(2), np.zeros((2, 2)),
                                 np.zeros((2, 2)), np.zeros(2), np.zeros(2))
    with pytest.raises(TypeError):  # an output must be float64 and C-contiguous: never a silent copy
        _core.fill_grip_rows(np.zeros((8, 6), order="F"), 3, np.ones((2, 2)), 3)


def test_qp_answer_check_reads_the_constants_by_name():
    """``qp_answer_check`` (the tick's check with a QPConstants' fields read by name) gives the verdict of the
    core's answer_ok and the mask of its binding_families called with the same constants as arguments (both checked
    against their statements above), on 200 seeded answers."""
    rng = np.random.default_rng(1000)
    seen = set()
    for trial in range(200):
        m, k, n_fric = int(rng.integers(1, 5)), 6, 4
        n = k * m
        n_in = m + m * n_fric + int(rng.integers(0, 6))
        M, lo, hi, x = _random_answer(rng, k + n_in, n, k)
        z = rng.normal(size=k + n_in) * (rng.random(k + n_in) < 0.3)
        g = rng.normal(size=n)
        eps_abs, answer_rho = 10.0 ** rng.uniform(-12, -6), 10.0 ** rng.uniform(-9, -3)
        min_grip_row, friction_row, torque_row = 0, m, m + m * n_fric
        constants = loop_model.QPConstants(
            W_diag=None, W_inv_diag=None, s_des=None, tau_qp=None, tau_max=None, cos_phi=None, sin_phi=None,
            eps_abs=eps_abs, mu_c=0.5, max_iter=100, min_grip=1.0, answer_rho=answer_rho, has_squeeze=True,
            min_grip_row=min_grip_row, friction_row=friction_row, torque_row=torque_row, facets=n_fric,
            max_consecutive_failures=3)
        ok = _core.answer_ok(M, lo, hi, x, n, k, eps_abs, answer_rho)
        fams = (_core.binding_families(g, z, k, n, n_in, m, min_grip_row, friction_row, n_fric, torque_row)
                if ok else 0)
        assert _core.qp_answer_check(M, lo, hi, g, x, z, k, m, constants) == (ok, fams)
        seen.add(ok)
    assert seen == {True, False}
