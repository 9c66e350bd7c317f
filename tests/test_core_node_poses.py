"""coopctrl/core/node_poses (coopctrl._core): the node poses of recorded states, bit for bit the plant's own
:meth:`~plants.cooperative.CooperativePlant.node_poses` per sample, on every shipped scene (DH and URDF arms, in their
own charts and in the book's world angles, contact points, planar arms) at seeded states near its start, rows that
are not finite skipped; and the arguments checked once at the binding. (The pass was checked bit for bit against
the numba pass it replaced when it was ported; the golden records lock a run's poses since.)"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from coopctrl import _core, load_scenario
from coopctrl.errors import ScenarioError
from coopctrl.scenario import build

SCENES = sorted(p.stem for p in (pathlib.Path(__file__).parents[1] / "scenarios").glob("*.toml"))


def _states(plant, scenario, n, seed):
    x0 = build.initial_state(scenario)
    rng = np.random.default_rng(seed)
    x = np.tile(x0, (n, 1))
    x[:, :plant.nz] += rng.normal(0.0, 0.05, size=(n, plant.nz))
    x[1, 0] = np.nan
    x[3, -1] = np.inf
    return np.ascontiguousarray(x)


def _per_sample(plant, x):
    """The plant's own node poses of each finite row (NaN rows elsewhere)."""
    m, p = plant.arm_count, plant.p
    out = np.full((len(x), m, p), np.nan)
    for k, row in enumerate(x):
        if np.all(np.isfinite(row)):
            out[k] = plant.node_poses(row).reshape(m + 1, p)[1:]
    return out


def _core_poses(plant, x):
    out = np.full((len(x), plant.arm_count, plant.p), np.nan)
    status = np.zeros(2, dtype=np.int64)
    poses = _core.spatial_node_poses if plant.space == "spatial" else _core.planar_node_poses
    return poses(x, plant.plant_args, status, out), status, out


@pytest.mark.parametrize("name", SCENES)
def test_node_poses_are_the_plants_own_bit_for_bit(name):
    """The scene as shipped, and a spatial scene in both rotation modes where it allows them (charts: the arms'
    own charts)."""
    scenario = load_scenario(name)
    plant = build.build_plant(scenario)
    variants = [(plant, _states(plant, scenario, 6, seed=len(name)))]
    if plant.space == "spatial":
        for rotations in ("charts", "book"):
            try:
                other = load_scenario(name, {"scene.rotations": rotations})
                plant = build.build_plant(other)
                variants.append((plant, _states(plant, other, 6, seed=len(name))))
            except ScenarioError:  # a path the book's angles refuse (euler_singularity)
                pass
    for plant, x in variants:
        bad_core, status_core, got = _core_poses(plant, x)
        assert bad_core == -1 and status_core[0] == 0  # near the start: no kinematics fails
        np.testing.assert_array_equal(got, _per_sample(plant, x))
        assert np.isnan(got[1]).all() and np.isnan(got[3]).all()  # the rows that are not finite are skipped
        assert np.isfinite(got[[0, 2, 4, 5]]).all()


def test_the_binding_checks_its_arguments():
    scenario = load_scenario("planar_two_arm_lift")
    plant = build.build_plant(scenario)
    x = _states(plant, scenario, 6, seed=0)
    status = np.zeros(2, dtype=np.int64)
    with pytest.raises(ValueError, match="X"):
        _core.planar_node_poses(x[:, 1:].copy(), plant.plant_args, status, np.zeros((6, plant.arm_count, 3)))
    with pytest.raises(ValueError, match="out"):
        _core.planar_node_poses(x, plant.plant_args, status, np.zeros((6, plant.arm_count, 6)))
    with pytest.raises(ValueError, match="bases"):
        _core.spatial_node_poses(x, plant.plant_args, status, np.zeros((6, plant.arm_count, 6)))
