"""coopctrl/loop/parts.py: the closed loop's parts by concern are frozen and refuse a bad value naming it."""

from __future__ import annotations

import dataclasses

import pytest

import coopctrl
from coopctrl.closed_loop import ClosedLoop
from coopctrl.integrators import get_integrator
from coopctrl.loop.parts import LoopControllers, LoopGuards, LoopTiming
from coopctrl.simulator import closed_loop


@pytest.fixture(scope="module")
def lift():
    return closed_loop(coopctrl.load_scenario("planar_two_arm_lift"))


def test_the_parts_of_a_scene_rebuild_its_loop(lift):
    """A loop made from a built loop's parts has the same controllers, steps and guards (the squeeze and the
    torque rows from the load distribution's configuration)."""
    loop = ClosedLoop(lift.plant, lift.trajectory, lift.grasps, lift.ld,
                      LoopControllers(lift.leader, lift.followers, lift.compliance), lift.sensors,
                      LoopTiming(lift.integrator, lift.T, lift.substeps), LoopGuards(lift.max_deformation, lift.max_energy))
    assert loop.steps == lift.steps and loop.max_deformation == lift.max_deformation
    assert list(loop.squeeze_desired) == list(lift.squeeze_desired) and loop.torque_limits == lift.torque_limits
    assert loop.leader is lift.leader and loop.followers == lift.followers and loop.enabled


def test_the_parts_are_frozen(lift):
    parts = LoopControllers(lift.leader, lift.followers, lift.compliance)
    with pytest.raises(dataclasses.FrozenInstanceError):
        parts.enabled = False
    with pytest.raises(TypeError):
        parts.followers[0] = None  # a read-only view of the mapping it was given


@pytest.mark.parametrize("make, field", [
    (lambda l: LoopTiming(get_integrator("rk4"), 0.0), "control_period"),
    (lambda l: LoopTiming(get_integrator("rk4"), 1e-3, substeps=0), "substeps"),
    (lambda l: LoopTiming(get_integrator("rk4"), 1e-3, step=-1e-4), "step"),
    (lambda l: LoopTiming(None, 1e-3), "integrator"),
    (lambda l: LoopGuards(0.0), "max_deformation"),
    (lambda l: LoopGuards(0.1, max_energy=float("nan")), "max_energy"),
    (lambda l: LoopControllers(l.leader, [1, 2], l.compliance), "followers"),
    (lambda l: LoopControllers(l.leader, l.followers, l.compliance, enabled=1), "enabled"),
    (lambda l: LoopControllers(l.leader, l.followers, l.compliance, leader_law=len), "leader_law"),
])
def test_a_bad_part_is_refused_naming_its_field(lift, make, field):
    with pytest.raises((TypeError, ValueError)) as info:
        make(lift)
    message = str(info.value)
    assert message.startswith(f"{field} = ") and "expected" in message and "\n" not in message


def test_the_loop_refuses_a_part_of_another_kind(lift):
    with pytest.raises(TypeError, match=r"^timing = .* is invalid: expected a coopctrl.loop.parts.LoopTiming"):
        ClosedLoop(lift.plant, lift.trajectory, lift.grasps, lift.ld,
                   LoopControllers(lift.leader, lift.followers, lift.compliance), lift.sensors, lift.T,
                   LoopGuards(lift.max_deformation))
