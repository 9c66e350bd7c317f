"""Tests of coopctrl.sensors: exactness when off, reproducibility, noise and quantization."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coopctrl.errors import ScenarioError
from coopctrl.sensors import Sensor, SensorConfig, SensorSuite


def values(seed=0):
    rng = np.random.default_rng(seed)
    return {
        "q": rng.normal(size=12),
        "dq": rng.normal(size=12),
        "F": rng.normal(size=(2, 6)) * 50.0,
        "Y0": rng.normal(size=6),
        "dY0": rng.normal(size=6),
    }


def read_all(suite, v):
    q, dq = suite.read_joints(v["q"], v["dq"])
    F = suite.read_forces(v["F"])
    Y0, dY0 = suite.read_object(v["Y0"], v["dY0"])
    return {"q": q, "dq": dq, "F": F, "Y0": Y0, "dY0": dY0}


def test_exact_when_off_returns_copies_and_draws_nothing():
    v = values()
    suite = SensorSuite(SensorConfig(), SensorConfig(), SensorConfig(), seed=1)
    state = [s.rng.bit_generator.state for s in (suite.joints, suite.forces, suite.object)]
    out = read_all(suite, v)
    for key in v:
        np.testing.assert_array_equal(out[key], v[key])
        assert out[key] is not v[key] and not np.shares_memory(out[key], v[key])
    assert state == [s.rng.bit_generator.state for s in (suite.joints, suite.forces, suite.object)]
    out["q"][:] = 0.0
    assert v["q"].any()


def test_exact_constructor():
    v = values(2)
    out = read_all(SensorSuite.exact(), v)
    for key in v:
        np.testing.assert_array_equal(out[key], v[key])


def test_seeded_reproducibility_and_seed_sensitivity():
    cfg = SensorConfig(noise_std=0.01, quantization=1e-4)
    v = values()
    a = [read_all(SensorSuite(cfg, cfg, cfg, seed=42), v) for _ in range(2)]
    b = read_all(SensorSuite(cfg, cfg, cfg, seed=43), v)
    for key in v:
        np.testing.assert_array_equal(a[0][key], a[1][key])
        assert not np.array_equal(a[0][key], b[key])


def test_channels_have_independent_streams():
    noisy, off = SensorConfig(noise_std=0.1), SensorConfig()
    v = values()
    only_forces = SensorSuite(off, noisy, off, seed=5).read_forces(v["F"])
    all_noisy = SensorSuite(noisy, noisy, noisy, seed=5)
    all_noisy.read_joints(v["q"], v["dq"])
    np.testing.assert_array_equal(all_noisy.read_forces(v["F"]), only_forces)


@pytest.mark.parametrize("std", [1e-3, 0.5, 20.0])
def test_noise_statistics(std):
    sensor = Sensor(SensorConfig(noise_std=std), np.random.default_rng(123))
    value = np.full(1000, 3.0)
    draws = np.stack([sensor.measure(value) for _ in range(100)]) - value
    assert abs(draws.mean()) <= 5.0 * std / math.sqrt(draws.size)
    assert draws.std() == pytest.approx(std, rel=0.02)


@pytest.mark.parametrize("step", [1e-3, 0.25, 2.0])
def test_quantization_rounds_to_nearest_multiple(step):
    sensor = Sensor(SensorConfig(quantization=step), np.random.default_rng(0))
    x = np.linspace(-10.0, 10.0, 4001) * step + 0.123 * step
    y = sensor.measure(x)
    multiples = y / step
    np.testing.assert_allclose(multiples, np.round(multiples), atol=1e-9)
    assert np.abs(y - x).max() <= 0.5 * step * (1 + 1e-9)
    np.testing.assert_allclose(y, np.round(x / step) * step, rtol=0, atol=1e-12 * max(step, 1.0))
    levels = np.unique(np.round(multiples))
    assert np.all(np.diff(levels) == 1.0)


def test_noise_then_quantization():
    sensor = Sensor(SensorConfig(noise_std=0.3, quantization=0.1), np.random.default_rng(9))
    y = sensor.measure(np.zeros(10000))
    np.testing.assert_allclose(y / 0.1, np.round(y / 0.1), atol=1e-9)
    assert y.std() == pytest.approx(math.sqrt(0.3**2 + 0.1**2 / 12), rel=0.03)


def test_measure_keeps_shape_and_input():
    sensor = Sensor(SensorConfig(noise_std=1.0, quantization=0.5), np.random.default_rng(0))
    x = np.arange(12.0).reshape(3, 4)
    keep = x.copy()
    y = sensor.measure(x)
    assert y.shape == (3, 4)
    np.testing.assert_array_equal(x, keep)
    assert np.ndim(sensor.measure(1.0)) == 0


@pytest.mark.parametrize("field", ["noise_std", "quantization"])
@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf, "0.1", True])
def test_config_validation_names_the_field(field, bad):
    with pytest.raises(ScenarioError, match=rf"^{field} = ") as info:
        SensorConfig(**{field: bad})
    assert isinstance(info.value, ValueError)


def test_config_is_frozen_and_converts_ints():
    cfg = SensorConfig(noise_std=1, quantization=0)
    assert isinstance(cfg.noise_std, float) and cfg.noise_std == 1.0
    assert SensorConfig().is_exact and not cfg.is_exact
    with pytest.raises(AttributeError):
        cfg.noise_std = 2.0


def test_suite_and_sensor_argument_checks():
    with pytest.raises(TypeError, match="forces"):
        SensorSuite(SensorConfig(), {"noise_std": 0.1}, SensorConfig(), seed=0)
    with pytest.raises(ValueError, match="seed"):
        SensorSuite(SensorConfig(), SensorConfig(), SensorConfig(), seed=-1)
    with pytest.raises(TypeError, match="Generator"):
        Sensor(SensorConfig(), np.random.RandomState(0))
