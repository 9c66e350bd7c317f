"""Tests of coopctrl.trajectory.MinimumJerkTrajectory."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from coopctrl.errors import ScenarioError
from coopctrl.trajectory import PEAK_VELOCITY_FACTOR, MinimumJerkTrajectory

SPACES = {"spatial": 6, "planar": 3}


def make(space, k=4, seed=0):
    rng = np.random.default_rng(seed)
    times = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 2.0, k - 1))))
    poses = rng.uniform(-1.0, 1.0, (k, SPACES[space]))
    return MinimumJerkTrajectory(times, poses, space)


@pytest.mark.parametrize("space", SPACES)
def test_boundary_conditions_at_via_points(space):
    tr = make(space)
    for ti, Yi in zip(tr.times, tr.poses):
        Y, dY, ddY = tr.evaluate(float(ti))
        assert Y.shape == dY.shape == ddY.shape == (SPACES[space],)
        np.testing.assert_allclose(Y, Yi, atol=1e-14)
        np.testing.assert_allclose(dY, 0.0, atol=1e-12)
        np.testing.assert_allclose(ddY, 0.0, atol=1e-12)


@pytest.mark.parametrize("space", SPACES)
def test_holds_before_start_and_after_end(space):
    tr = make(space)
    for t, pose in ((-1.0, tr.poses[0]), (tr.duration + 5.0, tr.poses[-1])):
        Y, dY, ddY = tr.evaluate(t)
        np.testing.assert_array_equal(Y, pose)
        assert not dY.any() and not ddY.any()
    assert tr.duration == tr.times[-1]


@pytest.mark.parametrize("space", SPACES)
def test_continuity_at_via_points(space):
    tr = make(space, k=5)
    eps = 1e-9
    for ti in tr.times[1:-1]:
        left = tr.evaluate(float(ti) - eps)
        right = tr.evaluate(float(ti) + eps)
        for a, b, tol in zip(left, right, (1e-8, 1e-6, 1e-5)):
            np.testing.assert_allclose(a, b, atol=tol)


@pytest.mark.parametrize("space", SPACES)
def test_derivatives_match_finite_differences(space):
    tr = make(space, k=4, seed=3)
    rng = np.random.default_rng(7)
    d = 1e-6
    for t in rng.uniform(0.0, tr.duration, 25):
        Y, dY, ddY = tr.evaluate(t)
        Yp, dYp, _ = tr.evaluate(t + d)
        Ym, dYm, _ = tr.evaluate(t - d)
        np.testing.assert_allclose(dY, (Yp - Ym) / (2 * d), rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(ddY, (dYp - dYm) / (2 * d), rtol=1e-5, atol=1e-6)


def test_peak_velocity_of_one_segment():
    start = np.array([0.1, -0.2, 0.3, 0.0, 0.1, -0.3])
    goal = np.array([0.6, 0.4, -0.1, 0.5, -0.2, 0.2])
    T = 2.5
    tr = MinimumJerkTrajectory([0.0, T], [start, goal], "spatial")
    t = np.linspace(0.0, T, 2001)
    _, dY, _ = tr.sample(t)
    speed = np.abs(dY).max(axis=0)
    np.testing.assert_allclose(speed, PEAK_VELOCITY_FACTOR * np.abs(goal - start) / T, rtol=1e-9)
    _, dY_mid, _ = tr.evaluate(T / 2)
    np.testing.assert_allclose(dY_mid, 1.875 * (goal - start) / T, rtol=1e-12)
    assert PEAK_VELOCITY_FACTOR == 1.875


@pytest.mark.parametrize("space", SPACES)
def test_sample_matches_evaluate(space):
    tr = make(space, k=5, seed=11)
    t = np.concatenate(([-0.5, 0.0], np.linspace(0, tr.duration, 97), tr.times, [tr.duration + 1.0]))
    Ys, dYs, ddYs = tr.sample(t)
    assert Ys.shape == (t.shape[0], SPACES[space])
    for k, tk in enumerate(t):
        Y, dY, ddY = tr.evaluate(float(tk))
        np.testing.assert_allclose(Ys[k], Y, atol=1e-14)
        np.testing.assert_allclose(dYs[k], dY, atol=1e-12)
        np.testing.assert_allclose(ddYs[k], ddY, atol=1e-11)


def test_single_pose_is_constant():
    tr = MinimumJerkTrajectory([0.0], [[1.0, 2.0, 0.3]], "planar")
    assert tr.duration == 0.0
    Y, dY, ddY = tr.evaluate(1.0)
    np.testing.assert_array_equal(Y, [1.0, 2.0, 0.3])
    Ys, dYs, _ = tr.sample([0.0, 1.0])
    np.testing.assert_array_equal(Ys, [[1.0, 2.0, 0.3]] * 2)
    assert not dYs.any()


def test_frozen_and_returns_fresh_arrays():
    tr = make("planar")
    with pytest.raises(dataclasses.FrozenInstanceError):
        tr.space = "spatial"
    with pytest.raises(ValueError):
        tr.poses[0, 0] = 5.0
    Y, _, _ = tr.evaluate(tr.duration + 1)
    Y[:] = 99.0
    assert not np.any(tr.evaluate(tr.duration + 1)[0] == 99.0)
    Y, _, _ = tr.evaluate(0.3)
    Y[:] = 99.0
    assert not np.any(tr.evaluate(0.3)[0] == 99.0)


def test_input_arrays_are_copied():
    times = np.array([0.0, 1.0])
    poses = np.zeros((2, 3))
    tr = MinimumJerkTrajectory(times, poses, "planar")
    poses[1] = 1.0
    times[1] = 5.0
    assert tr.duration == 1.0 and not tr.poses.any()


@pytest.mark.parametrize(
    "times, poses, space, field",
    [
        ([0.0, 1.0], np.zeros((2, 3)), "3d", "space"),
        ([0.5, 1.0], np.zeros((2, 3)), "planar", r"times\[0\]"),
        ([0.0, 1.0, 1.0], np.zeros((3, 3)), "planar", r"times\[2\]"),
        ([0.0, 2.0, 1.0], np.zeros((3, 3)), "planar", r"times\[2\]"),
        ([0.0, math.nan], np.zeros((2, 3)), "planar", r"times\[1\]"),
        ([], np.zeros((0, 3)), "planar", "times"),
        ([[0.0, 1.0]], np.zeros((2, 3)), "planar", "times"),
        ([0.0, 1.0], np.zeros((2, 6)), "planar", "poses"),
        ([0.0, 1.0], np.zeros((3, 6)), "spatial", "poses"),
        ([0.0, 1.0], [[0, 0, 0], [0, math.inf, 0]], "planar", r"poses\[1, 1\]"),
        ([0.0, 1.0], [["a", 0, 0], [0, 0, 0]], "planar", "poses"),
    ],
)
def test_validation_names_the_field(times, poses, space, field):
    with pytest.raises(ScenarioError, match=rf"^{field}") as info:
        MinimumJerkTrajectory(times, poses, space)
    assert isinstance(info.value, ValueError)


def test_evaluate_rejects_nan_time():
    with pytest.raises(ValueError, match="t = nan"):
        make("planar").evaluate(math.nan)
    with pytest.raises(ValueError, match="non-finite"):
        make("planar").sample([0.0, math.nan])


# ---------------------------------------------------------------- closed-form peaks (issue 22)
@pytest.mark.parametrize("space", SPACES)
def test_closed_form_peaks_bound_a_dense_sampling_and_are_reached(space):
    tr = make(space, k=5, seed=3)
    v_peak, a_peak = tr.peaks()
    assert v_peak.shape == a_peak.shape == (4, SPACES[space])
    t = np.linspace(0.0, tr.duration, 20001)
    _, dY, ddY = tr.sample(t)
    seg = np.clip(np.searchsorted(tr.times, t, side="right") - 1, 0, 3)
    # a dense grid never exceeds the closed-form peaks (relative rounding of the polynomials: 1e-12) ...
    assert np.all(np.abs(dY) <= v_peak[seg] * (1 + 1e-12) + 1e-15)
    assert np.all(np.abs(ddY) <= a_peak[seg] * (1 + 1e-12) + 1e-15)
    # ... and the peak instants reach them (the same polynomials at the exact instants: rounding)
    for tp in tr.peak_times():
        i = min(int(np.searchsorted(tr.times, tp, side="right")) - 1, 3)
        _, dYp, ddYp = tr.evaluate(float(tp))
        tau = (tp - tr.times[i]) / (tr.times[i + 1] - tr.times[i])
        if abs(tau - 0.5) < 1e-9:
            np.testing.assert_allclose(np.abs(dYp), v_peak[i], rtol=1e-9, atol=1e-12)
        else:
            np.testing.assert_allclose(np.abs(ddYp), a_peak[i], rtol=1e-9, atol=1e-12)


def test_a_one_via_trajectory_has_no_peaks():
    tr = MinimumJerkTrajectory([0.0], [[0.0, 0.3, 0.0]], "planar")
    v, a = tr.peaks()
    assert v.shape == a.shape == (0, 3) and tr.peak_times().size == 0
