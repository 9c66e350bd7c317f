"""The integration methods of the compiled loop: each integrator name's run-time code.

The compiled advance (coopctrl/core/integration_plan.h's ``ExplicitMethod`` and the plans' families) branches on
it; the loop's driver (:mod:`coopctrl.loop.run`) picks it by the scenario's ``simulation.integrator``. An
integrator not listed here steps in Python.
"""

from __future__ import annotations

#: Explicit schemes (the run-time code ``ExplicitPlan.method``).
METHOD_EULER = 0
METHOD_SYMPLECTIC_EULER = 1
METHOD_RK4 = 2
#: The diagonally implicit Runge-Kutta schemes (an :class:`ImplicitPlan`; the tableau says which).
METHOD_SDIRK = 3
#: The error-controlled schemes (:mod:`coopctrl.integrators.adaptive_plans`: an ``EmbeddedPlan`` or a ``TRBDF2Plan``).
METHOD_ADAPTIVE = 4

#: The code of each integrator the compiled loop steps itself.
METHODS = {"euler": METHOD_EULER, "symplectic_euler": METHOD_SYMPLECTIC_EULER, "rk4": METHOD_RK4,
           "implicit_midpoint": METHOD_SDIRK, "implicit_euler": METHOD_SDIRK,
           "rk23": METHOD_ADAPTIVE, "rk45": METHOD_ADAPTIVE, "trbdf2": METHOD_ADAPTIVE}
