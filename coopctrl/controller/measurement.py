"""``Measurement``: what the controller reads once per control period, by name."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Measurement:
    """One control period's measurement, in the scene's world frame (the book's coordinates, ``docs/model.md``).

    ``p`` is 6 for a spatial scene (``x, y, z, psi, theta, phi``: positions [m], ZYX Euler angles [rad],
    ``R = Rz(psi) Ry(theta) Rx(phi)``) and 3 for a planar one (``x, z, theta``); ``n_i`` the joints of arm ``i``;
    ``m`` the arms (one grasp each).

    Attributes:
        q: Per arm, (n_i,) joint positions [rad] (a prismatic joint [m]).
        dq: Per arm, (n_i,) joint rates [rad/s] ([m/s]).
        wrench: (m, p) per grasp, the wrench the grasp applies to the object (what a wrist force-torque
            sensor reads): spatial rows ``(f_x, f_y, f_z, n_x, n_y, n_z)`` [N, N m], planar ``(f_x, f_z, n)``,
            world frame, the force at the contact point.
        object_pose: (p,) the object's pose ``Y_0`` [m, rad].
        object_twist: (p,) its rate ``dY_0``: velocity [m/s] and Euler-angle rates [rad/s] (not the angular
            velocity).

    The fields are stored as given (no copy); :meth:`coopctrl.Controller.step` checks their shapes and that
    every value is finite, and refuses a bad one with a :class:`~coopctrl.errors.MeasurementError` naming it.
    """

    q: tuple
    dq: tuple
    wrench: np.ndarray
    object_pose: np.ndarray
    object_twist: np.ndarray


__all__ = ["Measurement"]
