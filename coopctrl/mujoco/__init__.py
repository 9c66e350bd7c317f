"""The MuJoCo plant of a scene (optional extra ``coopctrl[mujoco]``; docs/mujoco.md).

Nothing here imports MuJoCo at import time: :func:`~coopctrl.mujoco.requirement.import_mujoco` does, and
names the extra when it is missing.
"""

from coopctrl.mujoco.closed_loop import PLANTS, check_plant, mujoco_closed_loop
from coopctrl.mujoco.mjcf import scene_mjcf
from coopctrl.mujoco.requirement import INSTALL_HINT, MujocoMissing, import_mujoco

__all__ = ["PLANTS", "INSTALL_HINT", "MujocoMissing", "check_plant", "import_mujoco", "mujoco_closed_loop", "scene_mjcf"]
