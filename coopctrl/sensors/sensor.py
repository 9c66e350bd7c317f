"""One measurement channel: noise, then quantization."""

from __future__ import annotations

import numpy as np

from coopctrl.sensors.sensor_config import SensorConfig


class Sensor:
    """Measures a value as ``quantize(value + noise)``.

    .. math::

        y = q \\,\\operatorname{round}\\!\\left(\\frac{x + \\varepsilon}{q}\\right), \\qquad
        \\varepsilon \\sim \\mathcal N(0, \\sigma^2 I)

    with ``sigma = config.noise_std`` and ``q = config.quantization`` (rounding to the nearest
    multiple of ``q``, ties to even; skipped when ``q = 0``). With ``sigma = 0`` no random number
    is drawn, so the generator's stream is left untouched.

    Args:
        config: The channel's :class:`SensorConfig`.
        rng: A ``numpy.random.Generator``, seeded by the caller.
    """

    __slots__ = ("config", "rng", "_std", "_q")

    def __init__(self, config: SensorConfig, rng: np.random.Generator):
        if not isinstance(config, SensorConfig):
            raise TypeError(f"config is a {type(config).__name__}: expected a SensorConfig")
        if not isinstance(rng, np.random.Generator):
            raise TypeError(
                f"rng is a {type(rng).__name__}: expected a numpy.random.Generator "
                "(numpy.random.default_rng(seed))"
            )
        self.config = config
        self.rng = rng
        self._std = config.noise_std
        self._q = config.quantization

    def measure(self, value) -> np.ndarray:
        """A measured copy of ``value`` (array-like of any shape; never modified)."""
        y = np.array(value, dtype=float)
        if self._std != 0.0:
            y += self.rng.standard_normal(y.shape) * self._std
        if self._q != 0.0:
            y /= self._q
            np.rint(y, out=y)
            y *= self._q
        return y

    def __repr__(self) -> str:
        return f"Sensor({self.config!r})"
