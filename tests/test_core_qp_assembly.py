"""coopctrl/core/qp_* (the compiled core's load-distribution QP assembly and checks, coopctrl._core): the same bits
as the numba kernels they port (coopctrl.load_distribution.assembly, contact_model, answer_check, tensions,
elastic_assembly) on seeded random inputs, planar and spatial, 1 to 4 arms, including the failure returns; numpy's
dense algebra as an independent oracle of the solves (to rounding: LAPACK's order of operations differs); and
the arguments checked once at the binding."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.load_distribution import answer_check, assembly, contact_model, elastic_assembly, tensions
from coopctrl.loop import model as loop_model

SPACES = ("planar", "spatial")


def _dims(space):
    """``(spatial, k, npos)``: wrench entries per contact and position entries."""
    return (True, 6, 3) if space == "spatial" else (False, 3, 2)


def _pair(shape_or_array):
    """Two equal arrays (one for the numba kernel, one for the core)."""
    a = np.array(shape_or_array, dtype=float) if not isinstance(shape_or_array, tuple) else np.zeros(shape_or_array)
    return a, a.copy()


def _grasp_rows(rng, space, m):
    """A stacked ``M`` with the balance rows of ``m`` random contacts (identity blocks and moment arms)."""
    spatial, k, npos = _dims(space)
    r = rng.normal(size=(m, npos)) * 0.4
    r0 = rng.normal(size=npos) * 0.1
    M = np.zeros((k + 4 * m, k * m))
    for i in range(m):
        M[:k, k * i:k * i + k] = np.eye(k)
    assembly.fill_grasp_rows(M, r, r0, spatial)
    return M, r, r0


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_row_fills_match_the_numba_kernels_bit_for_bit(space, m):
    """fill_grasp_rows, fill_grip_rows, fill_friction_rows (normals near and far from the x axis: both branches of
    the tangent) and fill_torque_rows (arms of different joint counts) write the same bits, and nothing else."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(300 + 10 * m + spatial)
    nf = 4 if spatial else 2
    cos_phi = np.cos(2 * np.pi * np.arange(nf) / nf) if spatial else np.zeros(1)
    sin_phi = np.sin(2 * np.pi * np.arange(nf) / nf) if spatial else np.zeros(1)
    dofs = rng.integers(k - 1 if spatial else 2, k + 2, size=m).astype(np.int64)
    for _ in range(10):
        rows = k + m + nf * m + int(dofs.sum())
        r = rng.normal(size=(m, npos))
        r0 = rng.normal(size=npos)
        nrm = rng.normal(size=(m, npos))
        nrm[0, 0] = 5.0 * np.sign(nrm[0, 0])  # |n_x| > 0.9 after normalising: the other tangent branch
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        Jg = rng.normal(size=(m, k, int(dofs.max())))
        tau_qp = rng.uniform(1.0, 50.0, size=int(dofs.sum()))
        bias = rng.normal(size=int(dofs.sum())) * 10
        mu_c = float(rng.uniform(0.2, 1.0))
        Ma, Mb = _pair(rng.normal(size=(rows, k * m)))
        loa, lob = _pair(rng.normal(size=rows))
        hia, hib = _pair(rng.normal(size=rows))
        assembly.fill_grasp_rows(Ma, r, r0, spatial)
        _core.fill_grasp_rows(Mb, r, r0, spatial)
        assembly.fill_grip_rows(Ma, k, nrm, k)
        _core.fill_grip_rows(Mb, k, nrm, k)
        assembly.fill_friction_rows(Ma, k + m, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial)
        _core.fill_friction_rows(Mb, k + m, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial)
        assembly.fill_torque_rows(Ma, loa, hia, k + m + nf * m, Jg, dofs, k, tau_qp, bias)
        _core.fill_torque_rows(Mb, lob, hib, k + m + nf * m, Jg, dofs, k, tau_qp, bias)
        np.testing.assert_array_equal(Mb, Ma)
        np.testing.assert_array_equal(lob, loa)
        np.testing.assert_array_equal(hib, hia)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_pseudo_inverse_and_squeeze_basis_match_the_numba_kernels_and_numpy(space, m):
    """The pseudo-inverse split and the squeeze basis: bit for bit against the kernels; against numpy,
    ``W^-1 G^T (G W^-1 G^T)^-1 w`` within 1e-12 relative (both are backward stable on these well-conditioned
    k x k systems, condition numbers below 1e3: a few ulps times that) and ``G E = 0`` (the squeeze is internal);
    coincident contacts and a rank-deficient ``G`` give False in both."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(400 + 10 * m + spatial)
    for trial in range(10):
        M, r, r0 = _grasp_rows(rng, space, m)
        n = k * m
        W_inv = rng.uniform(0.2, 2.0, size=n)
        w = rng.normal(size=k) * 20
        ext_a, ext_b = np.zeros(n), np.zeros(n)
        A_a, A_b, y_a, y_b = np.zeros((k, k)), np.zeros((k, k)), np.zeros(k), np.zeros(k)
        ok_a = assembly.pseudo_inverse_external(M, k, W_inv, w, ext_a, A_a, y_a)
        ok_b = _core.pseudo_inverse_external(M, k, W_inv, w, ext_b, A_b, y_b)
        assert ok_a is True and ok_b is True
        for got, want in ((ext_b, ext_a), (A_b, A_a), (y_b, y_a)):
            np.testing.assert_array_equal(got, want)
        G = M[:k]
        want = W_inv * (G.T @ np.linalg.solve((G * W_inv) @ G.T, w))
        np.testing.assert_allclose(ext_b, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
        npairs = m * (m - 1) // 2
        E_a, E_b = np.zeros((n, npairs)), np.zeros((n, npairs))
        if trial == 9 and m > 1:
            r[m - 1] = r[0]
        ok_a = assembly.fill_squeeze_basis(E_a, r, k)
        ok_b = _core.fill_squeeze_basis(E_b, r, k)
        assert ok_a == ok_b == (trial != 9 or m == 1)
        np.testing.assert_array_equal(E_b, E_a)
        if ok_b and npairs:
            Mr, _, _ = _grasp_rows(np.random.default_rng(0), space, m)
            assembly.fill_grasp_rows(Mr, r, r0, spatial)
            assert np.abs(Mr[:k] @ E_b).max() <= 1e-14
    # zero weights: G W^-1 G^T = 0 is not positive definite
    M, _, _ = _grasp_rows(rng, space, m)
    for fn in (assembly.pseudo_inverse_external, _core.pseudo_inverse_external):
        assert not fn(M, k, np.zeros(k * m), np.ones(k), np.zeros(k * m), np.zeros((k, k)), np.zeros(k))


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


def test_answer_check_matches_the_numba_kernels_bit_for_bit():
    """answer_violation, answer_tolerance, answer_ok (accepted and refused answers, the load cap in play, a
    NaN answer) and binding_families (every family on or off, both z offsets) on 400 seeded problems."""
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
        assert _core.answer_violation(M, lo, hi, x, n) == answer_check.answer_violation(M, lo, hi, x, n)
        viol, scale = answer_check.answer_violation(M, lo, hi, x, n)
        assert (_core.answer_tolerance(lo, hi, k, viol, scale, eps_abs, rho)
                == answer_check.answer_tolerance(lo, hi, k, viol, scale, eps_abs, rho))
        verdict = answer_check.answer_ok(M, lo, hi, x, n, k, eps_abs, rho)
        assert _core.answer_ok(M, lo, hi, x, n, k, eps_abs, rho) == verdict
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
            mask = answer_check.binding_families(*args)
            assert _core.binding_families(*args) == mask
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
def test_contact_model_matches_the_numba_kernels_bit_for_bit(space, m, redundant):
    """contact_normals_into and torque_model_into (square, redundant, contact-point and singular arms): the same
    bits in every output and scratch array."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(600 + 10 * m + 2 * spatial + redundant)
    for _ in range(8):
        Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof, nmax = _control_terms(rng, spatial, m, redundant)
        na, nb = np.zeros((m, npos)), np.zeros((m, npos))
        contact_model.contact_normals_into(Y, spatial, na, np.zeros((3, 3)))
        _core.contact_normals_into(Y, spatial, nb, np.zeros((3, 3)))
        np.testing.assert_array_equal(nb, na)
        terms = (Y, ddYn, W, w_free, H, h, J, Jdq, kind, dof)
        wa = _torque_work(m, k, nmax, int(dof.sum()))
        wb = _torque_work(m, k, nmax, int(dof.sum()))
        contact_model.torque_model_into(spatial, *terms, *wa)
        _core.torque_model_into(spatial, *terms, *wb)
        for got, want in zip(wb, wa):
            np.testing.assert_array_equal(got, want)


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
def test_pair_tensions_match_the_numba_kernel_and_the_pseudo_inverse(space, m):
    """pair_tensions_into on the squeeze basis (P <= R) and on its transpose-shaped columns (P > R), and with two
    dependent columns (NaN or dropped): bit for bit; against numpy's pinv, s = s_des + E^+ (f - E s_des) within
    1e-9 relative (an SVD to rounding of |E| on columns of condition number below about 10)."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(800 + 10 * m + spatial)
    P = m * (m - 1) // 2
    for trial in range(10):
        r = rng.normal(size=(m, npos))
        E = np.zeros((k * m, P))
        assert assembly.fill_squeeze_basis(E, r, k)
        Ef = np.ascontiguousarray(E[np.arange(k * m) % k < npos])  # the force rows (R = npos m)
        if trial >= 7:  # P > R: random wide columns
            Ef = rng.normal(size=(2, 5))
        R_, P_ = Ef.shape
        npos_ = npos if trial < 7 else 1
        F = rng.normal(size=(R_ // npos_, npos_)) * 10
        desired = rng.uniform(0, 20, size=P_)
        out = []
        for fn in (tensions.pair_tensions_into, _core.pair_tensions_into):
            W, V, sigma = tensions.tension_work(R_, P_)
            s = np.zeros(P_)
            fn(Ef, F, npos_, desired, W, V, sigma, s)
            out.append((s, W, V, sigma))
        for got, want in zip(out[1], out[0]):
            np.testing.assert_array_equal(got, want)
        s = out[1][0]
        if np.all(np.isfinite(s)):
            want = desired + np.linalg.pinv(Ef) @ (F.ravel() - Ef @ desired)
            np.testing.assert_allclose(s, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [1, 2, 3])
def test_elastic_split_matches_the_numba_kernel_and_numpy(space, m):
    """fill_elastic_split along a sequence of poses and stiffnesses (P redone only when K changes; a singular
    block; a degenerate grasp): the same code, P_changed and bits; against numpy, P = sym(K^-1) and
    external = K G^T (G K G^T)^-1 w within 1e-10 relative (well-conditioned blocks, condition below 1e3)."""
    spatial, k, npos = _dims(space)
    rng = np.random.default_rng(900 + 10 * m + spatial)
    n = k * m
    arrays = [[np.zeros((n, n)), np.zeros((n, n)), np.zeros(n), np.zeros((n, k)), np.zeros((k, k)), np.zeros(k),
               np.zeros((k, k)), np.zeros((k, 2 * k))] for _ in range(2)]
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
        results = []
        for fn, (K, Pm, ext, KGt, Ak, y, Rb, work) in zip(
                (elastic_assembly.fill_elastic_split, _core.fill_elastic_split), arrays):
            results.append(fn(M, k, K_in, Y0, spatial, K, Pm, w, ext, KGt, Ak, y, Rb, work))
        assert tuple(results[1]) == tuple(results[0])
        codes.add(results[0][0])
        for got, want in zip(arrays[1], arrays[0]):
            np.testing.assert_array_equal(got, want)
        if results[0][0] == 0:
            K, Pm, ext = arrays[1][0], arrays[1][1], arrays[1][2]
            np.testing.assert_allclose(Pm, np.linalg.inv(K), rtol=0, atol=1e-10 * np.abs(np.linalg.inv(K)).max())
            G = M[:k]
            want = K @ G.T @ np.linalg.solve(G @ K @ G.T, w)
            np.testing.assert_allclose(ext, want, rtol=0, atol=1e-10 * np.abs(want).max())
    assert 0 in codes and -3 in codes


def test_qp_constants_are_named_as_the_loop_names_them():
    """The core's QPNumbers and QPRows fields are the loop's names of ``QPConstants.numbers`` and ``.rows``, in
    the same order (the core reads a packed row by these names)."""
    assert _core.QP_NUMBERS_FIELDS == loop_model.QP_NUMBERS_FIELDS
    assert _core.QP_ROWS_FIELDS == loop_model.QP_ROWS_FIELDS


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
    """``qp_answer_check`` (the tick's check with QPConstants.numbers and .rows read by name) gives the verdict of
    answer_ok and the mask of binding_families as the tick calls them (by index) on 200 seeded answers."""
    rng = np.random.default_rng(1000)
    seen = set()
    for trial in range(200):
        m, k, n_fric = int(rng.integers(1, 5)), 6, 4
        n = k * m
        n_in = m + m * n_fric + int(rng.integers(0, 6))
        M, lo, hi, x = _random_answer(rng, k + n_in, n, k)
        z = rng.normal(size=k + n_in) * (rng.random(k + n_in) < 0.3)
        g = rng.normal(size=n)
        numbers = np.array([10.0 ** rng.uniform(-12, -6), 0.5, 100.0, 1.0, 10.0 ** rng.uniform(-9, -3)])
        rows = np.array([1, 0, m, m + m * n_fric, n_fric, 3], dtype=np.int64)
        ok = answer_check.answer_ok(M, lo, hi, x, n, k, numbers[0], numbers[4])
        fams = answer_check.binding_families(g, z, k, n, n_in, m, rows[1], rows[2], rows[4], rows[3]) if ok else 0
        assert _core.qp_answer_check(M, lo, hi, g, x, z, k, m, numbers, rows) == (ok, fams)
        seen.add(ok)
    assert seen == {True, False}
