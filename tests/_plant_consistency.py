"""Checks of a cooperative plant's compiled right-hand side against the plant's Python statement of its
equations, ``Gamma(z) z'' + phi(z, z') = (tau, 0)`` (docs/model.md s.5), for the tests of the compiled core."""

from __future__ import annotations

import numpy as np

#: The inputs' part of the accelerations against ``Gamma^-1 (tau, 0)`` from the plant's mass matrix (assembled in
#: Python from the arms' ``H``, ``J`` and the nodes' inertia): the same solve written another way, relative to the
#: size of the terms (``|Gamma| |z''|`` and ``|tau|``).
MASS_MATRIX_RTOL = 1e-11


def assert_inputs_act_through_the_mass_matrix(plant, x, tau, rhs):
    """``Gamma(z) (z''(tau) - z''(0)) = (tau, 0)`` with ``rhs(x, tau) -> (status, dx)``: the right-hand side's
    accelerations are the mass matrix's solve, and the inputs enter the arms' rows only; ``dz = x[nz:]``."""
    nz = plant.nz
    status, dx = rhs(x, tau)
    status0, dx0 = rhs(x, np.zeros_like(tau))
    assert status == status0 == 0
    np.testing.assert_array_equal(dx[:nz], x[nz:])
    G = plant.mass_matrix(x)
    got = G @ (dx[nz:] - dx0[nz:])
    want = np.concatenate([tau, np.zeros(nz - tau.size)])
    scale = np.abs(G).max() * max(np.abs(dx[nz:]).max(), np.abs(dx0[nz:]).max()) + np.abs(tau).max()
    np.testing.assert_allclose(got, want, rtol=0.0, atol=MASS_MATRIX_RTOL * scale)


def arm_potential(plant, x) -> float:
    """The arms' gravitational potential [J] summed arm by arm in Python (``arm.potential(q)``; 0 for a contact
    point, whose node's gravity is the elastic system's)."""
    return sum(arm.potential(x[plant.q_slice(i)]) for i, arm in enumerate(plant.arms) if hasattr(arm, "potential"))
