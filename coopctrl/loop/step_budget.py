"""The step budget of an error-controlled run: every run ends.

An error-controlled scheme (``rk23``, ``rk45``, ``trbdf2``, and the Python reference of ``coopctrl
tradeoff`` and ``simulation.accuracy``) shrinks its step until the tolerance is met; where it cannot
be met at any step above ``simulation.min_step`` it may crawl on with tiny steps for hours. The loop
(:func:`coopctrl.loop.run.run_compiled`) counts the steps taken (accepted and rejected) and stops the
run when they exceed

.. math::
    B = b \\cdot \\max(k, 1)

after ``k`` control periods, ``b`` = :data:`STEPS_PER_PERIOD` for a compiled scheme and
:data:`PYTHON_STEPS_PER_PERIOD` for one stepped in Python (about a hundred times slower per step).
The run then ends with status ``diverged`` (exit 1) and a reason naming the scheme, the steps taken,
the budget and what to change. The count is checked between chunks of ticks; a chunk is shortened so
that it holds about :data:`CHECK_STEPS` steps at the rate measured so far.

The defaults are met only when the tolerance is unreachable: the stiffest scene the reference allows
(1e10 N/m on a 0.1 g node, ``omega`` = 1e7 rad/s) limits an explicit scheme to a step of about
``3 / omega`` = 3e-7 s, some 3000 steps per 1 ms period, 30 times below :data:`STEPS_PER_PERIOD`; the
shipped scenes take 1 to 100.
"""

from __future__ import annotations

from coopctrl.errors import DivergenceError

__all__ = ["CHECK_STEPS", "LONG_RUN_STEPS", "PYTHON_STEPS_PER_PERIOD", "STEPS_PER_PERIOD", "StepBudgetExceeded",
           "long_run_notice", "step_budget"]

#: Steps per control period, on average over the run, of a compiled error-controlled scheme [-].
STEPS_PER_PERIOD = 100_000
#: The same for a scheme stepped in Python (the scipy reference) [-].
PYTHON_STEPS_PER_PERIOD = 1_000
#: Steps [-] between two checks of the budget (a chunk of ticks is cut to about this many).
CHECK_STEPS = 2_000_000


def step_budget(periods: int, per_period: int) -> int:
    """``B`` [-] after ``periods`` control periods (module docstring)."""
    return int(per_period) * max(int(periods), 1)


class StepBudgetExceeded(DivergenceError):
    """An error-controlled scheme took more steps than its budget (module docstring).

    Attributes:
        time: Simulation time [s] when the budget was found exceeded; steps: the steps taken [-];
        budget: ``B`` [-]; integrator: the scheme's name.
    """

    def __init__(self, time: float, steps: int, budget: int, integrator: str, per_period: int):
        self.steps, self.budget, self.integrator = int(steps), int(budget), integrator
        super().__init__(time, "integration steps", float(steps))
        fix = ("the reference's tolerance cannot be met on this scene at a cost that ends, so no accuracy can be "
               "measured against it: choose the setting by hand (simulation.integrator, substeps or rtol) or soften "
               "the stiffest springs" if integrator == "reference" else
               "the tolerance cannot be met at a cost that ends; loosen simulation.rtol / simulation.atol, use "
               "simulation.integrator = \"trbdf2\" for stiff grasps, or a fixed step")
        self.args = (f"{integrator} took {steps} steps by t = {time:.6g} s, beyond its budget of {budget} "
                     f"({per_period} per control period on average; docs/reliability.md, 'Budgets'): {fix}",)


#: An error-controlled run estimated to take more steps than this [-] says so before it starts (on a terminal).
LONG_RUN_STEPS = 1_000_000


#: Stability interval on the imaginary axis [-] of the explicit error-controlled schemes: an undamped mode of
#: ``omega`` [rad/s] limits their step to about this over ``omega`` (Dormand-Prince 5(4): 3.3, Bogacki-Shampine
#: 3(2): 1.7; ``trbdf2`` is L-stable and has no limit).
STABILITY_INTERVAL = {"rk45": 3.3, "rk23": 1.7}


def long_run_notice(loop, x0, duration: float) -> str:
    """A line saying that an error-controlled run of ``loop`` from ``x0`` over ``duration`` [s] will be long,
    or ``""``: an explicit scheme's steps are at least ``duration / h*``, ``h* = c / omega_max`` with ``c`` its
    :data:`STABILITY_INTERVAL` and ``omega_max`` the plant's highest mode at ``x0`` [rad/s] (whatever the
    tolerance, it cannot step beyond it)."""
    c = STABILITY_INTERVAL.get(getattr(loop.integrator, "name", ""))
    if c is None or not getattr(loop.integrator, "adaptive", False):
        return ""
    try:
        omega = float(loop.omega_max(x0))
    except Exception:  # noqa: BLE001 - no estimate: no notice
        return ""
    if not omega > 0.0:
        return ""
    limit = c / omega
    least = int(duration / min(limit, loop.T))
    if least <= LONG_RUN_STEPS:
        return ""
    periods = max(int(round(duration / loop.T)), 1)
    return (f"{loop.integrator.name} will take at least {least} steps over {duration:g} s (the plant's highest mode, "
            f"{omega:.3g} rad/s, limits its step to about {limit:.3g} s); it stops at its budget of "
            f"{step_budget(periods, STEPS_PER_PERIOD)} steps (docs/reliability.md, 'Budgets')")
