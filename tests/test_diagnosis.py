"""Truthful causes (issue 12): each cause of a failed run provoked on purpose, and the reason names it;
the step advice appears only when the step is beyond the closed loop's predicted limit.

(The Euler-angle singularity, the sixth cause, is provoked in tests/test_euler_singularity.py.)"""

from __future__ import annotations

from coopctrl.analysis.diagnosis import held_split_cause, unreachable_cause
from coopctrl.scenario import load_scenario
from coopctrl.simulator import closed_loop, simulate
from test_cli import REPO

FAR = {"trajectory.via[1].pose": [0.0, 0.15, 1.5, 0.3, 0.0, 0.0]}  # 0.8 m above the carry's reach


def load(name, **overrides):
    return load_scenario(REPO / "scenarios" / f"{name}.toml", overrides)


def test_torque_saturation_is_named_not_the_step():
    """60 kg on the two Pumas: the torques saturate from the first tick; the reason names the saturation
    (joints, ticks, first time) and says the step is not the cause, with no step advice."""
    result = simulate(load("spatial_two_puma_carry", **{"object.mass": 60.0, "simulation.duration": 1.0}))
    assert result.status == "diverged"
    reason = result.reason
    assert "cause: torque saturation" in reason and "ticks from t = 0 s" in reason and "arm " in reason
    assert "not the likely cause" in reason and "try a step" not in reason
    assert result.torque_saturated_ticks == len(result.t)


def test_static_instability_is_named():
    result = simulate(load("central_spring_buckling", **{"simulation.duration": 0.1}))
    assert result.status == "diverged"
    assert "statically unstable" in result.reason and "buckles" in result.reason
    assert "try a step" not in result.reason


def test_step_beyond_the_closed_loop_limit_is_named_with_advice():
    """Explicit Euler at T = 1 ms on the stiff grasp (closed-loop limit ~ 3e-5 s): the step is the cause."""
    result = simulate(load("stiff_grasp_extreme", **{"simulation.integrator": "euler", "simulation.substeps": 1,
                                                     "simulation.duration": 0.05}))
    assert result.status == "diverged"
    assert "try a step of at most" in result.reason and "not the likely cause" not in result.reason
    assert "torque saturation" not in result.reason  # the saturation came with the blow-up, after it


def test_step_within_the_closed_loop_limit_gets_no_step_advice():
    """Explicit Euler at 2e-4 s on the spatial carry: beyond the open-loop plant's limit (2.2e-4 s is its
    prediction; the undamped-looking mode) but well inside the closed loop's (8.6e-4 s), and a 60 kg payload
    makes the run fail: the step is not blamed."""
    result = simulate(load("spatial_two_puma_carry", **{"object.mass": 60.0, "simulation.duration": 1.0,
                                                        "simulation.integrator": "euler", "simulation.substeps": 4}))
    assert result.status == "diverged"
    assert "try a step" not in result.reason and "not the likely cause" in result.reason


def test_unreachable_pose_is_named():
    loop = closed_loop(load("spatial_two_puma_carry", **FAR))
    assert unreachable_cause(loop, 0.0) == ""
    why = unreachable_cause(loop, 2.0)
    assert why.startswith("unreachable pose: at t = 2 s arm ") and "joint limits" in why
    # the node pose is computed (its theta is -1 * 0.0 here): printed without a "-0"
    pose = why.split("node pose (")[1].split(")")[0].split(", ")
    assert len(pose) == 6 and "-0" not in pose


def test_out_of_reach_waypoint_run_warns_of_the_saturation():
    """Run anyway (--no-preflight): the arms cannot follow, the torques saturate, and the printed summary
    shows the saturated ticks and warns on stderr (the run itself stays bounded here)."""
    from test_cli import coopctrl

    proc = coopctrl("run", "spatial_two_puma_carry", "--no-preflight", "--set",
                    "trajectory.via[1].pose=[0.0,0.15,1.5,0.3,0.0,0.0]", "--set", "simulation.duration=2.5")
    assert "torque-saturated ticks" in proc.stdout
    assert "warning: the torques saturated at tau_max on" in proc.stderr


def test_qp_failure_after_held_splits_is_named_with_its_time():
    """30 kg carried within the torque limits in 0.5 s: the QP fails at the acceleration peak, the loop holds
    its last split on 4 ticks, then stops; the reason gives the time, the binding family and the held ticks."""
    result = simulate(load("heavy_payload_torque_limits", **{"object.mass": 30.0, "trajectory.via[1].time": 0.5,
                                                             "simulation.duration": 0.1}))
    assert result.status == "qp_failed"
    reason = result.reason
    assert reason.startswith("at t = ") and "binding: torque_limits" in reason
    assert "cause: load distribution: the QP failed on " in reason and "held its last feasible split" in reason


def test_held_split_is_named():
    events = [(0.25, "qp_held", "QP status 'infeasible' (binding: torque_limits); holding the last feasible split"),
              (0.26, "qp_held", "QP status 'infeasible' (binding: torque_limits); holding the last feasible split")]
    why = held_split_cause(events)
    assert why.startswith("load distribution: the QP failed on 2 ticks from t = 0.25 s")
    assert "torque_limits" in why
    assert held_split_cause([]) == ""


def test_a_failure_at_the_first_tick_is_diagnosed_without_recursion():
    """Soft grasps (1e2 N/m): the loaded start already deforms beyond the bound. The closed-loop limit is
    linearized on loops that refuse that state with their own reason (the closed-loop diagnosis runs in
    simulate, after the run, and never inside a run: it cannot recurse), and the reason says the step is
    not the cause and why the start fails."""
    scenario = load("planar_two_arm_lift", **{"springs[0].stiffness": 1e2, "springs[1].stiffness": 1e2,
                                              "simulation.duration": 0.02})
    result = simulate(scenario)
    assert result.status == "diverged"
    assert "diverged at t = 0 s: deformation" in result.reason and "too soft" in result.reason
    assert "not the likely cause" in result.reason and "try a step" not in result.reason


def test_saturation_at_the_blow_up_does_not_outweigh_the_step():
    """RK4 at T/2 = 1.5 ms on the stiff scene (grasps 5e7 N/m, T = 3 ms; RK4's closed-loop limit ~1.3e-4 s):
    it diverges at its second tick, where the torques of the blow-up saturate (1 of 2 ticks). That
    saturation is the divergence's consequence: the step is blamed, with advice, and saturation is not."""
    result = simulate(load("stiff_grasp_extreme", **{"springs[0].stiffness": 5e7, "springs[1].stiffness": 5e7,
                                                     "simulation.control_period": 0.003, "simulation.integrator": "rk4",
                                                     "simulation.substeps": 2, "simulation.duration": 0.03}))
    assert result.status == "diverged"
    assert result.torque_saturated_ticks >= 1  # the evidence was there, and is outweighed
    assert "try a step of at most" in result.reason and "not the likely cause" not in result.reason
    assert "torque saturation" not in result.reason


def test_saturation_precedes_blow_up():
    from coopctrl.analysis.diagnosis import saturation_precedes_blow_up

    # saturated from the start of a run judged 5 ticks before its failure: it came first
    assert saturation_precedes_blow_up({"saturation_first_time_s": 0.0}, t_fail=0.1, t_back=0.095)
    # saturated from the start of a run that failed at its second tick (judged at the start): came first
    assert saturation_precedes_blow_up({"saturation_first_time_s": 0.0}, t_fail=0.006, t_back=0.0)
    # first met after the state the step is judged at, or late in the run, or never: a consequence
    assert not saturation_precedes_blow_up({"saturation_first_time_s": 0.003}, t_fail=0.006, t_back=0.0)
    assert not saturation_precedes_blow_up({"saturation_first_time_s": 0.06}, t_fail=0.1, t_back=0.095)
    assert not saturation_precedes_blow_up({}, t_fail=0.1, t_back=0.095)
