"""coopctrl/core/tick_checks (coopctrl._core): the object's required wrench and the tick's guards give the numbers
and codes of the numba stages of coopctrl.loop.kernel, bit for bit, on seeded poses: every guard met (non-finite
state, the Euler band, the deformation) and passed."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.loop import kernel


@pytest.mark.parametrize("spatial", [True, False])
def test_required_wrench_matches_the_numba_stage_bit_for_bit(spatial):
    rng = np.random.default_rng(8 + spatial)
    p = 6 if spatial else 3
    for _ in range(50):
        inertia = rng.uniform(0.01, 0.2, 3 if spatial else 1)
        gravity = np.array([0.0, 0.0, -9.81]) if spatial else np.array([0.0, -9.81])
        Y0, dY0, ddY0 = rng.uniform(-1, 1, p), rng.normal(size=p), rng.normal(size=p)
        want, got = np.empty(p), np.empty(p)
        kernel.required_wrench(spatial, 2.5, inertia, gravity, Y0, dY0, ddY0, want, np.empty((8, 3)),
                               np.empty((3, 3)))
        _core.required_wrench(spatial, 2.5, inertia, gravity, Y0, dY0, ddY0, got)
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("spatial", [True, False])
def test_guards_match_the_numba_stage(spatial):
    rng = np.random.default_rng(20 + spatial)
    p, npos, m = (6, 3, 3) if spatial else (3, 2, 2)
    seen = set()
    for trial in range(60):
        Y = rng.uniform(-0.5, 0.5, (m + 1, p))
        rho = rng.uniform(-0.3, 0.3, (m, npos))
        x = rng.normal(size=4 * m + 2)
        if trial % 4 == 1:
            x[trial % x.shape[0]] = np.nan
        if spatial and trial % 4 == 2:
            Y[trial % (m + 1), 4] = np.pi / 2 - 1e-9
        max_def = 5.0 if trial % 4 == 3 else 0.1  # 5 m: no contact that far, every guard passes
        want = kernel._guards(spatial, x, Y, rho, 1e-3, max_def, np.empty((4, 3, 3)), np.empty(npos))
        got = _core.guards(spatial, x, Y, rho, 1e-3, max_def)
        assert got[0] == want[0]
        if want[0] == kernel.DEFORMATION:
            assert (got[1], got[2]) == (want[1], want[2])
        seen.add(want[0])
    expected = {kernel.NONFINITE, kernel.DEFORMATION, kernel.DONE} | ({kernel.NEAR_SINGULARITY} if spatial else set())
    assert seen == expected
