"""Tests of coopctrl.trajectory.GeodesicTrajectory (minimum jerk on the rotation group, issue 20)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation, Slerp

from coopctrl.errors import ScenarioError
from coopctrl.loop.euler_band import EULER_PITCH_MARGIN_DEG
from coopctrl.trajectory import (
    EULER_VIEW_MARGIN_DEG,
    PEAK_VELOCITY_FACTOR,
    EulerViewError,
    GeodesicTrajectory,
    MinimumJerkTrajectory,
)


def random_vias(k=4, seed=0, angle=1.2):
    rng = np.random.default_rng(seed)
    times = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 2.0, k - 1))))
    return times, np.hstack((rng.uniform(-1.0, 1.0, (k, 3)), rng.uniform(-angle, angle, (k, 3))))


def profile_time(tr, t):
    """The time of a linear-in-time slerp that is at the same point as the min-jerk path at ``t``."""
    times = tr.times
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
    T = np.diff(times)[i]
    tau = np.clip((t - times[i]) / T, 0.0, 1.0)
    return times[i] + T * tau**3 * (10 - 15 * tau + 6 * tau**2)


def rotations(q):
    return Rotation.from_quat(np.asarray(q)[:, [1, 2, 3, 0]])


def test_rotations_are_scipy_slerp_on_the_minimum_jerk_profile():
    times, poses = random_vias()
    tr = GeodesicTrajectory(times, poses)
    t = np.linspace(-0.5, tr.duration + 0.5, 301)
    m = tr.sample_rotation(t)
    reference = Slerp(times, Rotation.from_euler("ZYX", poses[:, 3:]))(profile_time(tr, t))
    # angle of R^T R_ref: rounding of a few quaternion products (1e-14 rad)
    assert np.max((rotations(m.q).inv() * reference).magnitude()) < 1e-13
    np.testing.assert_allclose(np.linalg.norm(m.q, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(m.r, MinimumJerkTrajectory(times, poses, "spatial").sample(t)[0][:, :3], atol=1e-14)
    # quaternion signs are continuous (no jump between q and -q at the vias)
    assert np.all(np.sum(m.q[1:] * m.q[:-1], axis=1) > 0.0)


def test_rates_match_finite_differences_of_the_rotation_and_of_the_rates():
    times, poses = random_vias(seed=3)
    tr = GeodesicTrajectory(times, poses)
    h = 1e-5
    t = np.random.default_rng(4).uniform(0.0, tr.duration, 20)
    a, b, c = (tr.sample_rotation(t + d) for d in (-h, 0.0, h))
    Ra, Rc = rotations(a.q), rotations(c.q)
    # central differences: truncation h^2 |d^3/dt^3| ~ 1e-10 * O(100), rounding eps / h ~ 1e-11
    np.testing.assert_allclose((Rc * Ra.inv()).as_rotvec() / (2 * h), b.omega, atol=1e-7)
    np.testing.assert_allclose((Ra.inv() * Rc).as_rotvec() / (2 * h), b.omega_body, atol=1e-7)
    np.testing.assert_allclose((c.omega - a.omega) / (2 * h), b.alpha, atol=1e-7)
    np.testing.assert_allclose((c.omega_body - a.omega_body) / (2 * h), b.alpha_body, atol=1e-7)
    np.testing.assert_allclose((c.r - a.r) / (2 * h), b.dr, atol=1e-7)
    np.testing.assert_allclose(rotations(b.q).apply(b.omega_body), b.omega, atol=1e-14)


def test_euler_view_is_the_rotation_and_its_rates_match_finite_differences():
    times, poses = random_vias(seed=5, angle=0.6)  # pitch stays below 85 deg: |theta| <= 3 * 0.6 rad
    tr = GeodesicTrajectory(times, poses)
    t = np.sort(np.random.default_rng(6).uniform(0.0, tr.duration, 97))  # off the vias: the jerk jumps there
    Y, dY, ddY = tr.sample(t)
    assert Y.shape == dY.shape == ddY.shape == (97, 6)
    m = tr.sample_rotation(t)
    assert np.max((Rotation.from_euler("ZYX", Y[:, 3:]).inv() * rotations(m.q)).magnitude()) < 1e-13
    h = 1e-5
    Ym, dYm, _ = tr.sample(t - h)
    Yp, dYp, _ = tr.sample(t + h)
    np.testing.assert_allclose((Yp - Ym) / (2 * h), dY, atol=1e-7)  # as above
    np.testing.assert_allclose((dYp - dYm) / (2 * h), ddY, atol=1e-7)
    Y0, dY0, ddY0 = tr.evaluate(float(t[40]))
    np.testing.assert_allclose(Y0, Y[40], atol=1e-15)
    np.testing.assert_allclose(dY0, dY[40], atol=1e-15)
    np.testing.assert_allclose(ddY0, ddY[40], atol=1e-14)


def test_rest_to_rest_at_every_via_and_held_outside():
    times, poses = random_vias(k=5, seed=7)
    tr = GeodesicTrajectory(times, poses)
    t = np.concatenate(([-1.0], times, [tr.duration + 1.0]))
    m = tr.sample_rotation(t)
    for v in (m.dr, m.ddr, m.omega, m.alpha, m.omega_body, m.alpha_body):
        assert not v.any()  # s'(0) = s'(1) = s''(0) = s''(1) = 0 exactly
    at_vias = rotations(m.q[1:-1]).inv() * Rotation.from_euler("ZYX", poses[:, 3:])
    assert np.max(at_vias.magnitude()) < 1e-13
    Y, dY, ddY = tr.sample(t)
    assert not dY.any() and not ddY.any()
    np.testing.assert_allclose(Y[1], poses[0], atol=1e-15)  # the Euler view starts at the angles as written


def test_a_path_through_pitch_90_deg_is_smooth_and_its_euler_view_refuses_the_band():
    T = 2.0
    tr = GeodesicTrajectory([0.0, T], [[0, 0, 0, 0, 0, 0], [0.1, 0, 0.2, 0, math.radians(120), 0]])
    np.testing.assert_allclose(tr.rotation_vectors, [[0.0, math.radians(120), 0.0]], atol=1e-15)
    t = np.linspace(0.0, T, 2001)
    m = tr.sample_rotation(t)
    np.testing.assert_allclose(np.linalg.norm(m.q, axis=1), 1.0, atol=1e-14)
    speed = np.linalg.norm(m.omega, axis=1)
    assert speed.max() <= PEAK_VELOCITY_FACTOR * math.radians(120) / T * (1 + 1e-12)
    assert speed.max() >= PEAK_VELOCITY_FACTOR * math.radians(120) / T * (1 - 1e-6)  # grid hits tau = 1/2
    np.testing.assert_allclose(m.omega[:, [0, 2]], 0.0, atol=1e-15)  # about y only
    pitch = Rotation.from_quat(m.q[:, [1, 2, 3, 0]]).as_euler("ZYX")[:, 1]
    assert np.max(np.abs(pitch)) > math.radians(89.9)  # it does pass the singular pitch
    # the view exists up to s = 85/120 and again from s = 95/120 (pure pitch: theta = 120 s deg)
    tau_in = brentq(lambda tau: tau**3 * (10 - 15 * tau + 6 * tau**2) - 85.0 / 120.0, 0.0, 1.0)
    segment, t_in, pitch_in = tr.euler_band_entry()
    assert segment == 0 and abs(pitch_in) == pytest.approx(85.0, abs=0.34)  # one table step: 0.33 deg
    assert t_in == pytest.approx(tau_in * T, abs=T / 1024)
    with pytest.raises(EulerViewError, match=r"t = 1\.31 s: its ZYX pitch 8\d\.\d+ deg is within 5 deg") as info:
        tr.sample([0.0, 1.33, 1.31])  # the earliest time inside is named (the band is t = 1.230 .. 1.335 s, pitch 90 deg at 1.281 s)
    assert "\n" not in str(info.value) and info.value.time == 1.31
    with pytest.raises(EulerViewError):
        tr.evaluate(1.33)
    # after the band the view continues on the family with theta > 90 deg (pure pitch: 0, 120 s, 0)
    Y, _, _ = tr.sample([0.0, 1.9, T])
    np.testing.assert_allclose(Y[-1, 3:], [0.0, math.radians(120), 0.0], atol=1e-13)


def test_single_axis_yaw_equals_the_component_wise_interpolation():
    # psi crosses +pi (3.0 -> 4.0 rad) with a constant pitch and roll: the geodesic is about world z
    poses = [[0.0, 0.1, 0.2, 3.0, 0.3, -0.2], [0.5, 0.1, 0.0, 4.0, 0.3, -0.2], [0.5, 0.0, 0.0, 3.5, 0.3, -0.2]]
    times = [0.0, 1.5, 2.0]
    t = np.linspace(-0.1, 2.1, 89)
    for ours, book in zip(GeodesicTrajectory(times, poses).sample(t),
                          MinimumJerkTrajectory(times, poses, "spatial").sample(t)):
        np.testing.assert_allclose(ours, book, rtol=0, atol=1e-13)  # rounding of the quaternion round trip


def test_quaternion_and_euler_vias_give_the_same_trajectory():
    times, poses = random_vias(seed=9)
    q = Rotation.from_euler("ZYX", poses[:, 3:]).as_quat()[:, [3, 0, 1, 2]]
    q[1] *= -1.0  # the other sign of the same rotation
    mixed = [np.concatenate((p[:3], qq)) if k % 2 else p for k, (p, qq) in enumerate(zip(poses, q))]
    a, b = GeodesicTrajectory(times, poses), GeodesicTrajectory(times, np.hstack((poses[:, :3], q)))
    c = GeodesicTrajectory(times, mixed)
    t = np.linspace(0.0, a.duration, 73)
    ma = a.sample_rotation(t)
    for other in (b, c):
        mo = other.sample_rotation(t)
        sign = np.sign(np.sum(ma.q * mo.q, axis=1))[:, None]
        np.testing.assert_allclose(mo.q * sign, ma.q, atol=1e-14)
        for u, v in zip(ma[4:], mo[4:]):
            np.testing.assert_allclose(u, v, atol=1e-13)
        np.testing.assert_allclose(other.rotation_vectors, a.rotation_vectors, atol=1e-14)


def test_half_turn_and_zero_rotation():
    # psi = pi and psi = -pi are one rotation: the half turn about z is taken about +z both ways
    for end in (math.pi, -math.pi):
        tr = GeodesicTrajectory([0.0, 1.0], [[0, 0, 0, 0, 0, 0], [0, 0, 0, end, 0, 0]])
        np.testing.assert_allclose(tr.rotation_vectors, [[0.0, 0.0, math.pi]], atol=1e-15)
    still = GeodesicTrajectory([0.0, 1.0, 2.0], [[0, 0, 0, 0.3, 0.2, 0.1], [1, 0, 0, 0.3, 0.2, 0.1],
                                                 [1, 0, 0, 0.3 + 1e-13, 0.2, 0.1]])
    m = still.sample_rotation(np.linspace(0.0, 2.0, 21))
    assert np.all(np.isfinite(m.q)) and np.all(np.isfinite(m.alpha))
    assert np.max(np.abs(m.omega[:10])) < 1e-16  # equal vias: rounding of q0^-1 q1 (1e-18 rad)
    assert np.max(np.abs(m.omega)) < 1e-12  # 1e-13 rad over 1 s
    np.testing.assert_allclose(np.linalg.norm(still.rotation_vectors[1]), 1e-13, rtol=1e-2)


@pytest.mark.parametrize(
    "times, poses, field",
    [
        ([0.0, 1.0], [[0, 0, 0, 0, 0, 0], [0, 0, 0, 1.1, 0, 0, 0]], r"poses\[1, 3:7\]"),
        ([0.0, 1.0], [[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0, 0]], r"poses\[1, 3:7\]"),
        ([0.0, 1.0], [[0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]], r"poses\[0\]"),
        ([0.0, 1.0], [[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, math.nan, 0]], r"poses\[1, 4\]"),
        ([0.0, 1.0], [[0, 0, 0, 0, 0, 0]], "poses"),
        ([0.0, 1.0], [["a", 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]], "poses"),
        ([0.0, 1.0], 3.0, "poses"),
        ([0.5, 1.0], np.zeros((2, 6)), r"times\[0\]"),
        ([0.0, 2.0, 1.0], np.zeros((3, 6)), r"times\[2\]"),
        ([], np.zeros((0, 6)), "times"),
    ],
)
def test_bad_input_is_one_line_naming_the_field(times, poses, field):
    with pytest.raises(ScenarioError, match=rf"^{field} = ") as info:
        GeodesicTrajectory(times, poses)
    assert "\n" not in str(info.value) and "expected" in str(info.value)


def test_planar_space_is_refused_and_near_unit_quaternions_normalized():
    with pytest.raises(ScenarioError, match=r"^space = 'planar' is invalid"):
        GeodesicTrajectory([0.0], [[0, 0, 0, 1, 0, 0, 0]], "planar")
    tr = GeodesicTrajectory([0.0], [[0, 0, 0, 1.0 + 5e-7, 0, 0, 0]])  # within the 1e-6 tolerance
    np.testing.assert_allclose(tr.quaternions, [[1.0, 0.0, 0.0, 0.0]], rtol=0, atol=1e-16)
    assert tr.poses.shape == (1, 6) and tr.peak_times().size == 0


def test_closed_form_peaks_bound_a_dense_sampling_and_are_reached():
    times, poses = random_vias(k=4, seed=11)
    tr = GeodesicTrajectory(times, poses)
    v_peak, a_peak = tr.peaks()
    assert v_peak.shape == a_peak.shape == (3, 6)
    t = np.linspace(0.0, tr.duration, 20001)
    m = tr.sample_rotation(t)
    seg = np.clip(np.searchsorted(tr.times, t, side="right") - 1, 0, 2)
    v, a = np.hstack((m.dr, m.omega_body)), np.hstack((m.ddr, m.alpha_body))
    # rounding of the polynomials: 1e-12 relative
    assert np.all(np.abs(v) <= v_peak[seg] * (1 + 1e-12) + 1e-15)
    assert np.all(np.abs(a) <= a_peak[seg] * (1 + 1e-12) + 1e-15)
    mp = tr.sample_rotation(tr.peak_times())
    vp, ap = np.hstack((mp.dr, mp.omega_body)), np.hstack((mp.ddr, mp.alpha_body))
    np.testing.assert_allclose(np.abs(vp[1::3]), v_peak, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(np.abs(ap[0::3]), a_peak, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(np.abs(ap[2::3]), a_peak, rtol=1e-9, atol=1e-12)


def test_the_euler_view_refuses_the_loops_band():
    assert EULER_VIEW_MARGIN_DEG == EULER_PITCH_MARGIN_DEG


def test_time_arguments_are_checked():
    tr = GeodesicTrajectory(*random_vias())
    with pytest.raises(ValueError, match="t = nan"):
        tr.evaluate(math.nan)
    with pytest.raises(ValueError, match="non-finite"):
        tr.sample([0.0, math.inf])
    with pytest.raises(ValueError, match="1-D"):
        tr.sample_rotation([[0.0]])
