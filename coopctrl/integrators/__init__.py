"""Fixed-step integrators for ``dx/dt = f(t, x, u)`` with ``x = (z, dz)`` and ``u`` held over a step.

========================  ==========================  =====  ==========================================
name                      class                       order  undamped stability limit ``h omega``
========================  ==========================  =====  ==========================================
``"euler"``               :class:`ExplicitEuler`      1      none (always unstable)
``"symplectic_euler"``    :class:`SymplecticEuler`    1      ``< 2``
``"rk4"``                 :class:`RungeKutta4`        4      ``<= 2 sqrt(2) ~= 2.828`` (real axis 2.785)
``"implicit_midpoint"``   :class:`ImplicitMidpoint`   2      unconditional (A-stable, symplectic)
``"implicit_euler"``      :class:`ImplicitEuler`      1      unconditional (L-stable: damps stiff modes)
========================  ==========================  =====  ==========================================

With damping ratio ``zeta`` (``predicted_max_step(omega, zeta)``): explicit Euler ``h omega <= 2 zeta``,
symplectic Euler ``h omega <= 2 / (zeta + sqrt(1 + zeta^2))``, RK4 2.6 to 2.96. On a linearization
``dx/dt = A x`` (every mode, coupled and damped), ``max_stable_step(A)``; see
:mod:`coopctrl.integrators.base` and :mod:`coopctrl.analysis.stability`.

Each scheme's arithmetic is written once, in the C++ core (coopctrl/core: explicit_schemes.h,
implicit_schemes.h, adaptive_schemes.h), on the plans of :mod:`coopctrl.integrators.compiled` (fixed-step)
and :mod:`coopctrl.integrators.adaptive_plans` (error-controlled), which state the schemes: the loop's tick
runs it, and so does ``step`` of the classes here (:mod:`coopctrl.integrators.stepping`). The classes are the
schemes' configuration: name, order, stability, settings (frozen once built).
"""

from __future__ import annotations

from coopctrl.errors import ScenarioError
from coopctrl.integrators.base import Integrator, RightHandSide
from coopctrl.integrators.diagonally_implicit import DiagonallyImplicitRungeKutta, NewtonConvergenceError
from coopctrl.integrators.error_controlled import TRBDF2, BogackiShampine, DormandPrince, ErrorControlled
from coopctrl.integrators.explicit_euler import ExplicitEuler
from coopctrl.integrators.implicit_euler import ImplicitEuler
from coopctrl.integrators.implicit_midpoint import ImplicitMidpoint
from coopctrl.integrators.integrate import IntegrationResult, integrate
from coopctrl.integrators.rk4 import RK4_IMAGINARY_AXIS_LIMIT, RK4_REAL_AXIS_LIMIT, RungeKutta4
from coopctrl.integrators.symplectic_euler import SymplecticEuler

#: Registry: name -> integrator class. Use :func:`get_integrator` to build one.
INTEGRATORS: dict[str, type[Integrator]] = {
    "euler": ExplicitEuler,
    "symplectic_euler": SymplecticEuler,
    "rk4": RungeKutta4,
    "implicit_midpoint": ImplicitMidpoint,
    "implicit_euler": ImplicitEuler,
}
#: Error-controlled schemes (:mod:`coopctrl.integrators.error_controlled`): name -> class. They run
#: compiled, over a control period (in the loop, or ``step`` on a plant's ``rhs``); :func:`get_integrator`
#: builds them too.
ERROR_CONTROLLED: dict[str, type[ErrorControlled]] = {
    "rk23": BogackiShampine,
    "rk45": DormandPrince,
    "trbdf2": TRBDF2,
}


def get_integrator(name: str, **options) -> Integrator:
    """A new integrator by registry name.

    Args:
        name: One of :data:`INTEGRATORS` (``"euler"``, ``"symplectic_euler"``, ``"rk4"``,
            ``"implicit_midpoint"``, ``"implicit_euler"``) or :data:`ERROR_CONTROLLED` (``"rk23"``,
            ``"rk45"``, ``"trbdf2"``).
        options: Keyword arguments of the class (the implicit schemes' Newton tolerances, see
            :class:`DiagonallyImplicitRungeKutta`; the error-controlled schemes' ``rtol``, ``atol``,
            ``atol_velocity``, ``min_step``, see :class:`ErrorControlled`);
            an unknown keyword raises ``TypeError``.

    Raises:
        ScenarioError: (a ``ValueError``) for an unknown name; the message lists the valid ones.
    """
    try:
        cls = INTEGRATORS[name] if name in INTEGRATORS else ERROR_CONTROLLED[name]
    except (KeyError, TypeError):
        valid = ", ".join(repr(n) for n in (*INTEGRATORS, *ERROR_CONTROLLED))
        raise ScenarioError("integrator", name, f"one of {valid}") from None
    return cls(**options)


__all__ = [
    "INTEGRATORS",
    "ERROR_CONTROLLED",
    "ErrorControlled",
    "BogackiShampine",
    "DormandPrince",
    "TRBDF2",
    "DiagonallyImplicitRungeKutta",
    "ExplicitEuler",
    "ImplicitEuler",
    "ImplicitMidpoint",
    "IntegrationResult",
    "Integrator",
    "NewtonConvergenceError",
    "RK4_IMAGINARY_AXIS_LIMIT",
    "RK4_REAL_AXIS_LIMIT",
    "RightHandSide",
    "RungeKutta4",
    "SymplecticEuler",
    "get_integrator",
    "integrate",
]
