"""The operating point of the linear models: the closed loop holding the scene's initial pose.

The scene's trajectory is replaced by a single via point at the initial object pose (the
nominal motion at rest; a minimum-jerk trajectory starts at rest too, so this is also the
state the run starts from) and the sensors by exact ones (the linear model is that of the
noise-free loop). The operating point is the equilibrium of that held loop, found by Newton's
method on the one-period map from the scene's initial state (the loaded state, or the
unloaded one for ``simulation.start = "unloaded"``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning.errors import NoOperatingPoint


def hold_scenario(scenario):
    """``scenario`` with its object held at the initial pose and exact sensors."""
    from coopctrl.scenario import SensorsConfig, TrajectoryConfig, ViaPoint

    return dataclasses.replace(scenario, trajectory=TrajectoryConfig(via=(ViaPoint(0.0, scenario.object.pose),)),
                               sensors=SensorsConfig())


def opened_scenario(scenario):
    """The held scene with the followers' PI removed (``force_kp = force_ki = 0``): the loop
    of :class:`~coopctrl.tuning.one_period_map.OnePeriodMap`."""
    c = scenario.controllers
    followers = dataclasses.replace(c.followers, force_kp=0.0, force_ki=0.0)
    return dataclasses.replace(hold_scenario(scenario), controllers=dataclasses.replace(c, followers=followers))


@dataclass(frozen=True, eq=False)
class OperatingPoint:
    """An equilibrium of the held closed loop.

    Attributes:
        x: Plant state ``(z, z')`` (docs/model.md s.5).
        tau: Joint torques there [N m].
        pi_output: Stacked PI outputs ``v`` of the followers [N, N m] (``k_p e + k_i I``).
        integrals: Follower arm index -> error integral ``I`` [N s] (the follower's state).
        outputs: The outputs ``y`` of :class:`OnePeriodMap` there (poses, wrenches, errors).
        drift: ``max |x_{k+1} - x_k|`` over one period at the returned point [m, rad, m/s, rad/s].
        force_error: ``max |F* - F_meas|`` there [N, N m].
        iterations: Newton iterations used.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    x: np.ndarray
    tau: np.ndarray
    pi_output: np.ndarray
    integrals: dict
    outputs: np.ndarray
    drift: float
    force_error: float
    iterations: int


#: Convergence of the equilibrium: largest change of a state over one period [m, rad, m/s, rad/s]
#: and largest residual of the force equations [N, N m]. Both are about 100 times the
#: round-off floor of one period of the shipped scenes (1e-14 and 1e-12 measured).
DRIFT_TOLERANCE = 1e-12
FORCE_TOLERANCE = 1e-9


def _force_equations(kp: float, ki: float, on: bool, nv: int):
    """``(E_e, E_v)``: the rows ``E_e e + E_v v = 0`` that the follower PI imposes at rest."""
    eye = np.eye(nv)
    if on and ki > 0:  # the integral stops only at e = 0
        return eye, np.zeros((nv, nv))
    if on:  # P only: v = kp e
        return -kp * eye, eye
    return np.zeros((nv, nv)), eye  # no force loop: v = 0


def find_operating_point(period_map, force_kp: float, force_ki: float, force_loop: bool = True,
                         max_iterations: int = 12) -> tuple[OperatingPoint, tuple]:
    """Newton's method for ``x = Phi(x, 0, v)`` with the PI at rest.

    The unknowns are the plant state ``x`` and the PI outputs ``v``; the equations are the
    fixed point of the one-period map and, per follower component, ``e = 0`` (``k_i > 0``),
    ``v = k_p e`` (``k_i = 0``) or ``v = 0`` (no force loop). The Jacobian is that of
    :meth:`OnePeriodMap.jacobians`, which is returned too, evaluated at the solution.

    Returns:
        ``(OperatingPoint, (A, B, C, D))``.

    Raises:
        NoOperatingPoint: no convergence in ``max_iterations``.
    """
    from coopctrl.scenario import build

    x = np.asarray(build.initial_state(period_map.scenario), dtype=float)
    nx, nu, nv = x.size, period_map.nu, period_map.nv
    v = np.zeros(nv)
    E_e, E_v = _force_equations(force_kp, force_ki, force_loop, nv)
    n_out = len(period_map.output_names)
    try:
        for it in range(1, max_iterations + 1):
            A, B, C, D = period_map.jacobians(x, None, v)
            x1, y, tau = period_map(x, None, v)
            e = y[n_out:]
            res = np.r_[x1 - x, E_e @ e + E_v @ v]
            drift = float(np.max(np.abs(res[:nx])))
            force_residual = float(np.max(np.abs(res[nx:]))) if nv else 0.0
            if drift <= DRIFT_TOLERANCE and force_residual <= FORCE_TOLERANCE:
                break
            Ce, Dev = C[n_out:], D[n_out:, nu:]
            J = np.block([[A - np.eye(nx), B[:, nu:]], [E_e @ Ce, E_e @ Dev + E_v]])
            dz = np.linalg.lstsq(J, -res, rcond=None)[0]
            x = x + dz[:nx]
            v = v + dz[nx:]
        else:
            raise NoOperatingPoint(period_map.scenario.name, float(np.max(np.abs(res))),
                                   f"Newton's method did not converge in {max_iterations} iterations")
    except ArithmeticError as exc:
        if isinstance(exc, NoOperatingPoint):
            raise
        raise NoOperatingPoint(period_map.scenario.name, float("nan"), str(exc)) from None
    p = period_map.p
    integrals = {}
    for k, i in enumerate(period_map.follower_indices):
        sl = slice(p * k, p * (k + 1))
        integrals[i] = (v[sl] - force_kp * e[sl]) / force_ki if (force_loop and force_ki > 0) else np.zeros(p)
    op = OperatingPoint(x=x, tau=tau, pi_output=v, integrals=integrals, outputs=y, drift=drift,
                        force_error=float(np.max(np.abs(e))) if e.size else 0.0, iterations=it)
    return op, (A, B, C, D)
