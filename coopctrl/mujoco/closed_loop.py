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


def check_scene(scenario) -> None:
    """Refuse, before any work, a scene the MuJoCo plant cannot run: a ``contact_point`` arm (no body to simulate)
    or ``scene.rotations = "charts"`` (the state map is in the book's world angles):
    :class:`~coopctrl.errors.ScenarioError` naming the field (exit 2 from the command line)."""
    from coopctrl.errors import ScenarioError

    for i, arm in enumerate(scenario.arms):
        if arm.model == "contact_point":
            raise ScenarioError(f"arms[{i}].model", "contact_point", "a robot, a DH table or a planar arm for MuJoCo "
                                "(a contact point has no body to simulate)", scenario.source)
    if scenario.scene.rotations != "book":
        raise ScenarioError("scene.rotations", scenario.scene.rotations, "'book' for the mujoco plant (its state map "
                            "is in the book's world Euler angles; the loop's world charts would re-centre them)",
                            scenario.source)


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
    check_scene(scenario)
    stepper = MujocoStepper(scenario, build_plant(scenario))
    return closed_loop(scenario, integrator=stepper, step=scenario.simulation.control_period)
