"""Tests of coopctrl.tuning: linear models against the nonlinear closed loop, margins and poles
against simulation, gain design, and the gains' round trip into scenarios.

The nonlinear reference is the ClosedLoop that ``coopctrl run`` builds, with the test signals
injected by probes (coopctrl.tuning.loop_probes) and nothing else changed. The linear models are
finite-difference Jacobians of that loop over one period, with the followers' PI closed
analytically; the tests check that they predict what the loop does for small steps, and that
their frequency-domain figures predict where it stops being stable.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl import tuning
from coopctrl.errors import ScenarioError
from coopctrl.simulator import closed_loop
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.frequency import frequency_response
from coopctrl.tuning.leader_error_model import error_poles
from coopctrl.tuning.loop_probes import probe_errors, probed_closed_loop

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
PLANAR = SCENARIOS / "planar_two_arm_lift.toml"
SPATIAL = SCENARIOS / "spatial_two_puma_carry.toml"


def load(path, **overrides):
    return coopctrl.load_scenario(path, overrides or None)


@pytest.fixture(scope="module")
def planar():
    return tuning.linearize_closed_loop(load(PLANAR))


@pytest.fixture(scope="module")
def spatial():
    return tuning.linearize_closed_loop(load(SPATIAL))


# ---------------------------------------------------------------------- the closed-loop model
def test_closed_loop_model_signals(planar):
    sys = planar.closed()
    T = load(PLANAR).simulation.control_period
    assert sys.dt == T
    assert sys.input_labels == ["arm1_ref_x", "arm1_ref_z", "arm1_ref_theta",
                                "arm2_setpoint_Fx", "arm2_setpoint_Fz", "arm2_setpoint_M"]
    assert sys.state_labels[:3] == ["arm1_q1", "arm1_q2", "arm1_q3"]
    assert sys.state_labels[-3:] == ["arm2_force_integral_Fx", "arm2_force_integral_Fz", "arm2_force_integral_M"]
    for name in ("object_x", "object_theta", "arm1_node_z", "arm2_Fx", "arm1_M", "arm2_force_error_Fz"):
        assert name in sys.output_labels
    assert sys.nstates == 2 * (3 + 3 + 3) + 3  # (q, Y_0) and their rates, and one integral per component
    assert np.max(np.abs(sys.poles())) < 1.0


@pytest.mark.parametrize("model", ["planar", "spatial"])
def test_operating_point_is_an_equilibrium(model, request):
    """The held loop does not move from the operating point: the largest change of any state over
    one period and the force error are at the round-off floor of one period (1e-14 and 1e-12)."""
    op = request.getfixturevalue(model).operating_point
    assert op.drift <= 1e-12
    assert op.force_error <= 1e-9


# Steps: 5 mm / 10 mrad on the leader's target, 5 N on the follower's setpoint: ten times the
# errors of the carry in test_closed_loop, and still small enough for a linear model to hold.
STEPS = [("arm1_ref_x", 5e-3, ["arm1_node_x"]),
         ("arm1_ref_theta", 1e-2, ["arm1_node_theta"]),
         ("arm2_setpoint_Fx", 5.0, ["arm2_Fx"]),
         ("arm2_setpoint_Fz", 5.0, ["arm2_Fz"])]


@pytest.mark.parametrize("model", ["planar", "spatial"])
@pytest.mark.parametrize("input, amplitude, driven", STEPS)
def test_linear_model_matches_nonlinear_step(model, input, amplitude, driven, request):
    """The issue's criterion: relative error <= 2 %, where the error is
    ``max_t |y_nl - y_lin| / max_t |y_lin|`` over 0.4 s (the leader's and the force loop's settling
    times at the scenes' gains), for the driven output and, jointly, for the object position and
    for every measured force (each group in one unit). Measured: <= 2e-5 on the driven outputs
    and <= 0.4 % on the groups (the object's tilt under a leader rotation is the largest)."""
    m = request.getfixturevalue(model)
    r = tuning.simulate_step(m, input, amplitude, 0.4)
    assert r.status == "ok"
    forces = [n for n in r.outputs if n.split("_")[1] in ("Fx", "Fy", "Fz")]
    position = ["object_x", "object_z"] if m.space == "planar" else ["object_x", "object_y", "object_z"]
    assert r.relative_error(driven) <= 0.02
    assert r.relative_error(forces) <= 0.02
    assert r.relative_error(position) <= 0.02
    # the step did something: the driven output moved by at least half the step
    assert np.max(np.abs(r.nonlinear[:, r.columns(driven)])) >= 0.5 * amplitude


def test_pi_closed_on_the_model_matches_the_loop_with_other_gains(planar):
    """The followers' PI is closed analytically on the opened model; with gains other than the
    scene's the prediction still matches the nonlinear loop run with those gains (2 %)."""
    r = tuning.simulate_step(planar, "arm2_setpoint_Fx", 5.0, 0.4, force_kp=3.0, force_ki=150.0)
    assert r.status == "ok"
    assert r.relative_error(["arm2_Fx"]) <= 0.02
    # and the gains matter: the response differs from the scene's gains by far more than 2 %
    base = tuning.simulate_step(planar, "arm2_setpoint_Fx", 5.0, 0.4)
    c = r.columns("arm2_Fx")
    assert np.max(np.abs(r.linear[:, c] - base.linear[:, c])) >= 0.1 * 5.0


def test_probes_with_zero_signals_do_not_change_the_loop():
    """A probed loop is the loop: same run to the last bit."""
    # the reference path (proxsuite): the probes' signals are kernel inputs on every path
    s = load(PLANAR, **{"simulation.duration": 0.2, "load_distribution.solver": "proxsuite"})
    x0 = s.initial_state()
    plain = closed_loop(s).run(x0, 0.2)
    loop, _, _ = probed_closed_loop(s)
    probed = loop.run(x0, 0.2)
    assert np.array_equal(plain["x"], probed["x"]) and np.array_equal(plain["tau"], probed["tau"])


def test_probe_errors_are_read_from_the_record():
    """``probe_errors``: ``F* + r - F_meas`` per follower and tick. The first tick's split and measurement
    come before the setpoint step can act, so its error is the plain loop's plus the step ``r``."""
    s = load(PLANAR, **{"simulation.duration": 0.05})
    x0 = s.initial_state()
    loop, _, followers = probed_closed_loop(s)
    i = sorted(followers)[0]
    followers[i].setpoint_offset[0] = 2.0
    rec = loop.run(x0, 0.05)
    errors = probe_errors(rec, loop)
    assert sorted(errors) == sorted(followers) and errors[i].shape == (len(rec["t"]), loop.plant.p)
    plain = closed_loop(s).run(x0, 0.05)
    plain_error = plain["F_commanded"][0, i] - plain["F_measured"][0, i]
    # 1e-9 N: the two sums round differently (forces of tens of N, double precision: ~1e-14 N)
    np.testing.assert_allclose(errors[i][0], plain_error + followers[i].setpoint_offset, rtol=0, atol=1e-9)
    assert abs(errors[i][-1, 0] - (plain["F_commanded"][-1, i, 0] - plain["F_measured"][-1, i, 0] + 2.0)) > 1e-6


# ---------------------------------------------------------------------- leader loop
def test_leader_dominant_poles_are_the_designed_error_poles(planar):
    """The full closed loop has the two poles of the sampled error model of the leader's gains
    (computed torque on the exact model). With zeta = 1 the pair is (nearly) double, and a double
    pole moves by the square root of a perturbation: measured |dz| = 1.7e-3 (for zeta = 0.5 it is
    4e-5). The bound 2e-3 is 5 % of the poles' distance 1 - |z| = 0.04 to the unit circle."""
    ll = tuning.leader_loop(planar, "x")
    assert np.max(np.abs(np.sort_complex(ll.dominant_poles) - np.sort_complex(ll.design_poles))) <= 2e-3
    assert ll.dominant_frequency == pytest.approx(40.0, rel=0.06)


def _zeta_from_overshoot(overshoot):
    return -math.log(overshoot) / math.sqrt(math.pi**2 + math.log(overshoot) ** 2)


@pytest.mark.parametrize("zeta", [0.3, 0.5, 0.7])
def test_leader_poles_agree_with_simulated_step(zeta):
    """Damping and peak time of the nonlinear loop's step (leader target, 1 mm along x, the grip
    axis) against the second-order figures of the model's dominant poles.

    Tolerances: the x channel also carries the object's and the follower's modes, which the
    second-order formula ignores (the full linear model, which matches the loop to 1e-5, puts its
    own overshoot-implied damping within 0.009 of the pole pair for these gains): |dzeta| <= 0.015.
    The peak is located to one control period and the ZOH delays the response by about half of
    one: |dt_peak| <= 5 ms (measured <= 3.7 ms).
    """
    import control

    m = tuning.linearize_closed_loop(load(PLANAR, **{"controllers.leader.damping_ratio": zeta}))
    ll = tuning.leader_loop(m, "x")
    r = tuning.simulate_step(m, "arm1_ref_x", 1e-3, 0.5)
    y = r.nonlinear[:, r.columns("arm1_node_x")[0]]
    info = control.step_info(y, r.t)
    assert _zeta_from_overshoot(info["Overshoot"] / 100) == pytest.approx(ll.dominant_damping, abs=0.015)
    assert info["PeakTime"] == pytest.approx(ll.predicted_step["peak_time_s"], abs=5e-3)
    # the comparison is not vacuous: the designed damping is visible in the response
    assert ll.dominant_damping == pytest.approx(zeta, abs=0.02)


# ---------------------------------------------------------------------- force loop
def test_force_loop_of_the_default_scene(planar):
    fl = tuning.force_loop(planar)
    assert (fl.follower, fl.component) == (1, "Fx")  # the grip normal of arm 2
    # the elastic mode it acts through: the object along x between two 2e4 N/m springs, 2 kg
    assert fl.elastic_coordinate == "object_x"
    assert fl.elastic_mode == pytest.approx(math.sqrt(2 * 2e4 / 2.0), rel=1e-3)
    assert fl.stable and 0 < fl.bandwidth_ratio < 1
    assert 0 < fl.margins.phase_margin < 180 and fl.margins.gain_margin > 1
    # the closed force loop tracks its setpoint at DC (integral action)
    assert float(np.squeeze(fl.closed_loop.dcgain())) == pytest.approx(1.0, abs=1e-6)


def test_closed_loop_has_the_elastic_modes(planar):
    """The nodes-held elastic modes (the object on its interconnections) are poles of the closed
    loop, within 5 % (the motion loops hold the nodes stiffly, not rigidly: measured 1.6 % for the
    translations, 2.5 % for the rotation)."""
    modes = tuning.elastic_modes(planar.scenario.plant(), planar.operating_point.x)
    wn = np.abs(np.log(planar.closed().poles().astype(complex))) / planar.control_period
    for w in modes.natural_frequencies:
        assert np.min(np.abs(wn - w)) <= 0.05 * w


def _run_perturbed(model, component, gain=1.0, delay=0, duration=1.0, step=0.1):
    """The nonlinear loop from the operating point with a small setpoint step on one component of
    follower arm 2, its loop gain scaled by ``gain`` and its measurement delayed ``delay`` periods.
    Returns the error of that component per tick."""
    c = names.component_index(model.space, component)
    loop, _, followers = probed_closed_loop(model.scenario)
    f = followers[1]
    f.error_gain[c] = gain
    f.measurement_delay[c] = delay
    f.setpoint_offset[c] = step
    rec = loop.run(model.operating_point.x, duration, integrals={1: model.operating_point.integrals[1]})
    return rec["status"], probe_errors(rec, loop)[1][:, c]


@pytest.mark.parametrize("model, component", [("planar", "Fx"), ("spatial", "Mx")])
def test_gain_margin_predicts_nonlinear_stability(model, component, request):
    """Scaling one force loop's gain (kp and ki) by 0.9 GM keeps the nonlinear loop stable (the
    step's error decays below 1 % of it), by 1.1 GM makes it unstable (the error ends larger than
    the step). Planar Fx: GM ~ 170 at the Nyquist frequency; spatial Mx: GM ~ 18 at 263 rad/s,
    near the grasp's rotational modes. The linear model agrees on both sides."""
    m = request.getfixturevalue(model)
    fl = tuning.force_loop(m, component=component)
    gm = fl.margins.gain_margin
    assert 1 < gm < 1e3
    kp, ki = m.force_gains
    for factor, stable in ((0.9, True), (1.1, False)):
        gains_kp = np.full(m.p, kp)
        gains_ki = np.full(m.p, ki)
        c = names.component_index(m.space, component)
        gains_kp[c] *= factor * gm
        gains_ki[c] *= factor * gm
        assert (np.max(np.abs(m.closed(gains_kp, gains_ki).poles())) < 1.0) == stable
        status, e = _run_perturbed(m, component, gain=factor * gm)
        late = np.max(np.abs(e[-100:]))
        if stable:
            assert status == "ok" and late <= 0.01 * 0.1
        else:
            assert status != "ok" or late >= 0.1


def test_delay_margin_predicts_nonlinear_stability(planar):
    """The phase margin at the crossover gives a delay margin PM / w_c (74 periods for the
    default Fx loop): a measurement delay of 0.9 of it keeps the nonlinear loop stable (the error
    decays over 3 s), 1.1 of it makes it oscillate and grow."""
    fl = tuning.force_loop(planar, component="Fx")
    ticks = fl.margins.delay_margin / planar.control_period
    assert 20 < ticks < 200
    _, e_ok = _run_perturbed(planar, "Fx", delay=int(math.floor(0.9 * ticks)), duration=3.0)
    _, e_bad = _run_perturbed(planar, "Fx", delay=int(math.ceil(1.1 * ticks)), duration=3.0)
    n = len(e_ok)
    assert np.max(np.abs(e_ok[-500:])) < 0.5 * np.max(np.abs(e_ok[n // 2 - 500:n // 2]))
    assert np.max(np.abs(e_bad[-500:])) > 2.0 * np.max(np.abs(e_bad[n // 2 - 500:n // 2]))


# ---------------------------------------------------------------------- frequency figures
def test_margins_and_bandwidth_against_closed_forms():
    """L = k / (s (s + 1)) sampled at T: the phase margin of the continuous loop is
    ``atan(1 / w_c)`` with ``w_c^2 (w_c^2 + 1) = k^2``; sampling adds ``w_c T / 2`` of lag (the
    ZOH's half-period delay), so at T = 1 ms the two agree to 0.05 deg. The bandwidth of a sampled
    first-order 10 / (s + 10) is 10 rad/s to 0.3 % (python-control 0.10.2's own bandwidth fails on
    discrete systems: see coopctrl.tuning.frequency) and exactly the closed form of its sampled
    transfer function."""
    import control

    k, T = 4.0, 1e-3
    L = control.c2d(control.tf([k], [1.0, 1.0, 0.0]), T)
    wc = math.sqrt((-1 + math.sqrt(1 + 4 * k * k)) / 2)
    pm = math.degrees(math.atan(1 / wc)) - math.degrees(wc * T / 2)
    m = tuning.margins(control.ss(L))
    assert m.gain_crossover == pytest.approx(wc, rel=1e-3)
    assert m.phase_margin == pytest.approx(pm, abs=0.05)
    G = control.c2d(control.tf([10.0], [1.0, 10.0]), T)
    # G(z) = (1 - a) / (z - a): |G|^2 = g2 = 10^(-3/10) (-3 dB) at cos(w T) = (1 + a^2 - (1 - a)^2 / g2) / (2 a)
    a, g2 = math.exp(-10.0 * T), 10 ** (-0.3)
    w_b = math.acos((1 + a * a - (1 - a) ** 2 / g2) / (2 * a)) / T
    assert tuning.bandwidth(control.ss(G)) == pytest.approx(w_b, rel=1e-8)
    assert w_b == pytest.approx(10.0, rel=3e-3)
    w = np.logspace(-1, 3, 7)
    assert np.allclose(frequency_response(control.ss(G), w), G(np.exp(1j * w * T)), rtol=1e-8)


# ---------------------------------------------------------------------- gain design
def test_follower_design_reaches_its_targets_and_round_trips(planar, tmp_path):
    """Design for 60 rad/s and 60 deg; the returned gains, written into the scenario and
    linearized again from it (no analytic PI closure), give the same figures."""
    d = tuning.follower_force_gains(planar, bandwidth_rad_s=60.0, phase_margin_deg=60.0)
    assert d.force_loop.bandwidth == pytest.approx(60.0, rel=0.01)
    assert d.force_loop.margins.phase_margin == pytest.approx(60.0, abs=0.5)
    assert d.gains.follower_force_loop is True
    out = d.gains.write_to(PLANAR, tmp_path / "tuned.toml")
    s = coopctrl.load_scenario(out)
    assert s.controllers.followers.force_kp == d.gains.follower_force_kp
    again = tuning.force_loop(tuning.linearize_closed_loop(s))
    assert again.bandwidth == pytest.approx(60.0, rel=0.01)
    assert again.margins.phase_margin == pytest.approx(60.0, abs=0.5)


@pytest.mark.parametrize("bandwidth, reason", [(200.0, "above the elastic mode"), (5000.0, "beyond the control rate"),
                                               (130.0, "motion loop")])
def test_follower_design_says_why_it_cannot(planar, bandwidth, reason):
    with pytest.raises(tuning.UnachievableDesign, match=reason) as info:
        tuning.follower_force_gains(planar, bandwidth_rad_s=bandwidth, phase_margin_deg=45.0)
    assert info.value.target["bandwidth_rad_s"] == bandwidth


def test_follower_design_rejects_bad_targets(planar):
    with pytest.raises(tuning.TuningError, match="phase_margin_deg"):
        tuning.follower_force_gains(planar, 50.0, 200.0)
    with pytest.raises(tuning.TuningError, match="bandwidth_rad_s"):
        tuning.follower_force_gains(planar, -1.0, 60.0)


def test_leader_lqr_closed_forms():
    """Continuous double integrator: ``K_p = sqrt(q1 / r)``, ``K_d = sqrt(q2 / r + 2 sqrt(q1 / r))``;
    sampled, the dlqr closed loop is exactly the error model with the returned (omega_n, zeta)."""
    q1, q2, r = 1e6, 4e2, 1.0
    d = tuning.leader_gains_lqr(np.diag([q1, q2]), r)
    kp, kd = math.sqrt(q1 / r), math.sqrt(q2 / r + 2 * math.sqrt(q1 / r))
    assert d.gains.leader_natural_frequency == pytest.approx(math.sqrt(kp), rel=1e-9)
    assert d.gains.leader_damping_ratio == pytest.approx(kd / (2 * math.sqrt(kp)), rel=1e-9)
    assert d.structure_error == 0.0 and d.note == ""
    T = 1e-3
    Q, R = tuning.bryson_weights(1e-3, 0.05, 5.0)
    dd = tuning.leader_gains_lqr(Q, R, T)
    assert np.allclose(np.sort_complex(dd.lqr_poles), np.sort_complex(dd.poles), atol=1e-12)


def test_leader_lqr_full_weights_are_mapped_and_said(planar):
    Q = np.diag([1e6, 1e6, 1e2, 400.0, 400.0, 4.0])
    d = tuning.leader_gains_lqr(Q, 0.04 * np.eye(3), 1e-3)
    assert d.structure_error > 0.1 and "nearest" in d.note
    assert d.natural_frequencies[0] != pytest.approx(d.natural_frequencies[2], rel=0.1)


def test_leader_lqr_design_poles_appear_in_the_closed_loop():
    """The design model is what the loop does: the returned gains, in the scene, put the leader's
    poles where the LQR put them (|dz| <= 2e-3, as in the pole test above)."""
    Q, R = tuning.bryson_weights(2e-3, 0.1, 20.0)
    d = tuning.leader_gains_lqr(Q, R, 1e-3)
    m = tuning.linearize_closed_loop(load(PLANAR), d.gains.as_overrides())
    ll = tuning.leader_loop(m, "x")
    assert np.max(np.abs(np.sort_complex(ll.dominant_poles) - np.sort_complex(d.lqr_poles))) <= 2e-3


def test_leader_gains_from_frequency_and_damping():
    g = tuning.leader_gains(60.0, 0.7, 1e-3)
    assert g.as_overrides() == {"controllers.leader.natural_frequency": 60.0, "controllers.leader.damping_ratio": 0.7}
    assert np.allclose(error_poles(60.0, 0.7), [complex(-42, 60 * math.sqrt(1 - 0.49)), complex(-42, -60 * math.sqrt(0.51))])
    with pytest.raises(tuning.UnachievableDesign, match="beyond the control rate"):
        tuning.leader_gains(3000.0, 0.7, 1e-3)
    with pytest.raises(ScenarioError, match="controllers.leader.damping_ratio"):
        tuning.leader_gains(60.0, -1.0)


# ---------------------------------------------------------------------- gains into scenarios
def test_gains_round_trip_overrides_toml_set_and_file(tmp_path):
    from coopctrl import cli

    g = tuning.Gains(leader_natural_frequency=55.0, leader_damping_ratio=0.8, follower_force_kp=0.0,
                     follower_force_ki=120.0)
    s = coopctrl.load_scenario(PLANAR, g.as_overrides())
    assert (s.controllers.leader.natural_frequency, s.controllers.followers.force_ki) == (55.0, 120.0)
    assert tomllib.loads(g.as_toml()) == {"controllers": {"leader": {"natural_frequency": 55.0, "damping_ratio": 0.8},
                                                          "followers": {"force_kp": 0.0, "force_ki": 120.0}}}
    assert cli.main(["check", str(PLANAR), *g.as_set_options()]) == 0
    out = g.write_to(PLANAR, tmp_path / "gains.toml")
    written = coopctrl.load_scenario(out)
    assert tuning.Gains.from_scenario(written) == tuning.Gains.from_scenario(s)
    assert written.springs == load(PLANAR).springs  # the rest of the scene is unchanged
    assert (tuning.Gains.from_scenario(s) | tuning.Gains(leader_damping_ratio=1.0)).leader_damping_ratio == 1.0


def test_gains_reject_values_the_scenario_rejects():
    with pytest.raises(ScenarioError, match="controllers.followers.force_ki"):
        tuning.Gains(follower_force_ki=-1.0)
    with pytest.raises(ScenarioError, match="controllers.leader.natural_frequency"):
        tuning.Gains(leader_natural_frequency=0.0)


# ---------------------------------------------------------------------- the plant alone
def test_plant_model_matches_the_nonlinear_plant():
    """A 0.05 N m torque step on arm 2's first joint, 50 ms, RK4 at 0.1 ms: the linear plant
    (ZOH-discretized at the same step) predicts the node and force deviations from the unforced
    run within 2 % (measured 1e-4: the loaded state is not an exact equilibrium, hence the
    difference of two runs)."""
    from coopctrl.integrators import get_integrator

    s = load(PLANAR)
    pm = tuning.linearize_plant(s)
    sys = pm.system
    assert sys.isctime() and sys.input_labels[3] == "arm2_tau1" and "arm2_Fx" in sys.output_labels
    assert pm.residual < 1e-4
    plant, rk4, h, n = s.plant(), get_integrator("rk4"), 1e-4, 500
    du = np.zeros(plant.input_size)
    du[3] = 0.05

    def run(tau):
        x, ys = pm.x.copy(), []
        for _ in range(n):
            ys.append(np.concatenate([plant.node_poses(x), plant.control_terms(x).Fw.reshape(-1)]))
            x = rk4.step(plant.rhs, 0.0, x, tau, h)
        return np.array(ys)

    dy = run(pm.tau + du) - run(pm.tau)
    import control

    lin = np.asarray(control.forced_response(pm.discretize(h), np.arange(n) * h,
                                             np.tile(du[:, None], (1, n))).outputs).T
    for group in (["arm2_node_x", "arm2_node_z"], ["arm2_Fx", "arm2_Fz"]):
        c = [sys.output_labels.index(g) for g in group]
        err = np.max(np.abs(dy[:, c] - lin[:, c])) / np.max(np.abs(lin[:, c]))
        assert err <= 0.02


def test_plant_model_of_an_immobile_scene_is_about_the_unloaded_state():
    s = load(SCENARIOS / "gripping_immobile_object.toml")
    pm = tuning.linearize_plant(s)
    from coopctrl.scenario import build

    assert np.array_equal(pm.x, build.unloaded_state(s))
    assert pm.residual == pytest.approx(9.81, rel=1e-6)  # the object's weight is not yet carried


def test_no_operating_point_is_reported():
    with pytest.raises(tuning.NoOperatingPoint, match="central_spring_buckling"):
        tuning.linearize_closed_loop(load(SCENARIOS / "central_spring_buckling.toml"))
