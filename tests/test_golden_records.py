"""The golden records (tests/_golden.py): every shipped scene, and each integrator family on the carry and the
planar lift, runs to the numbers recorded before, to 1e-10 relative.

The scale of a signal is its largest magnitude over the record (a torque of 1e-14 N m at the rest pose is compared
against the run's largest torque, not against itself). The compiled kernels are deterministic on one machine
(bit-identical between runs), and the C++ core ports them expression for expression (docs/core.md, "Rounding");
1e-10 leaves room for a compiler that rounds differently (another numba or LLVM version), whose differences of a
few ulps the closed loop carries along."""

from __future__ import annotations

import numpy as np
import pytest

import _golden

RELATIVE = 1e-10


@pytest.mark.parametrize("name", list(_golden.CASES))
def test_the_case_runs_to_its_golden_record(name):
    path = _golden.path_of(name)
    assert path.is_file(), f"no golden record for {name}: python tests/_golden.py {name}"
    with np.load(path) as kept:
        want = {key: kept[key] for key in kept.files}
    got = _golden.run_case(name)
    assert str(got["status"]) == str(want["status"])
    np.testing.assert_array_equal(got["t"], want["t"])
    for key in _golden.SIGNALS:
        scale = max(float(np.max(np.abs(want[key]), initial=0.0)), 1e-300)
        error = float(np.max(np.abs(got[key] - want[key]), initial=0.0)) / scale
        assert error <= RELATIVE, f"{name}: {key} differs by {error:.3g} of its largest magnitude"
