"""coopctrl.results.node_poses: the compiled pass over a run's states equals the plant's own node poses."""

import numpy as np

from coopctrl import load_scenario
from coopctrl.results.node_poses import node_poses_of
from coopctrl.scenario import build


def _states(scenario, n, seed):
    """``n`` states near the scenario's start: its initial state plus seeded perturbations of the positions."""
    plant = build.build_plant(scenario)
    x0 = build.initial_state(scenario)
    rng = np.random.default_rng(seed)
    x = np.tile(x0, (n, 1))
    x[:, :plant.nz] += rng.normal(0.0, 0.05, size=(n, plant.nz))
    return plant, x


def _expected(plant, x):
    m, p = plant.arm_count, plant.p
    out = np.full((len(x), m, p), np.nan)
    for k, row in enumerate(x):
        if np.all(np.isfinite(row)):
            out[k] = plant.node_poses(row).reshape(m + 1, p)[1:]
    return out


def test_planar_poses_equal_the_plants_bit_for_bit_and_nan_where_the_state_is_not_finite():
    plant, x = _states(load_scenario("planar_two_arm_lift"), 6, seed=1)
    x[2, 0] = np.nan
    x[4, -1] = np.inf
    got = node_poses_of(x, plant)
    # the same compiled kinematics per sample: equal bit for bit, no tolerance
    np.testing.assert_array_equal(got, _expected(plant, x))
    assert np.isnan(got[2]).all() and np.isnan(got[4]).all() and np.isfinite(got[0]).all()


def test_spatial_poses_equal_the_plants_bit_for_bit():
    plant, x = _states(load_scenario("spatial_two_puma_carry"), 5, seed=2)
    np.testing.assert_array_equal(node_poses_of(x, plant), _expected(plant, x))


def test_no_samples_give_an_empty_array_of_the_pose_shape():
    plant, x = _states(load_scenario("planar_two_arm_lift"), 1, seed=3)
    assert node_poses_of(x[:0], plant).shape == (0, plant.arm_count, plant.p)
