"""coopctrl/core/tick_checks (coopctrl._core): the object's required wrench agrees with its Python statement
(coopctrl.controllers.required_object_wrench, the Newton-Euler equations of docs/model.md s.6) on seeded poses, and
the tick's guards meet each condition they check where it is built on purpose: a non-finite state, a node in the
Euler band (spatial), a contact farther than max_deformation from its grasp point (the contact and its deformation
[m] computed here in the object frame), and none of them."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.controllers import required_object_wrench
from coopctrl.loop import tick_codes
from plants.frames import rotation_zyx


@pytest.mark.parametrize("spatial", [True, False])
def test_required_wrench_is_the_newton_euler_wrench(spatial):
    rng = np.random.default_rng(8 + spatial)
    p = 6 if spatial else 3
    for _ in range(50):
        inertia = rng.uniform(0.01, 0.2, 3 if spatial else 1)
        gravity = np.array([0.0, 0.0, -9.81]) if spatial else np.array([0.0, -9.81])
        Y0, dY0, ddY0 = rng.uniform(-1, 1, p), rng.normal(size=p), rng.normal(size=p)
        got = np.empty(p)
        _core.required_wrench(spatial, 2.5, inertia, gravity, Y0, dY0, ddY0, got)
        want = required_object_wrench("spatial" if spatial else "planar", 2.5,
                                      inertia, gravity, Y0, dY0, ddY0)
        # the same formula, evaluated in another order: rounding of terms of order 10 N
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def _deformations(spatial, Y, rho):
    """Each contact's offset from its grasp point in the object frame [m]."""
    npos = 3 if spatial else 2
    if spatial:
        R0 = rotation_zyx(Y[0, 3:6])
    else:
        c, s = np.cos(Y[0, 2]), np.sin(Y[0, 2])
        R0 = np.array([[c, -s], [s, c]])
    return np.linalg.norm((Y[1:, :npos] - Y[0, :npos]) @ R0 - rho, axis=1)


@pytest.mark.parametrize("spatial", [True, False])
def test_each_guard_meets_the_condition_built_for_it(spatial):
    rng = np.random.default_rng(20 + spatial)
    p, npos, m = (6, 3, 3) if spatial else (3, 2, 2)
    seen = set()
    for trial in range(60):
        Y = rng.uniform(-0.5, 0.5, (m + 1, p))
        Y[:, 4 if spatial else 2] = rng.uniform(-1.0, 1.0, m + 1)  # pitch away from the band
        rho = rng.uniform(-0.3, 0.3, (m, npos))
        x = rng.normal(size=4 * m + 2)
        case = trial % 4
        if case == 1:
            x[trial % x.shape[0]] = np.nan
        if spatial and case == 2:
            Y[trial % (m + 1), 4] = np.pi / 2 - 1e-9
        deformation = _deformations(spatial, Y, rho)
        max_def = 5.0 if case == 3 else float(np.sort(deformation)[-1] * 0.99)
        code, contact, value = _core.guards(spatial, x, Y, rho, 1e-3, max_def)
        if case == 1:
            assert code == tick_codes.NONFINITE
        elif spatial and case == 2:
            assert code == tick_codes.NEAR_SINGULARITY
        elif case == 3:
            assert code == tick_codes.DONE
        else:
            assert code == tick_codes.DEFORMATION
            assert contact == int(np.argmax(deformation))
            assert value == pytest.approx(deformation.max(), rel=1e-12)
        seen.add(code)
    expected = {tick_codes.NONFINITE, tick_codes.DEFORMATION, tick_codes.DONE}
    assert seen == expected | ({tick_codes.NEAR_SINGULARITY} if spatial else set())
