"""Stiffness of one beam element in its own frame: the ``K_e^i`` of the book's (47).

A straight prismatic beam of length ``L`` [m] along its local x axis, between its end nodes a
(x = 0) and b (x = L). Young's modulus ``E`` [Pa], shear modulus ``G`` [Pa], area ``A`` [m^2],
second moments ``Iy``, ``Iz`` [m^4] (about the local y and z axes) and torsion constant ``J``
[m^4].

Spatial element, 12 displacements ``Delta_e = (u, v, w, rx, ry, rz)_a, (u, v, w, rx, ry, rz)_b``:
translations [m] along the local axes and small rotations [rad] about them (right-handed, so the
slopes are ``dv/dx = rz`` and ``dw/dx = -ry``). The entries are the classical ones (Przemieniecki,
*Theory of Matrix Structural Analysis*, 1968, ch. 5):

    axial      E A / L                       on (u_a, u_b)
    torsion    G J / L                       on (rx_a, rx_b)
    bending    12 E I / ((1 + Phi) L^3), 6 E I / ((1 + Phi) L^2),
               (4 + Phi) E I / ((1 + Phi) L), (2 - Phi) E I / ((1 + Phi) L)

with ``I = Iz`` for bending in the x-y plane (v, rz) and ``I = Iy`` in the x-z plane (w, ry). The
shear parameter ``Phi = 12 E I / (kappa G A L^2)`` (Timoshenko, ``shear=True``, shear
coefficient ``kappa``) is zero for Euler-Bernoulli beams.

Planar element (the x-z plane of the planar scenes, docs/model.md s.2), 6 displacements
``(u, w, theta)_a, (u, w, theta)_b`` with ``theta`` measured from +x towards +z, so that
``dw/dx = theta``: the axial and the x-z bending entries above with ``I = Iy`` and the sign of the
coupling terms for ``theta = -ry``.

Every matrix is symmetric, positive semi-definite, with exactly the element's rigid-body motions
(6 spatial, 3 planar) in its null space.
"""

from __future__ import annotations

import math

import numpy as np


def _check_section(**values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} = {value!r} is invalid: expected a finite number > 0")


def _bending_terms(E: float, I: float, L: float, phi: float) -> tuple[float, float, float, float]:
    """``(k11, k12, k22, k22')`` of one bending plane: transverse-transverse, transverse-rotation,
    rotation-rotation at one end and across the element."""
    c = E * I / ((1.0 + phi) * L**3)
    return 12.0 * c, 6.0 * c * L, (4.0 + phi) * c * L * L, (2.0 - phi) * c * L * L


def _shear_parameter(E: float, G: float, A: float, I: float, L: float, shear: bool, kappa: float) -> float:
    return 12.0 * E * I / (kappa * G * A * L * L) if shear else 0.0


def spatial_beam_stiffness(E: float, G: float, A: float, Iy: float, Iz: float, J: float, L: float,
                           shear: bool = False, kappa: float = 5.0 / 6.0) -> np.ndarray:
    """The 12x12 stiffness ``K_e^i`` [N/m, N, N m] of a 3-D beam element in its own frame.

    ``shear=True`` adds Timoshenko's shear deformation with shear coefficient ``kappa`` (5/6 for a
    rectangle). See the module docstring for the displacement order.
    """
    _check_section(E=E, G=G, A=A, Iy=Iy, Iz=Iz, J=J, L=L, kappa=kappa)
    K = np.zeros((12, 12))
    a, t = E * A / L, G * J / L
    for i, j, k in ((0, 6, a), (3, 9, t)):
        K[i, i] = K[j, j] = k
        K[i, j] = K[j, i] = -k
    # bending in the x-y plane: v (1, 7) and rz (5, 11), dv/dx = rz
    k11, k12, k22, k22x = _bending_terms(E, Iz, L, _shear_parameter(E, G, A, Iz, L, shear, kappa))
    _bending_block(K, (1, 5, 7, 11), k11, k12, k22, k22x, +1.0)
    # bending in the x-z plane: w (2, 8) and ry (4, 10), dw/dx = -ry
    k11, k12, k22, k22x = _bending_terms(E, Iy, L, _shear_parameter(E, G, A, Iy, L, shear, kappa))
    _bending_block(K, (2, 4, 8, 10), k11, k12, k22, k22x, -1.0)
    return K


def planar_beam_stiffness(E: float, A: float, I: float, L: float, G: float | None = None,
                          shear: bool = False, kappa: float = 5.0 / 6.0) -> np.ndarray:
    """The 6x6 stiffness [N/m, N, N m] of a beam element in the x-z plane, in its own frame:
    displacements ``(u, w, theta)`` at each end, ``dw/dx = theta``; ``I`` [m^4] is the second
    moment about the axis normal to the plane. ``shear=True`` needs ``G`` [Pa]."""
    _check_section(E=E, A=A, I=I, L=L, kappa=kappa)
    if shear:
        if G is None:
            raise ValueError("G = None is invalid with shear=True: expected the shear modulus [Pa] > 0")
        _check_section(G=G)
    K = np.zeros((6, 6))
    a = E * A / L
    K[0, 0] = K[3, 3] = a
    K[0, 3] = K[3, 0] = -a
    phi = _shear_parameter(E, G if shear else 1.0, A, I, L, shear, kappa)
    _bending_block(K, (1, 2, 4, 5), *_bending_terms(E, I, L, phi), +1.0)
    return K


def _bending_block(K: np.ndarray, index: tuple[int, int, int, int], k11: float, k12: float,
                   k22: float, k22x: float, sign: float) -> None:
    """Write one bending plane's 4x4 block on displacements ``(v_a, r_a, v_b, r_b)`` with slope
    ``dv/dx = sign * r``."""
    s = sign
    block = np.array([[k11, s * k12, -k11, s * k12],
                      [s * k12, k22, -s * k12, k22x],
                      [-k11, -s * k12, k11, -s * k12],
                      [s * k12, k22x, -s * k12, k22]])
    K[np.ix_(index, index)] = block
