"""Shared checks of arm parameters (raise :class:`plants.errors.ParameterError`)."""

from __future__ import annotations

import math

import numpy as np

from plants.errors import ParameterError


#: Largest magnitude of an arm parameter in SI units (1000 km, 1e6 kg, 1e6 kg m^2, 1e6 N m): beyond it
#: the kinematics and dynamics overflow or lose all precision. URDF numbers and DH rows are checked.
MAX_MAGNITUDE = 1e6


def check_magnitude(where: str, value, bound: float = MAX_MAGNITUDE) -> None:
    """Raise unless ``value`` (scalar or array) is finite with every magnitude <= ``bound``."""
    if type(value) is float:  # the common case, without numpy's overhead (the same checks and messages)
        if not math.isfinite(value):
            raise ParameterError(where, value, "finite numbers")
        if abs(value) > bound:
            raise ParameterError(where, value, f"numbers of magnitude <= {bound:g} (SI units)")
        return
    arr = np.asarray(value, dtype=float)
    shown = arr.tolist() if arr.ndim else float(arr)  # a list prints on one line, an array may not
    if not np.all(np.isfinite(arr)):
        raise ParameterError(where, shown, "finite numbers")
    if arr.size and float(np.max(np.abs(arr))) > bound:
        raise ParameterError(where, shown, f"numbers of magnitude <= {bound:g} (SI units)")


def check_finite(where: str, value) -> None:
    """Raise if ``value`` (scalar or array) is not finite everywhere."""
    if type(value) is float:  # the common case, without numpy's overhead (the same check and message)
        if not math.isfinite(value):
            raise ParameterError(where, value, "a finite number")
        return
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(where, arr.tolist() if arr.ndim else value, "a finite number")


def check_nonnegative(where: str, value: float) -> None:
    """Raise if ``value`` is not a finite number >= 0."""
    check_finite(where, value)
    if value < 0.0:
        raise ParameterError(where, value, "a number >= 0")


def check_inertia(where: str, inertia: np.ndarray, mass: float, triangle: bool = True) -> None:
    """Raise unless the 3x3 inertia about the COM [kg m^2] is symmetric PSD and physical.

    For ``mass > 0``, physical means the principal moments satisfy the triangle inequality
    ``I1 + I2 >= I3`` (a mass distribution exists). A massless link may carry a lumped
    rotor-like inertia (the Puma 560's link 1 has only ``Iyy``), so it need only be PSD.
    ``triangle=False`` skips the triangle inequality (published identified data sets, such
    as the Puma 560's link 3, can violate it slightly); PSD is always required.
    """
    check_finite(where, inertia)
    scale = max(float(np.max(np.abs(inertia))), 1e-300)
    if np.max(np.abs(inertia - inertia.T)) > 1e-12 * scale:
        raise ParameterError(where, inertia.tolist(), "a symmetric 3x3 inertia matrix")
    principal = np.linalg.eigvalsh(inertia)
    tol = 1e-12 * scale
    if principal[0] < -tol:
        raise ParameterError(
            where, inertia.tolist(), f"a positive semi-definite inertia (principal moments {principal})"
        )
    if triangle and mass > 0.0 and principal[0] + principal[1] < principal[2] - tol:
        raise ParameterError(
            where,
            inertia.tolist(),
            f"principal moments satisfying the triangle inequality I1 + I2 >= I3 (got {principal})",
        )


def check_pose4(where: str, T) -> np.ndarray:
    """Return ``T`` as a float 4x4 homogeneous transform, raising if it is not one."""
    arr = np.array(T, dtype=float)
    if arr.shape != (4, 4):
        raise ParameterError(where, T, f"a 4x4 homogeneous transform (got shape {arr.shape})")
    check_finite(where, arr)
    R = arr[:3, :3]
    if np.max(np.abs(R.T @ R - np.eye(3))) > 1e-9 or np.linalg.det(R) < 0.0:
        raise ParameterError(where, T, "a proper rotation in the upper-left 3x3 block")
    if np.max(np.abs(arr[3] - [0.0, 0.0, 0.0, 1.0])) > 0.0:
        raise ParameterError(where, T, "last row (0, 0, 0, 1)")
    return arr


def check_vector(where: str, value, length: int) -> np.ndarray:
    """Return ``value`` as a finite float vector of the given length."""
    arr = np.array(value, dtype=float).reshape(-1)
    if arr.shape != (length,):
        raise ParameterError(where, value, f"{length} numbers (got shape {np.shape(value)})")
    check_finite(where, arr)
    return arr


def check_limits(where_tau: str, tau_max, where_q: str, q_limits, n: int):
    """Validate torque limits (n,) > 0 [N m] and joint limits (n, 2) with lower < upper [rad]."""
    tau = np.array(tau_max, dtype=float).reshape(-1)
    if tau.shape != (n,):
        raise ParameterError(where_tau, tau_max, f"{n} torque limits [N m]")
    if np.any(np.isnan(tau)) or np.any(tau <= 0.0):
        raise ParameterError(where_tau, tau_max, "torque limits > 0 [N m] (inf = unlimited)")
    lim = np.array(q_limits, dtype=float)
    if lim.shape != (n, 2):
        raise ParameterError(where_q, q_limits, f"an ({n}, 2) array of [lower, upper] [rad]")
    if np.any(np.isnan(lim)) or np.any(lim[:, 0] >= lim[:, 1]):
        raise ParameterError(where_q, q_limits, "lower < upper for every joint")
    tau.setflags(write=False)
    lim.setflags(write=False)
    return tau, lim


def wrap_angle(angle):
    """Wrap an angle [rad] to (-pi, pi]."""
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi
