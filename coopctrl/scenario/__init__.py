"""Scenario configuration: a tree of frozen, self-checking dataclasses loaded from TOML.

``load_scenario(path, overrides=None)`` is the entry point; ``Scenario()`` is the default scene.
"""

from coopctrl.scenario.arm import ARM_MODELS, ROLES, ArmConfig
from coopctrl.scenario.controllers import ControllersConfig, FollowerControllerConfig, LeaderControllerConfig
from coopctrl.scenario.load_distribution import LoadDistributionConfig
from coopctrl.scenario.loader import apply_overrides, load_scenario, parse_override_value, scenario_from_dict
from coopctrl.scenario.object_config import ObjectConfig
from coopctrl.scenario.scenario import Scenario
from coopctrl.scenario.scene import SceneConfig
from coopctrl.scenario.sensors import SensorConfig, SensorsConfig
from coopctrl.scenario.simulation import INTEGRATORS, SimulationConfig
from coopctrl.scenario.spring import ELEMENTS, SpringConfig
from coopctrl.scenario.trajectory import TrajectoryConfig, ViaPoint

__all__ = [
    "ARM_MODELS",
    "ELEMENTS",
    "INTEGRATORS",
    "ROLES",
    "ArmConfig",
    "ControllersConfig",
    "FollowerControllerConfig",
    "LeaderControllerConfig",
    "LoadDistributionConfig",
    "ObjectConfig",
    "Scenario",
    "SceneConfig",
    "SensorConfig",
    "SensorsConfig",
    "SimulationConfig",
    "SpringConfig",
    "TrajectoryConfig",
    "ViaPoint",
    "apply_overrides",
    "load_scenario",
    "parse_override_value",
    "scenario_from_dict",
]
