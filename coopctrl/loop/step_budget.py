"""The step budget of an error-controlled run: every run ends.

An error-controlled scheme (``rk23``, ``rk45``, ``trbdf2``, and the Python reference of ``coopctrl
tradeoff`` and ``simulation.accuracy``) shrinks its step until the tolerance is met; where it cannot
be met at any step above ``simulation.min_step`` it may crawl on with tiny steps for hours. The loop
(:func:`coopctrl.loop.compiled.run_compiled`) counts the steps taken (accepted and rejected) and stops the
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

__all__ = ["CHECK_STEPS", "PYTHON_STEPS_PER_PERIOD", "STEPS_PER_PERIOD", "StepBudgetExceeded", "step_budget"]

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
        self.args = (f"{integrator} took {steps} steps by t = {time:.6g} s, beyond its budget of {budget} "
                     f"({per_period} per control period on average; docs/reliability.md, 'Budgets'): the tolerance "
                     "cannot be met at a cost that ends; loosen simulation.rtol / simulation.atol, use "
                     "simulation.integrator = \"trbdf2\" for stiff grasps, or a fixed step",)
