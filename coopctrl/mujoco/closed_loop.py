"""The closed loop of a scene on the MuJoCo plant: the scene's controllers, sensors and load split, the plant
stepped by MuJoCo (:class:`~coopctrl.mujoco.stepper.MujocoStepper`) once per control period."""

from __future__ import annotations

#: The plants a run can drive: the book's elastic plant (the compiled loop's own) and MuJoCo.
PLANTS = ("elastic", "mujoco")


def check_plant(plant) -> str:
    """``plant`` if it names one of :data:`PLANTS`; else ``ValueError`` naming it and what is allowed."""
    from coopctrl import arguments

    if not isinstance(plant, str) or plant not in PLANTS:
        raise arguments.invalid("plant", plant, f"one of {', '.join(PLANTS)}")
    return plant


def mujoco_closed_loop(scenario):
    """``closed_loop(scenario)`` whose plant is advanced by MuJoCo: one external step per control period.

    Raises:
        MujocoMissing: MuJoCo is not installed (``pip install 'coopctrl[mujoco]'``).
        ValueError: the scene has an arm MuJoCo cannot hold (a ``contact_point`` arm) or world charts.
    """
    from coopctrl.mujoco.requirement import import_mujoco
    from coopctrl.mujoco.stepper import MujocoStepper
    from coopctrl.scenario.build import build_plant
    from coopctrl.wiring import closed_loop

    import_mujoco()  # the missing extra named before any work
    stepper = MujocoStepper(scenario, build_plant(scenario))
    return closed_loop(scenario, integrator=stepper, step=scenario.simulation.control_period)
