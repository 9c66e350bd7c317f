"""Controller tuning on linear models of a scene (python-control throughout).

- :func:`linearize_plant` - the plant alone about the scene's nominal state: a continuous
  ``control.StateSpace`` with named states, inputs (joint torques) and outputs (object pose,
  node poses, interconnection wrenches);
- :func:`linearize_closed_loop` - the whole closed loop with its gains about its equilibrium
  holding the initial pose: discrete time (``dt`` = the control period), from the actual
  :class:`~coopctrl.closed_loop.ClosedLoop` over one period, with the followers' PI closed
  analytically (:class:`ClosedLoopModel`);
- :func:`leader_loop` - the leader's tracking loop: poles, damping, step response;
- :func:`force_loop` - a follower's force loop: loop transfer function, margins
  (``control.stability_margins``), bandwidth, and the elastic mode it acts through;
- gain design: :func:`leader_gains` (from ``omega_n``, ``zeta``), :func:`leader_gains_lqr`,
  :func:`follower_force_gains` (target bandwidth and phase margin); each returns
  :class:`Gains`, which become ``--set`` overrides, a TOML fragment or a new scenario file;
- :func:`simulate_step` - a small step on the nonlinear loop next to the linear prediction.

Example::

    import coopctrl
    from coopctrl import tuning

    scenario = coopctrl.load_scenario("scenarios/planar_two_arm_lift.toml")
    model = tuning.linearize_closed_loop(scenario)
    loop = tuning.force_loop(model)                  # follower arm 2, grip-normal component
    loop.margins.phase_margin, loop.bandwidth, loop.elastic_mode
    design = tuning.follower_force_gains(model, bandwidth_rad_s=60.0, phase_margin_deg=60.0)
    design.gains.as_overrides()                      # {"controllers.followers.force_kp": ...}
"""

from coopctrl.tuning.closed_loop_model import ClosedLoopModel, linearize_closed_loop
from coopctrl.tuning.elastic_modes import ElasticModes, elastic_modes
from coopctrl.tuning.errors import NoOperatingPoint, TuningError, UnachievableDesign
from coopctrl.tuning.force_loop import ForceLoop, default_component, discrete_pi, force_loop
from coopctrl.tuning.force_loop_design import ForceLoopDesign, follower_force_gains
from coopctrl.tuning.frequency import Margins, bandwidth, margins
from coopctrl.tuning.gains import Gains
from coopctrl.tuning.leader_design import LeaderLQRDesign, bryson_weights, leader_gains, leader_gains_lqr
from coopctrl.tuning.leader_loop import LeaderLoop, equivalent_second_order, leader_loop, second_order_step
from coopctrl.tuning.nonlinear_step import StepComparison, simulate_step
from coopctrl.tuning.operating_point import OperatingPoint, hold_scenario
from coopctrl.tuning.plant_model import PlantModel, linearize_plant

__all__ = [
    "ClosedLoopModel",
    "ElasticModes",
    "ForceLoop",
    "ForceLoopDesign",
    "Gains",
    "LeaderLQRDesign",
    "LeaderLoop",
    "Margins",
    "NoOperatingPoint",
    "OperatingPoint",
    "PlantModel",
    "StepComparison",
    "TuningError",
    "UnachievableDesign",
    "bandwidth",
    "bryson_weights",
    "default_component",
    "discrete_pi",
    "elastic_modes",
    "equivalent_second_order",
    "follower_force_gains",
    "force_loop",
    "hold_scenario",
    "leader_gains",
    "leader_gains_lqr",
    "leader_loop",
    "linearize_closed_loop",
    "linearize_plant",
    "margins",
    "second_order_step",
    "simulate_step",
]
