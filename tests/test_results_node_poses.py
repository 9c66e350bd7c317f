"""coopctrl.results.node_poses: the compiled pass over a run's states equals the plant's own node poses."""

import numpy as np
import pytest

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


@pytest.mark.parametrize("name, rotations", [("spatial_two_puma_carry", "charts"), ("spatial_two_puma_carry", "book"),
                                             ("ur5e_panda_carry", "charts"), ("contact_points_only", "book")])
def test_spatial_poses_equal_the_plants_bit_for_bit(name, rotations):
    """The spatial pass runs the forward kinematics alone (``node_poses_into``); the plant's ``node_poses`` runs
    the whole ``node_state_into`` (rates and dynamics too): the same link frames and tip, so equal bit for bit.
    DH arms (the Pumas) and URDF chains (UR5e, Panda), in their own charts and in the book's world angles, and
    contact points."""
    plant, x = _states(load_scenario(name, {"scene.rotations": rotations}), 5, seed=2)
    np.testing.assert_array_equal(node_poses_of(x, plant), _expected(plant, x))


def test_no_samples_give_an_empty_array_of_the_pose_shape():
    plant, x = _states(load_scenario("planar_two_arm_lift"), 1, seed=3)
    assert node_poses_of(x[:0], plant).shape == (0, plant.arm_count, plant.p)


def test_a_run_without_node_poses_is_the_same_run_with_y_nodes_none():
    """``simulate(..., node_poses=False)`` (what ``coopctrl run`` does without ``--out``) skips only the
    poses: every other array and the summary are those of the run with them, whose poses are the plant's."""
    import pytest

    from coopctrl import simulator

    scenario = load_scenario("planar_two_arm_lift", {"simulation.duration": 0.02, "simulation.record_every": 3})
    full = simulator.simulate(scenario)
    bare = simulator.simulate(scenario, node_poses=False)
    assert bare.Y_nodes is None and full.Y_nodes.shape == (len(full.t), 2, 3)
    np.testing.assert_array_equal(full.Y_nodes, node_poses_of(full.x, build.build_plant(scenario)))
    for name in ("t", "x", "tau", "F_measured", "F_commanded", "squeeze"):
        np.testing.assert_array_equal(getattr(bare, name), getattr(full, name))
    drop = ("wall_time_s", "realtime_factor", "startup_s")  # timing: not the run's outcome
    assert {k: v for k, v in bare.summary().items() if k not in drop} == \
        {k: v for k, v in full.summary().items() if k not in drop}
    with pytest.raises(TypeError, match="node_poses"):
        simulator.simulate(scenario, node_poses="no")
