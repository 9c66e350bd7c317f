"""coopctrl.Controller: the control layer stepped from Python gives the loop's torques, restores its state
exactly, and refuses a bad measurement with one line naming the field."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl import wiring
from coopctrl.controller import ControllerState, Measurement, Torques
from coopctrl.errors import CoopctrlError, MeasurementError, ScenarioError
from coopctrl.scenario import build

SCENES = Path(__file__).resolve().parent.parent / "scenarios"

#: The scenes of the step-equals-loop test: a spatial carry (two PUMAs), a planar lift, and the lift with the
#: elastic split (whose QP cost matrix and grasp stiffness carry over from step to step).
STEP_SCENES = ("spatial_two_puma_carry", "planar_two_arm_lift", "planar_two_arm_lift:elastic")


def _scenario(name: str, duration: float | None = None):
    name, _, split = name.partition(":")
    overrides = {} if duration is None else {"simulation.duration": duration}
    if split:
        overrides["load_distribution.split"] = split
    return coopctrl.load_scenario(SCENES / f"{name}.toml", overrides)


def _loop_record(scenario):
    """The loop's own run of ``scenario`` from its start, every tick recorded (no thinning)."""
    loop = wiring.closed_loop(scenario)
    rec = loop.run(build.initial_state(scenario, loop), scenario.simulation.duration)
    assert rec["status"] == "ok", rec["reason"]
    return rec


@pytest.fixture(scope="module", params=STEP_SCENES)
def scene(request):
    """(scenario, the loop's record of it): noise-free sensors, the whole scene."""
    scenario = _scenario(request.param)
    sensors = scenario.sensors
    assert all(getattr(sensors, s).noise_std == 0.0 for s in ("joints", "object", "forces")), "a noise-free scene"
    return scenario, _loop_record(scenario)


def test_step_equals_loop(scene):
    """Fed the loop's own measurements (its state and measured wrenches of every tick, noise-free), ``step``
    returns the torques the loop recorded, on every tick. The bound is 1e-12 of each joint's largest recorded
    torque (at least 1 N m): relative, at the scale of the torques. The step runs the same compiled stages on
    the same numbers, so the bits agree too, which is checked last."""
    scenario, rec = scene
    controller = coopctrl.Controller(scenario)
    T = controller.control_period
    ticks = len(rec["t"])
    assert ticks == round(scenario.simulation.duration / T) + 1
    taus = np.array([controller.step(k * T, controller.measurement(rec["x"][k], rec["F_measured"][k])).tau
                     for k in range(ticks)])
    scale = np.maximum(np.max(np.abs(rec["tau"]), axis=0), 1.0)  # [N m] per joint
    worst = np.max(np.abs(taus - rec["tau"]) / scale, axis=1)
    assert np.all(worst <= 1e-12), f"tick {int(np.argmax(worst))}: {np.max(worst):.3g} of the joint's scale"
    assert controller.state.flags.qp_solves == ticks  # one QP solve per step, none held
    assert np.array_equal(taus, rec["tau"])


def test_restore_gives_the_same_torques(scene):
    """Restoring a snapshot and stepping again gives the same torques, bit for bit, on this controller and
    on a fresh one (whose work arrays were never used): the snapshot holds all the state."""
    scenario, rec = scene
    T = scenario.simulation.control_period
    a = coopctrl.Controller(scenario)
    meas = [a.measurement(x, F) for x, F in zip(rec["x"][:400], rec["F_measured"][:400])]
    for k in range(200):
        a.step(k * T, meas[k])
    saved = a.state
    first = np.array([a.step(k * T, meas[k]).tau for k in range(200, 400)])
    a.state = saved
    again = np.array([a.step(k * T, meas[k]).tau for k in range(200, 400)])
    b = coopctrl.Controller(scenario)
    b.restore(saved)
    fresh = np.array([b.step(k * T, meas[k]).tau for k in range(200, 400)])
    assert np.array_equal(first, again)
    assert np.array_equal(first, fresh)
    assert np.array_equal(first, rec["tau"][200:400])
    assert a.state.steps == 400


def test_reset_is_a_fresh_controller(carry):
    """After steps, ``reset`` gives the first step of a fresh controller (bit for bit)."""
    c, x0, F0 = carry
    meas = c.measurement(x0, F0)
    for k in range(3):
        c.step(k * c.control_period, meas)
    c.reset()
    assert c.state.steps == 0 and not np.any(c.state.integrals) and c.state.flags.qp_solves == 0
    fresh = coopctrl.Controller(c.scenario)
    assert np.array_equal(c.step(0.0, meas).tau, fresh.step(0.0, meas).tau)


def test_a_failed_split_holds_the_last_one_then_gives_up():
    """The load distribution's failure policy, as in the loop: joint rates of 10 rad/s make bias torques beyond
    the QP's torque rows (a scene with torque limits), so the solve fails; the step holds the last feasible split
    and still returns saturated torques; the fifth failure in a row (``max_consecutive_failures``) raises
    InfeasibleLoad, one line; a good measurement then solves again."""
    from coopctrl.errors import InfeasibleLoad

    scenario = _scenario("heavy_payload_torque_limits", duration=0.05)
    c = coopctrl.Controller(scenario)
    loop = wiring.closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    good = c.measurement(x0, loop.plant.contact_wrenches(x0))
    T = c.control_period
    for k in range(3):
        c.step(k * T, good)
    saved = c.state
    x = x0.copy()
    nz = len(x) // 2
    x[nz:nz + sum(c.joint_counts)] = 10.0  # [rad/s]
    fast = c.measurement(x, good.wrench)
    tau = c.step(3 * T, fast).tau
    held = c.state
    assert held.flags.consecutive_failures == 1 and held.flags.qp_solves == saved.flags.qp_solves + 1  # one failed solve, counted
    assert np.array_equal(held.last_split, saved.last_split)
    assert np.all(np.isfinite(tau)) and np.all(np.abs(tau) <= np.concatenate(
        [np.broadcast_to(a.tau_max, (a.dof,)) for a in loop.plant.arms]))
    for k in range(4, 7):
        c.step(k * T, fast)
    with pytest.raises(InfeasibleLoad, match="5 consecutive failed solves") as info:
        c.step(7 * T, fast)
    assert "\n" not in str(info.value)
    c.step(8 * T, good)
    assert c.state.flags.consecutive_failures == 0


def test_state_is_a_frozen_copy(scene):
    scenario, rec = scene
    c = coopctrl.Controller(scenario)
    c.step(0.0, c.measurement(rec["x"][0], rec["F_measured"][0]))
    s = c.state
    before = s.integrals.copy()
    c.step(c.control_period, c.measurement(rec["x"][1], rec["F_measured"][1]))
    assert np.array_equal(s.integrals, before)  # a snapshot does not follow the controller
    with pytest.raises(ValueError):
        s.integrals[0, 0] = 1.0
    with pytest.raises(AttributeError):
        s.steps = 3


@pytest.fixture(scope="module")
def carry():
    """A controller of the carry and the measurement of its start."""
    scenario = _scenario("spatial_two_puma_carry", duration=0.05)
    c = coopctrl.Controller(scenario)
    loop = wiring.closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    return c, x0, loop.plant.contact_wrenches(x0)


def _with(meas: Measurement, **fields) -> Measurement:
    values = {f: getattr(meas, f) for f in ("q", "dq", "wrench", "object_pose", "object_twist")}
    values.update(fields)
    return Measurement(**values)


@pytest.mark.parametrize("field, make, named", [
    ("q", lambda m: (m.q[0], np.r_[m.q[1][:2], np.nan, m.q[1][3:]]), r"measurement\.q\[1\]\[2\] = nan"),
    ("dq", lambda m: (np.r_[np.inf, m.dq[0][1:]], m.dq[1]), r"measurement\.dq\[0\]\[0\] = inf"),
    ("wrench", lambda m: np.where(np.arange(12).reshape(2, 6) == 9, np.nan, m.wrench),
     r"measurement\.wrench\[1\]\[3\] = nan"),
    ("object_pose", lambda m: np.r_[m.object_pose[:4], -np.inf, m.object_pose[5]],
     r"measurement\.object_pose\[4\] = -inf"),
    ("object_twist", lambda m: None, r"measurement\.object_twist = missing"),
    ("q", lambda m: (m.q[0],), r"measurement\.q = 1 arrays"),
    ("dq", lambda m: (m.dq[0], m.dq[1][:5]), r"measurement\.dq\[1\] = an array of shape \(5,\)"),
    ("wrench", lambda m: m.wrench[:, :3], r"measurement\.wrench = an array of shape \(2, 3\)"),
    ("object_pose", lambda m: "up", r"measurement\.object_pose = str \(not numbers\)"),
])
def test_bad_measurement_is_refused_naming_the_field(carry, field, make, named):
    """A missing, non-finite or wrongly shaped field: one line naming it, and the state is unchanged."""
    c, x0, F0 = carry
    good = c.measurement(x0, F0)
    before = c.state
    with pytest.raises(MeasurementError, match=named) as info:
        c.step(0.0, _with(good, **{field: make(good)}))
    message = str(info.value)
    assert "\n" not in message and "expected" in message
    assert isinstance(info.value, ValueError) and isinstance(info.value, CoopctrlError)
    after = c.state
    for name in ("tau", "integrals", "last_split", "flags"):
        assert np.array_equal(getattr(before, name), getattr(after, name))


def test_pitch_beyond_the_first_world_chart_is_refused(carry):
    """The carry runs in rotation charts: the controller steps in the first chart (the book's world), so an
    object pitched past the loop's re-centring bound (|cos theta| < 0.7, 45.6 deg) is refused, naming it."""
    c, x0, F0 = carry
    good = c.measurement(x0, F0)
    pose = good.object_pose.copy()
    pose[4] = 0.85  # [rad], 48.7 deg
    with pytest.raises(MeasurementError, match=r"measurement\.object_pose\[4\] = 0\.85 is invalid: expected a "
                                               r"pitch within 45\.6 deg"):
        c.step(0.0, _with(good, object_pose=pose))
    pose[4] = 0.75  # 43 deg: within
    assert np.all(np.isfinite(c.step(0.0, _with(good, object_pose=pose)).tau))


def test_measurement_from_lists_is_accepted(carry):
    """Fields given as lists (or integer arrays) are converted; the torques are those of the arrays."""
    c, x0, F0 = carry
    good = c.measurement(x0, F0)
    saved = c.state
    a = c.step(0.0, good).tau
    c.state = saved
    b = c.step(0.0, Measurement(q=[list(v) for v in good.q], dq=[list(v) for v in good.dq], wrench=F0.tolist(),
                                object_pose=list(good.object_pose), object_twist=list(good.object_twist))).tau
    assert np.array_equal(a, b)


def test_torques_by_arm(carry):
    c, x0, F0 = carry
    torques = c.step(0.0, c.measurement(x0, F0))
    assert isinstance(torques, Torques)
    assert torques.names == c.arm_names and len(torques) == len(c.arm_names)
    np.testing.assert_array_equal(np.concatenate(torques.arms), torques.tau)
    np.testing.assert_array_equal(torques[c.arm_names[1]], torques[1])
    assert torques[1].shape == (c.joint_counts[1],)
    with pytest.raises(KeyError, match="is not in this scene"):
        torques["nobody"]
    with pytest.raises(ValueError):
        torques.tau[0] = 0.0  # read-only: the next step does not change what this one returned


def test_time_off_the_grid_and_bad_time(carry):
    """A time between two periods reads the trajectory there (a time within 1e-9 T of the grid reads its table
    row); any time after the trajectory's end its last pose; a negative or non-finite time is refused."""
    c, x0, F0 = carry
    meas = c.measurement(x0, F0)
    saved = c.state
    on = c.step(0.0, meas).tau
    c.state = saved
    near = c.step(1e-15, meas).tau  # within 1e-9 T of tick 0: its row
    c.state = saved
    off = c.step(0.3e-3, meas).tau  # between ticks 0 and 1: the trajectory evaluated at t
    assert np.array_equal(on, near)
    assert np.all(np.isfinite(off)) and not np.array_equal(on, off)
    after = []
    for t in (2.0, 2.5, 2.2004, 7.3):  # [s] the carry's trajectory ends at 2 s: its last pose, held, at any time after
        c.state = saved
        after.append(c.step(t, meas).tau)
    assert all(np.array_equal(after[0], a) for a in after[1:])  # (0.05 s of table: the trajectory evaluated)
    whole = coopctrl.Controller(_scenario("spatial_two_puma_carry"))  # 2.5 s of table: its row at 2 s
    whole.restore(saved)
    assert np.array_equal(whole.step(7.3, meas).tau, after[0])
    for t in (-1e-3, float("nan"), float("inf")):
        with pytest.raises(ValueError, match=r"t = .* is invalid: expected a finite time >= 0 \[s\]"):
            c.step(t, meas)


def test_restore_refuses_another_scene(carry):
    c, _, _ = carry
    lift = coopctrl.Controller(_scenario("planar_two_arm_lift", duration=0.05))
    with pytest.raises(ValueError, match="restore a snapshot taken from a controller of the same scene"):
        c.restore(lift.state)
    with pytest.raises(TypeError, match="expected a ControllerState"):
        c.restore({"tau": 0})
    assert isinstance(c.state, ControllerState)


def test_scene_it_cannot_run_is_refused():
    scenario = coopctrl.load_scenario(SCENES / "planar_two_arm_lift.toml",
                                      {"simulation.duration": 0.05, "controllers.enabled": False})
    with pytest.raises(ScenarioError, match=r"controllers\.enabled = False is invalid"):
        coopctrl.Controller(scenario)


def test_public_names():
    assert "Controller" in coopctrl.__all__ and "Measurement" in coopctrl.__all__
    assert coopctrl.Measurement is Measurement
