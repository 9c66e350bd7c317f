"""``plants.cooperative.plant_args``: the plant's kernel arrays by name, each the plant's own array in the shape its
documentation states, and the space read from their shapes."""

from __future__ import annotations

import numpy as np
import pytest

from plants.cooperative import PlantArgs
from plants.cooperative.plant_args import is_spatial
from _scenes import scene

#: The fields, in order.
NAMES = ("arm_kind", "arm_dof", "q_off", "tables", "table_off", "bases", "tools", "gravity", "node_params",
         "edge_index", "edge_params", "Y_ref", "immobile")


@pytest.mark.parametrize("space,m,unloaded_state", [("spatial", 2, "mobile"), ("spatial", 3, "immobile"),
                                                    ("planar", 3, "mobile")])
def test_plant_args_are_the_plants_arrays_by_name(space, m, unloaded_state):
    """The fields in order, the plant's own arrays (the same objects on every read), each the shape its
    documentation states."""
    plant, _ = scene(space, m=m, arms="full", unloaded_state=unloaded_state)
    P = plant.plant_args
    assert type(P) is PlantArgs
    assert len(P) == len(NAMES) and all(getattr(P, name) is value for name, value in zip(NAMES, P))
    assert all(a is b for a, b in zip(P, plant.plant_args))
    p = 6 if space == "spatial" else 3
    assert P.arm_kind.shape == P.arm_dof.shape == P.q_off.shape == P.table_off.shape == (m,)
    assert P.bases.shape == ((m, 4, 4) if space == "spatial" else (m, 3))
    assert P.gravity.shape == ((3,) if space == "spatial" else (2,))
    assert P.node_params.shape[0] == P.Y_ref.shape[0] == m + 1 and P.Y_ref.shape[1] == p
    assert P.edge_index.shape == (P.edge_params.shape[0], 4)  # nodes i, j, element, damping form
    assert P.immobile is (unloaded_state == "immobile")


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_space_from_the_arrays(space):
    """``is_spatial`` tells the space from the arrays' shapes."""
    P = scene(space, m=2, arms="full")[0].plant_args
    assert is_spatial(P) is (space == "spatial")
