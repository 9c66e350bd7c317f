"""Parameter sweeps: the Cartesian product of scenario overrides, one summary row per run, on any
:class:`concurrent.futures.Executor` (in process, a local process pool, or a Dask cluster).

``run_sweep(scenario_path, SweepGrid.parse(["simulation.integrator=rk4,euler"]), jobs=2)`` returns
a :class:`SweepResult`; ``coopctrl sweep`` is its command line.
"""

from coopctrl.sweep.errors import GridError, MissingExtra, SchedulerError, SweepError, SweepInterrupted
from coopctrl.sweep.executors import DaskExecutor, LocalProcessPool, SerialExecutor, make_executor
from coopctrl.sweep.grid import SweepAxis, SweepGrid, split_values
from coopctrl.sweep.plan import SweepPlan, SweepRun, plan_sweep
from coopctrl.sweep.results import METRICS, RUN_STATUSES, TIMING_COLUMNS, SweepResult
from coopctrl.sweep.runner import run_sweep
from coopctrl.sweep.worker import execute_run, simulate_run

__all__ = [
    "METRICS",
    "RUN_STATUSES",
    "TIMING_COLUMNS",
    "DaskExecutor",
    "GridError",
    "LocalProcessPool",
    "MissingExtra",
    "SchedulerError",
    "SerialExecutor",
    "SweepAxis",
    "SweepError",
    "SweepGrid",
    "SweepInterrupted",
    "SweepPlan",
    "SweepResult",
    "SweepRun",
    "execute_run",
    "make_executor",
    "plan_sweep",
    "run_sweep",
    "simulate_run",
    "split_values",
]
