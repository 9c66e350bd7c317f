"""Results of a closed-loop run: :class:`SimulationResult`, its summary, files and plots."""

from coopctrl.results.simulation_result import STATUSES, SimulationResult
from coopctrl.results.summary import QP_SUCCESS, json_safe, summary_table

__all__ = ["QP_SUCCESS", "STATUSES", "SimulationResult", "json_safe", "summary_table"]
