"""The measurement channels of the cooperative system: joints, grasp forces, object."""

from __future__ import annotations

import numpy as np

from coopctrl.sensors.sensor import Sensor
from coopctrl.sensors.sensor_config import SensorConfig


class SensorSuite:
    """Joint, force and object sensors with independent, reproducible noise streams.

    The seed is split with ``numpy.random.SeedSequence(seed).spawn(3)`` into one generator per
    channel (joints, forces, object), so turning noise on in one channel does not change the
    noise of the others. Joint angles and rates share the ``joints`` configuration (its
    ``noise_std`` and ``quantization`` apply in [rad] to ``q`` and in [rad/s] to ``dq``); the
    object pose and twist share ``object`` likewise ([m, rad] and [m/s, rad/s]).

    Args:
        joints: Configuration of the joint encoders (``q``, ``dq``).
        forces: Configuration of the grasp force sensors ``F`` [N, N m].
        object: Configuration of the object pose sensor (``Y_0``, ``dY_0``).
        seed: Seed of the noise, an integer >= 0.
    """

    def __init__(self, joints: SensorConfig, forces: SensorConfig, object: SensorConfig, seed: int):
        for name, cfg in (("joints", joints), ("forces", forces), ("object", object)):
            if not isinstance(cfg, SensorConfig):
                raise TypeError(f"{name} is a {type(cfg).__name__}: expected a SensorConfig")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ValueError(f"seed = {seed!r} is invalid: expected an integer >= 0")
        self.seed = int(seed)
        rng_joints, rng_forces, rng_object = (
            np.random.default_rng(s) for s in np.random.SeedSequence(self.seed).spawn(3)
        )
        self.joints = Sensor(joints, rng_joints)
        self.forces = Sensor(forces, rng_forces)
        self.object = Sensor(object, rng_object)

    def restarted(self) -> "SensorSuite":
        """A suite with the same channels and seed whose noise streams start from the beginning."""
        return SensorSuite(self.joints.config, self.forces.config, self.object.config, self.seed)

    @classmethod
    def exact(cls, seed: int = 0) -> "SensorSuite":
        """A suite that returns exact copies of every value."""
        off = SensorConfig()
        return cls(off, off, off, seed)

    def read_joints(self, q, dq) -> tuple[np.ndarray, np.ndarray]:
        """Measured joint angles [rad] and rates [rad/s] (new arrays)."""
        measure = self.joints.measure
        return measure(q), measure(dq)

    def read_forces(self, F) -> np.ndarray:
        """Measured grasp forces and moments [N, N m] (a new array)."""
        return self.forces.measure(F)

    def read_object(self, Y0, dY0) -> tuple[np.ndarray, np.ndarray]:
        """Measured object pose ``Y_0`` [m, rad] and its rate ``dY_0`` [m/s, rad/s] (new arrays)."""
        measure = self.object.measure
        return measure(Y0), measure(dY0)

    def __repr__(self) -> str:
        return (f"SensorSuite(joints={self.joints.config!r}, forces={self.forces.config!r}, "
                f"object={self.object.config!r}, seed={self.seed})")
