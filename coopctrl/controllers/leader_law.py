"""The nodes' control laws as the user's choice: a function the closed loop's tick calls.

The tick (coopctrl/core/tick.h) computes the leader node's target, the nominal deformed node
``Y_nominal + increment`` (the nominal node pose (148) and the deformation that makes the leader carry
its QP share), and its pose error ``err = target - Y`` (angles wrapped into ``[-pi, pi)``). A leader law
turns them into the node's commanded acceleration; computed torque on the leader's arm (the contact
wrench and the arm's dynamics) then gives the joint torques. Its signature::

    law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd) -> None

- ``err`` (p,) the pose error [m, rad] (``p = 6``: 3 positions then ZYX angles; ``p = 3`` planar);
- ``dY_ref``, ``dY`` (p,) the nominal and measured node rates [m/s, rad/s];
- ``ddY_ref`` (p,) the nominal node acceleration [m/s^2, rad/s^2];
- ``npos`` the number of position components (3 spatial, 2 planar): ``a >= npos`` are angles;
- ``params`` (k,) the law's constants (:attr:`LeaderLaw.params`);
- ``a_cmd`` (p,) written by the law: the commanded node acceleration [m/s^2, rad/s^2].

``law`` is a plain Python function on numpy arrays, writing ``a_cmd`` in place. The built-in laws,
:func:`computed_torque` (the default, with the scenario's leader gains) and :func:`object_impedance`, run in
the compiled core; a law of your own is called from the compiled tick once per tick (the documented slower
path: about a microsecond or more a call, with the interpreter's lock taken). An exception it raises stops the
run and is raised again; a non-finite entry of ``a_cmd`` stops the run with a ``ValueError`` naming it.

The same signature serves the followers (``closed_loop(scenario, follower_law=...)``): their target is the rigid
node moved by the compliance map of the force PI's correction, and the law turns the error to it into the
node's commanded acceleration (default: computed torque with the followers' gains).

:func:`object_impedance` is the example a user starts from: the leader node (and the object it carries)
behaves like a mass-damper-spring about its target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np


def computed_torque_law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
    """The default leader law: ``a_cmd = ddY_ref + Kd (dY_ref - dY) + Kp err`` with ``params = (Kp
    [1/s^2], Kd [1/s])``: with an exact model the node error obeys ``e'' + Kd e' + Kp e = 0``."""
    a_cmd[:] = ddY_ref + params[1] * (dY_ref - dY) + params[0] * err


def object_impedance_law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
    """An object impedance about the target: ``M e'' + D e' + K e = 0`` for the node error ``e``,
    i.e. ``a_cmd = ddY_ref + (D / M) (dY_ref - dY) + (K / M) err``, with ``params = (M_t [kg], D_t
    [N s/m], K_t [N/m], M_r [kg m^2], D_r [N m s/rad], K_r [N m/rad])`` for the position components
    (``a < npos``) and the angles."""
    for a in range(a_cmd.shape[0]):
        o = 0 if a < npos else 3
        a_cmd[a] = ddY_ref[a] + (params[o + 1] / params[o]) * (dY_ref[a] - dY[a]) + (params[o + 2] / params[o]) * err[a]


@dataclass(frozen=True)
class LeaderLaw:
    """A node's control law and its constants, for ``closed_loop(scenario, leader_law=...)`` (or
    ``follower_law=...``).

    Attributes:
        function: ``law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd)`` (module docstring), a plain
            Python function.
        params: The law's constants, a 1-d sequence of finite floats (units the law documents).
        name: A short name for summaries and errors.
    """

    function: Callable
    params: tuple[float, ...]
    name: str = "custom"

    def __post_init__(self):
        f = self.function
        if not callable(f) or not hasattr(f, "__code__"):
            raise TypeError(f"LeaderLaw.function = {f!r}: expected a plain Python function "
                            "law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd) (not a compiled one)")
        if f.__code__.co_argcount != 7:
            raise TypeError(f"LeaderLaw.function = {f.__name__} takes {f.__code__.co_argcount} arguments: expected 7, "
                            "law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd)")
        try:
            p = tuple(float(v) for v in np.asarray(self.params, dtype=float).reshape(-1))
        except (TypeError, ValueError):
            raise TypeError(f"LeaderLaw.params = {self.params!r}: expected a sequence of floats") from None
        if not p or not all(math.isfinite(v) for v in p):
            raise ValueError(f"LeaderLaw.params = {self.params!r}: expected at least one value, all finite")
        object.__setattr__(self, "params", p)

    @property
    def param_array(self) -> np.ndarray:
        """:attr:`params` as a float array (what the compiled law receives)."""
        return np.array(self.params, dtype=float)


def computed_torque(Kp: float, Kd: float) -> LeaderLaw:
    """The default law with gains ``Kp`` [1/s^2] and ``Kd`` [1/s] (the scenario's leader gains)."""
    return LeaderLaw(computed_torque_law, (Kp, Kd), "computed_torque")


def object_impedance(mass: float, damping: float, stiffness: float, inertia: float, rot_damping: float,
                     rot_stiffness: float) -> LeaderLaw:
    """The object impedance law: translational ``mass`` [kg], ``damping`` [N s/m], ``stiffness`` [N/m];
    rotational ``inertia`` [kg m^2], ``rot_damping`` [N m s/rad], ``rot_stiffness`` [N m/rad]. The node
    error then rings at ``omega = sqrt(stiffness / mass)`` with damping ratio ``damping / (2 sqrt(stiffness
    mass))`` (and likewise in rotation)."""
    values = (mass, damping, stiffness, inertia, rot_damping, rot_stiffness)
    if not (mass > 0.0 and inertia > 0.0) or any(not (math.isfinite(v) and v >= 0.0) for v in values):
        raise ValueError(f"object_impedance{values}: expected mass > 0, inertia > 0 and finite damping and "
                         "stiffness >= 0 [kg, N s/m, N/m, kg m^2, N m s/rad, N m/rad]")
    return LeaderLaw(object_impedance_law, values, "object_impedance")
