"""Sensor models: additive Gaussian noise and quantization, seeded by the caller."""

from __future__ import annotations

from coopctrl.sensors.sensor import Sensor
from coopctrl.sensors.sensor_config import SensorConfig
from coopctrl.sensors.sensor_suite import SensorSuite

__all__ = ["Sensor", "SensorConfig", "SensorSuite"]
