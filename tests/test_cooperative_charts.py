"""The cooperative plant in rotation charts (docs/model.md s.2 and s.5): arms' nodes in their own charts,
the object in a stored chart that is re-centred between steps. The same physical state gives the same
motion in the book's coordinates whatever the charts, and two passive arms carry an object that turns
through pitch 90 deg with the energy conserved, where the book's world angles stop."""

from __future__ import annotations

import numpy as np
import pytest

from _passive import integrate_passive, pitch_about_y
from plants.arms import puma560
from plants.arms.puma560 import GRIPPER_TOOL
from plants.cooperative import assemble_plant
from plants.elastic import Interconnection, Node
from plants.errors import EulerSingularityError, ParameterError
from plants.frames import rotation_zyx

# Rounding only: the charts change the arithmetic, not the equations (1e-12 relative).
EXACT_RTOL = 1e-12


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


def two_pumas(torsion=(3.0, 4.0, 5.0), damping=0.0, torsion_damping=0.0, gravity=9.81, rotation_form="geodesic"):
    """The two-PUMA carry reduced to its plant: the object between two PUMA 560s, contacts 0.15 m
    from its mass centre on central springs."""
    arms, grasps = [], []
    for k in range(2):
        phi = np.pi * (1 + k)
        c, s = np.cos(phi), np.sin(phi)
        grasps.append([0.15 * c, 0.15 * s, 0.0, phi + np.pi, 0.0, 0.0])
        base = np.eye(4)
        base[:3, :3] = rotation_zyx(np.array([phi + np.pi, 0.0, 0.0]))
        base[:3, 3] = (0.7 * c, 0.7 * s, 0.0)
        arms.append(puma560(base=base, tool=GRIPPER_TOOL))
    springs = [Interconnection((0, k + 1), stiffness=2e3, torsion=list(torsion), damping=damping,
                               torsion_damping=torsion_damping, rotation_form=rotation_form) for k in range(2)]
    return assemble_plant("spatial", Node(2.0, (0.02, 0.03, 0.025), name="object"), [0.0, 0.0, 0.5, 0.0, 0.0, 0.0],
                          arms, np.array(grasps), [Node(0.3, (1e-3, 1.2e-3, 1.4e-3))] * 2, springs, gravity=gravity)


def test_the_same_state_in_other_charts_gives_the_same_book_coordinates():
    plant, x0 = two_pumas(damping=3.0, torsion_damping=0.2)
    rng = np.random.default_rng(3)
    x = x0 + rng.normal(0.0, 0.1, x0.size)
    tau = rng.normal(0.0, 5.0, plant.input_size)
    book = plant.book_coordinates(x, plant.rhs(0.0, x, tau))
    own = plant.with_charts(arm_charts="own")
    recentred, xr = own.recentred(x)
    assert own.charted and np.array_equal(own.node_poses(x).reshape(3, 6)[1:, 3:], np.zeros((2, 3)))
    assert np.array_equal(xr[plant.nz - 3:plant.nz], np.zeros(3))
    for p, xx in ((own, x), (recentred, xr)):
        for a, b in zip(p.book_coordinates(xx, p.rhs(0.0, xx, tau)), book):
            assert rel(a, b) <= EXACT_RTOL
        assert p.energy(xx) == pytest.approx(plant.energy(x), rel=EXACT_RTOL)
        assert rel(p.contact_wrenches(xx), plant.contact_wrenches(x)) <= EXACT_RTOL
        assert rel(p.control_terms(xx).Fw, plant.control_terms(x).Fw) <= EXACT_RTOL
    # identity charts are the book's plant: the same packed rows, the same right-hand side bits
    assert not plant.charted and not plant.with_charts(np.stack([np.eye(3)] * 3)).charted
    assert np.array_equal(plant.with_charts(np.stack([np.eye(3)] * 3)).rhs(0.0, x, tau), plant.rhs(0.0, x, tau))
    # the book's rotation form depends on the chart: refused with the reason
    book_plant, _ = two_pumas(rotation_form="book")
    with pytest.raises(ParameterError, match="arm_charts = 'own'.*rotation_form = 'book'.*'geodesic'"):
        book_plant.with_charts(arm_charts="own")
    with pytest.raises(ParameterError, match=r"arm_charts = 'tip' is invalid: expected one of \('world', 'own'\)"):
        plant.with_charts(arm_charts="tip")


def test_two_passive_arms_carry_an_object_through_pitch_90_deg_with_energy_conserved():
    """No damping, gravity or torques: the object spins about y from pitch 80 deg through 90 deg on
    soft geodesic torsion springs, the arms' nodes in their own charts and the object's chart
    re-centred between segments. The book's world angles stop at the same state."""
    plant, x0 = two_pumas(torsion=(0.02, 0.02, 0.02), gravity=0.0)
    own = plant.with_charts(arm_charts="own")
    nz = own.nz
    x0 = x0.copy()
    x0[nz - 2] = np.radians(80.0)  # the object's pitch
    x0[2 * nz - 2] = 2.0  # [rad/s]
    tau = np.zeros(own.input_size)
    E0 = own.energy(x0)

    def world_rotation(p, x):
        return p.elastic.charts[0] @ rotation_zyx(x[nz - 3:nz])

    times, states, plants = integrate_passive(
        own, x0, lambda p, t, x: p.rhs(t, x, tau), lambda p, x: p.recentred(x),
        lambda p, x: p.chart_cos(x), 2.0, 0.05)
    E = np.array([p.energy(x) for p, x in zip(plants, states)])
    # drift (see _passive), relative to the energy of the motion (~0.08 J)
    assert np.max(np.abs(E - E0)) / abs(E0) <= 1e-8
    beta = np.degrees(np.unwrap([pitch_about_y(world_rotation(p, x)) for p, x in zip(plants, states)]))
    assert beta[0] == pytest.approx(80.0) and np.max(beta) > 100.0
    assert min(np.hypot(*world_rotation(p, x)[2, 1:]) for p, x in zip(plants, states)) < 0.05
    # the arms moved (the springs coupled them): not an object alone
    assert np.max(np.abs(states[-1][nz:2 * nz - 6])) > 1e-3
    # the book's world angles at pitch exactly 90 deg: the old stop
    xw = x0.copy()
    xw[nz - 2] = np.pi / 2
    with pytest.raises(EulerSingularityError, match="object"):
        plant.rhs(0.0, xw, tau)
    charted, xc = own.recentred(xw)
    assert np.all(np.isfinite(charted.rhs(0.0, xc, tau)))
