"""Controllers over the cooperative plant: nominal load, leader computed torque, follower force regulation."""

from coopctrl.controllers.computed_torque import node_computed_torque, pose_error
from coopctrl.controllers.follower import FollowerForceController
from coopctrl.controllers.grasp_compliance import GraspCompliance
from coopctrl.controllers.leader import LeaderController
from coopctrl.controllers.nominal_load import required_object_wrench

__all__ = [
    "FollowerForceController",
    "GraspCompliance",
    "LeaderController",
    "node_computed_torque",
    "pose_error",
    "required_object_wrench",
]
