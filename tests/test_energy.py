"""Energy conservation of the whole cooperative plant (docs/model.md s.3: without damping and input,
T + Pi + gravity is conserved), integrated with scipy's DOP853 as the reference integrator.

What is checked: ``plant.energy`` (arm and node kinetic energy through Gamma, elastic energy,
gravity of nodes and links) stays constant along ``plant.rhs`` with ``tau = 0``. This ties the
assembly (177, 183), the arm dynamics, the elastic forces and the gyroscopic terms together: a
missing or inconsistent term shows up as an energy drift of the order of that term.

Scenes start at the assembled unloaded state ``x0`` (springs undeformed, gravity not
balanced) plus small random joint velocities; with tau = 0 the arms then sag under gravity and
the object swings in its springs. Checked over the 5 s horizon: neither the Puma nor the planar
3R scenes reach an Euler or kinematic singularity (rhs would raise), so full gravity is kept.
Stiffness is moderate (5e3 N/m, 50 N m/rad) to keep each case around 0.5 s of wall time.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from _scenes import scene

HORIZON = 5.0  # [s]
# DOP853 with rtol = atol = 1e-10 keeps the local error per step at ~1e-10 of the state; over
# ~3000 steps the energy wanders by ~1e-9 relative (measured 1e-10 to 3e-10). The required bound
# 1e-6 leaves three orders of margin; a wrong term (e.g. a missing J^T W Jdot qdot, or F_e not
# the gradient of Pi) drifts by 1e-3 to 1 relative.
ENERGY_RTOL = 1e-6


def _run(plant, x0, horizon=HORIZON):
    tau = np.zeros(plant.input_size)
    t_eval = np.linspace(0.0, horizon, 101)
    sol = solve_ivp(lambda t, x: plant.rhs(t, x, tau), (0.0, horizon), x0, method="DOP853",
                    rtol=1e-10, atol=1e-10, t_eval=t_eval)
    assert sol.success, sol.message
    E = np.array([plant.energy(sol.y[:, k]) for k in range(sol.y.shape[1])])
    nz = plant.nz
    T = np.array([0.5 * sol.y[nz:, k] @ plant.mass_matrix(sol.y[:, k]) @ sol.y[nz:, k]
                  for k in range(sol.y.shape[1])])
    return sol, E, T


def _check(E, T):
    # Relative to max(|E0|, max T): E has an arbitrary gravity offset (it can be near 0 or
    # large), so |E0| alone is not a meaningful scale; the largest kinetic energy reached
    # measures how much energy was actually exchanged during the run. Taking the max of the
    # two never makes the test stricter than either alone would be meaningful for.
    scale = max(abs(E[0]), T.max())
    assert T.max() > 1e-3 * scale  # the system really moved
    drift = np.abs(E - E[0]).max()
    assert drift <= ENERGY_RTOL * scale, f"energy drift {drift:.3e} J of scale {scale:.3e} J"


@pytest.mark.parametrize("space", ["planar", "spatial"])
@pytest.mark.parametrize("m", [2, 3])
@pytest.mark.parametrize("element", ["offset", "central"])
def test_energy_conserved_full_arms(space, m, element):
    plant, x0 = scene(space, m, arms="full", element=element, stiffness=5e3, torsion=50.0,
                      node_springs=(m == 3))
    rng = np.random.default_rng(100 + 10 * m + (space == "spatial"))
    x = x0.copy()
    nq = plant.input_size
    x[plant.nz:plant.nz + nq] = rng.normal(0.0, 0.1, nq)  # joint velocities [rad/s]
    sol, E, T = _run(plant, x)
    _check(E, T)
    # the arms did move away from the start (gravity is not balanced)
    assert np.abs(sol.y[:nq, -1] - x0[:nq]).max() > 1e-2


@pytest.mark.parametrize("space", ["planar", "spatial"])
def test_energy_conserved_contact_points(space):
    """Contact points only: with gravity and tau = 0 everything would free-fall together, and
    the fall's kinetic energy (~3 kJ after 5 s) would swamp the elastic exchange, so gravity is
    off and the nodes start with random velocities (gyroscopic terms of all nodes active)."""
    plant, x0 = scene(space, 3, arms="contact", element="offset", stiffness=5e3, torsion=50.0,
                      gravity=0.0, node_springs=True)
    rng = np.random.default_rng(7)
    x = x0.copy()
    x[plant.nz:] = rng.normal(0.0, 0.3, plant.nz)
    sol, E, T = _run(plant, x)
    _check(E, T)
    # the elastic energy took part: it varied by more than 1 % of the kinetic energy
    Pi = [plant.elastic_potential(plant.node_poses(sol.y[:, k])) for k in range(sol.y.shape[1])]
    assert np.ptp(Pi) > 1e-2 * T.max()


@pytest.mark.parametrize("space,horizon", [
    ("planar", 1.0),
    ("spatial", 0.5),
])
def test_energy_conserved_immobile(space, horizon):
    """Immobile unloaded state (4.5): constant W(Y_ref), linear springs; still a Lagrangian
    system (N = H + J^T W_ref J with the J^T W_ref Jdot qdot term), so energy is conserved.
    With tau = 0 the arms fall and spin freely (tens of revolutions and ~10 kJ by t = 5 s);
    the linear model is for small displacements, and once two nodes' relative rotation passes
    pi a periodic (wrapped) linear torsion law must jump, so the planar horizon is 1 s. Spatial: the linear (Euler-angle) torsion springs let
    node 1 reach theta = pi/2 at t ~ 0.74 s (rhs raises EulerSingularityError, as it should),
    so the horizon is cut to 0.5 s."""
    plant, x0 = scene(space, 2, arms="full", element="central", stiffness=5e3, torsion=50.0,
                      unloaded_state="immobile")
    rng = np.random.default_rng(3)
    x = x0.copy()
    x[plant.nz:plant.nz + plant.input_size] = rng.normal(0.0, 0.1, plant.input_size)
    _, E, T = _run(plant, x, horizon)
    _check(E, T)


@pytest.mark.parametrize("space", ["planar", "spatial"])
@pytest.mark.parametrize("arms", ["full", "contact"])
@pytest.mark.parametrize("element", ["offset", "central"])
def test_power_balance_with_damping_and_input(space, arms, element):
    """dE/dt = tau . z' - 2 D(Y, Y') (Rayleigh, 110-112): input power minus dissipation, at a
    random state. dE/dt by a central difference of E along the flow f = rhs(x, tau)."""
    plant, x0 = scene(space, 2, arms=arms, element=element, stiffness=5e3, torsion=50.0,
                      damping=30.0, torsion_damping=0.3)
    rng = np.random.default_rng(11)
    nz, nq = plant.nz, plant.input_size
    x = x0.copy()
    x[:nq] += rng.normal(0.0, 0.02, nq)
    x[nz:] = rng.normal(0.0, 0.3, nz)
    tau = rng.normal(0.0, 5.0, nq)
    f = plant.rhs(0.0, x, tau)
    h = 1e-6
    dE = (plant.energy(x + h * f) - plant.energy(x - h * f)) / (2 * h)
    Y, dY = plant.node_poses(x), plant.node_velocities(x)
    P_in, P_d = tau @ x[nz:nz + nq], 2.0 * plant.elastic.dissipation(Y, dY)
    assert P_d > 0.0
    # truncation ~h^2 |E'''| and rounding ~eps |E| / h ~ 1e-16 * 350 / 1e-6 ~ 4e-8 W against
    # powers of ~10 W: 1e-6 relative; a missing damping or input term is O(1) relative
    assert abs(dE - (P_in - P_d)) <= 1e-6 * max(abs(P_in), P_d)
