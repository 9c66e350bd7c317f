"""Values derived from a shipped trajectory (coopctrl.derived): computed once per trajectory object and
key, the same values as a fresh computation, read-only where shared; a user's trajectory computed at every call."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.loop.charts import WorldChart, target_motion, world_table
from coopctrl.scenario import build
from coopctrl.scenario.loader import load_scenario
from coopctrl.trajectory import GeodesicTrajectory, MinimumJerkTrajectory
from coopctrl.derived import ENTRIES, derived, immutable

TIMES = [0.0, 1.0, 2.0]
POSES = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.1, 0.0, 0.2, 0.3, 0.2, 0.1], [0.2, 0.1, 0.2, 0.6, 0.1, 0.0]]


def geodesic():
    return GeodesicTrajectory(TIMES, POSES)


class Counter:
    def __init__(self):
        self.calls = 0

    def __call__(self):
        self.calls += 1
        return self.calls


def test_a_shipped_trajectory_computes_each_key_once():
    path, count = geodesic(), Counter()
    assert immutable(path) and immutable(MinimumJerkTrajectory(TIMES, POSES, "spatial"))
    assert [derived(path, "a", count) for _ in range(3)] == [1, 1, 1]
    assert derived(path, "b", count) == 2  # another key: computed
    assert derived(geodesic(), "a", count) == 3  # another trajectory, equal: its own values


def test_a_user_trajectory_is_computed_at_every_call():
    class Moving:  # a trajectory of the user's: it may change between calls
        def evaluate(self, t):
            return np.zeros(6), np.zeros(6), np.zeros(6)

    class Sub(GeodesicTrajectory):  # a subclass may add state of its own
        pass

    count = Counter()
    assert not immutable(Moving()) and not immutable(Sub(TIMES, POSES))
    user = Moving()
    assert [derived(user, "a", count) for _ in range(2)] == [1, 2]


def test_the_values_kept_are_bounded():
    path, count = geodesic(), Counter()
    for k in range(ENTRIES + 1):
        derived(path, k, count)
    assert count.calls == ENTRIES + 1
    derived(path, ENTRIES, count)  # the latest: kept
    assert count.calls == ENTRIES + 1
    derived(path, 0, count)  # the oldest: dropped, computed again
    assert count.calls == ENTRIES + 2


def test_a_failed_computation_is_not_kept():
    path, count = geodesic(), Counter()

    def fails():
        count()
        raise ValueError("bad")

    for _ in range(2):
        with pytest.raises(ValueError):
            derived(path, "f", fails)
    assert count.calls == 2


def test_the_target_motion_kept_equals_a_fresh_one_and_is_read_only():
    t = np.linspace(0.0, 2.5, 251)
    kept = target_motion(geodesic(), t)
    again = target_motion(geodesic(), t)  # a fresh trajectory: computed anew
    for a, b in zip(kept, again):
        assert np.array_equal(a, b) and not a.flags.writeable
    with pytest.raises(ValueError):
        kept[0][0, 0] = 1.0


def test_the_world_table_is_the_first_charts_table_in_a_new_array():
    scenario = load_scenario("scenarios/spatial_two_puma_carry.toml")
    plant = build.build_plant(scenario)
    path = build.trajectory(scenario)
    t = np.arange(301) * scenario.simulation.control_period
    table = world_table(path, t)
    fresh = np.zeros_like(table)
    WorldChart(plant.plant_args, plant.nz, target_motion(path, t)).table(fresh, 0)
    assert np.array_equal(fresh, table) and np.any(table[1] != 0.0)
    assert table.flags.writeable and world_table(path, t) is not table
    table[:] = 0.0  # the caller's own: the next is whole
    assert np.array_equal(world_table(path, t), fresh)


def carry():
    scenario = load_scenario("scenarios/spatial_two_puma_carry.toml")
    return scenario, build.build_plant(scenario)


def test_a_plants_grasp_compliance_is_computed_once_each_holding_its_own_copies():
    from coopctrl.controllers import GraspCompliance

    _, plant = carry()
    first, second = GraspCompliance(plant), GraspCompliance(plant)
    assert np.array_equal(first.K, second.K) and np.array_equal(first.C, second.C)
    assert first.K is not second.K and first.K.flags.writeable
    first.K[:] = 0.0  # one compliance's arrays: the next plant's compliance is whole
    fresh = GraspCompliance(build.build_plant(load_scenario("scenarios/spatial_two_puma_carry.toml")))
    assert np.array_equal(fresh.K, second.K) and np.array_equal(fresh.C, second.C)
    assert np.array_equal(GraspCompliance(plant, step=2e-6).K, GraspCompliance(plant, step=2e-6).K)
    assert not np.array_equal(GraspCompliance(plant, step=2e-6).K, second.K)  # another step: its own numbers


def test_the_loaded_state_kept_is_a_fresh_ones_in_a_new_array():
    from coopctrl.loop.loaded_start import loaded_state
    from coopctrl.wiring import closed_loop

    scenario, _ = carry()
    loop = closed_loop(scenario)
    x = build.unloaded_state(scenario)
    first = loaded_state(loop.plant, loop.trajectory, loop.grasps, loop.ld.config, loop.compliance, False, x)
    again = loaded_state(loop.plant, loop.trajectory, loop.grasps, loop.ld.config, loop.compliance, False, x)
    assert first is not again and np.array_equal(first, again) and first.flags.writeable
    other = load_scenario("scenarios/spatial_two_puma_carry.toml")  # its own plant: computed afresh
    fresh = build.initial_state(other)
    assert np.array_equal(fresh, first) and not np.array_equal(fresh, x)
    moved = loaded_state(loop.plant, loop.trajectory, loop.grasps + 0.001, loop.ld.config, loop.compliance, False, x)
    assert not np.array_equal(moved, first)  # other grasps: another state
