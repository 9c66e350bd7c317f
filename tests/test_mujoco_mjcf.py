"""coopctrl.mujoco.mjcf, state_map and plant: the MuJoCo model of each scene against the project's own kernels."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from coopctrl.mujoco.mjcf import node_body, scene_mjcf  # noqa: E402
from coopctrl.mujoco.plant import MujocoPlant  # noqa: E402
from coopctrl.mujoco.state_map import StateMap  # noqa: E402
from coopctrl.scenario import load_scenario  # noqa: E402
from coopctrl.scenario.build import build_plant  # noqa: E402
from plants.arms.urdf import COULOMB_SMOOTHING  # noqa: E402

SCENES = ("two_panda_carry", "ur5e_panda_carry", "three_iiwa_tray", "spatial_two_puma_carry", "planar_two_arm_lift")
#: Two recursions of the same rigid-body model (MuJoCo's CRB and RNE against the project's kernels) agree to
#: round-off: measured below 2e-15 relative; 1e-12 leaves room for other BLAS and compilers, and is far below any
#: modelling difference (a link's mass 1e-6 off would show at 1e-7).
REL_TOL = 1e-12


@pytest.fixture(scope="module", params=SCENES)
def scene(request):
    sc = load_scenario(request.param)
    plant = build_plant(sc)
    return sc, plant, MujocoPlant(sc, plant)


def _random_states(plant, sc, count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    sm = StateMap.from_plant(plant)
    n, nz = sm.n_q, sm.nz
    for _ in range(count):
        x = np.zeros(2 * nz)
        x[:n] = rng.uniform(-1.0, 1.0, n)
        x[nz:nz + n] = rng.uniform(-1.0, 1.0, n)
        x[n:nz] = np.asarray(sc.object.pose) + rng.uniform(-0.2, 0.2, sm.p)
        x[nz + n:] = rng.uniform(-0.5, 0.5, sm.p)
        yield x


def test_mass_matrix_and_bias_match_the_arm_kernels(scene):
    """Each arm's ``N = H + J^T W J`` (node included) and ``n = h + J^T (W Jdq + w_free)`` (177, 183) equal MuJoCo's
    joint-space inertia and bias forces (less its damper, plus the kernels' smoothed Coulomb) at seeded states."""
    sc, plant, mp = scene
    for x in _random_states(plant, sc, 4):
        mp.set_state(x)
        M = np.zeros((mp.model.nv, mp.model.nv))
        mujoco.mj_fullM(mp.model, mp.data, M) if _fullM_takes_data() else mujoco.mj_fullM(mp.model, M, mp.data.qM)
        terms = plant.control_terms(x)
        off = 0
        for i, arm in enumerate(plant.arms):
            d = arm.dof
            J = terms.J[i, :, :d]
            W = terms.W[i + 1]
            N = terms.H[i, :d, :d] + J.T @ W @ J
            bias = terms.h[i, :d] + J.T @ (W @ terms.Jdq[i] + terms.w_free[i + 1])
            sl = slice(off, off + d)
            mj_bias = (mp.data.qfrc_bias[sl] - mp.data.qfrc_damper[sl]
                       + mp.coulomb[sl] * np.tanh(mp.data.qvel[sl] / COULOMB_SMOOTHING))
            assert np.max(np.abs(M[sl, sl] - N)) <= REL_TOL * np.max(np.abs(N)), (sc.name, i)
            assert np.max(np.abs(mj_bias - bias)) <= REL_TOL * np.max(np.abs(bias)), (sc.name, i)
            off += d


def _fullM_takes_data() -> bool:
    return not hasattr(mujoco.MjData, "qM")


def test_nodes_and_state_map_are_exact(scene):
    """MuJoCo's node bodies sit at the plant's nodes ``Phi_i(q_i)``, and ``x -> (qpos, qvel) -> x`` is the identity."""
    sc, plant, mp = scene
    for x in _random_states(plant, sc, 3, seed=1):
        mp.set_state(x)
        Y = plant.arm_terms(x)[0]
        for i in range(plant.arm_count):
            pos = mp.data.xpos[mp.node_bodies[i + 1]]
            expected = Y[i + 1, :3] if plant.p == 6 else np.array([Y[i + 1, 0], 0.0, Y[i + 1, 1]])
            assert np.max(np.abs(pos - expected)) < 1e-12
        assert np.max(np.abs(mp.read_state() - x)) < 1e-12


def test_readings_are_the_state_by_name(scene):
    """``readings()`` (the fields of a controller's measurement) hold the plant state's parts, arm by arm, and the
    grasp wrenches the loop's sensors read (``contact_wrenches``) at that state."""
    sc, plant, mp = scene
    x = next(_random_states(plant, sc, 1, seed=3))
    mp.set_state(x)
    r = mp.readings()
    n, nz = mp.state_map.n_q, mp.state_map.nz
    assert np.array_equal(np.concatenate(r["q"]), x[:n]) and np.array_equal(np.concatenate(r["dq"]), x[nz:nz + n])
    assert [len(q) for q in r["q"]] == [a.dof for a in plant.arms]
    assert np.allclose(r["object_pose"], x[n:nz], rtol=0, atol=1e-12)
    assert np.allclose(r["object_twist"], x[nz + n:], rtol=0, atol=1e-12)
    assert np.allclose(r["wrench"], plant.contact_wrenches(x), rtol=0, atol=1e-9)


def test_force_sensors_carry_the_object_in_a_held_pose(scene):
    """At the loaded start, with the arms held still by their inverse-dynamics torques: MuJoCo's object
    acceleration is the elastic plant's (the start is the plant's static state, up to the loaded-state solve's
    residual), and the nodes' force sensors carry the object and the nodes: their world forces sum to
    ``(m_0 + sum m_i) g + m_0 a_0`` upward."""
    from coopctrl.scenario.build import initial_state

    sc, plant, mp = scene
    x0 = initial_state(sc)
    mp.set_state(x0)
    mp.apply(np.zeros(mp.state_map.n_q))  # the grasp wrenches of x0 in xfrc_applied
    d, m = mp.data, mp.model
    d.qacc[:] = 0.0
    mujoco.mj_inverse(m, d)
    grasp = np.zeros(m.nv)  # J^T of the grasp wrenches
    for b, w in zip(mp.node_bodies, d.xfrc_applied[mp.node_bodies]):
        mujoco.mj_applyFT(m, d, w[:3].copy(), w[3:].copy(), d.xipos[b].copy(), int(b), grasp)
    n, nz = mp.state_map.n_q, mp.state_map.nz
    d.qfrc_applied[:n] = d.qfrc_inverse[:n] - grasp[:n]
    mujoco.mj_forward(m, d)
    assert np.max(np.abs(d.qacc[:n])) < 1e-9  # [rad/s^2] the arms held (round-off of 100 N m over 0.01 kg m^2)
    a_plant = plant.rhs(0.0, x0, np.zeros(n))[nz + n:]  # the object's acceleration: Gamma is block diagonal
    a0 = np.zeros(3)
    if plant.p == 6:  # x0 is at rest: omega_dot = L(A_0) ddA_0
        from plants.frames import body_rate_map

        assert np.max(np.abs(d.qacc[n:n + 3] - a_plant[:3])) < 1e-9
        assert np.max(np.abs(d.qacc[n + 3:] - body_rate_map(x0[n + 3:nz]) @ a_plant[3:])) < 1e-9
        a0 = d.qacc[n:n + 3]
    else:
        assert np.max(np.abs(d.qacc[n:] - a_plant)) < 1e-9
        a0 = np.array([d.qacc[n], 0.0, d.qacc[n + 1]])
    total = np.zeros(3)
    for i in range(plant.arm_count):
        site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, node_body(i))
        total += d.site_xmat[site].reshape(3, 3) @ d.sensor(f"{node_body(i)}_force").data
    g = sc.scene.gravity
    carried = (sc.object.mass + sum(a.node_mass for a in sc.arms)) * np.array([0.0, 0.0, g]) + sc.object.mass * a0
    assert np.max(np.abs(total - carried)) < 1e-9 * np.linalg.norm(carried)


def test_exported_model_loads_with_its_start_keyframe():
    """The written XML compiles alone and its keyframe ``start`` is the plant state it was given."""
    sc = load_scenario("planar_two_arm_lift")
    plant = build_plant(sc)
    x = next(_random_states(plant, sc, 1, seed=2))
    model = mujoco.MjModel.from_xml_string(scene_mjcf(sc, x_start=x, plant=plant))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    assert np.max(np.abs(StateMap.from_plant(plant).state(data.qpos, data.qvel) - x)) < 1e-12


def test_contact_point_arms_have_no_body():
    sc = load_scenario("contact_points_only")
    with pytest.raises(ValueError, match=r"arms\[0\].model = 'contact_point' is invalid"):
        scene_mjcf(sc)


def test_closed_form_maps_match_the_frames_module():
    """The plant's closed forms against ``plants.frames`` at seeded angles: ``world_couples`` is
    ``R(A) L(A)^-T Q``, ``euler_rates`` is ``L(A)^-1 omega``, ``euler_zyx`` inverts ``R(A)``."""
    from coopctrl.mujoco.plant import world_couples
    from coopctrl.mujoco.state_map import euler_rates, euler_zyx
    from plants.frames import body_rate_map, rotation_zyx

    rng = np.random.default_rng(4)
    A = rng.uniform(-1.4, 1.4, (8, 3))
    Q = rng.normal(size=(8, 3))
    expected = np.array([rotation_zyx(a) @ np.linalg.solve(body_rate_map(a).T, q) for a, q in zip(A, Q)])
    assert np.max(np.abs(world_couples(A, Q) - expected)) < 1e-12 * np.max(np.abs(expected))
    for a, w in zip(A, Q):
        assert np.max(np.abs(euler_rates(a, w) - np.linalg.solve(body_rate_map(a), w))) < 1e-12 * np.max(np.abs(w)) / np.cos(a[1])
        assert np.max(np.abs(euler_zyx(rotation_zyx(a)) - a)) < 1e-12
