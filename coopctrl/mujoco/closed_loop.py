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
    """Refuse, before any work, a scene the MuJoCo plant cannot run (:class:`~coopctrl.errors.ScenarioError`
    naming the field, exit 2 from the command line): a ``contact_point`` arm (no body to simulate), or a spatial
    scene in world charts (``scene.rotations = "charts"``) whose nominal path tilts the object to
    ``|cos theta| < RECENTRE_COS`` (:mod:`coopctrl.loop.charts`): the loop would re-centre its chart and turn the
    state, which the state map (in the book's world angles) cannot follow."""
    import math

    import numpy as np

    from coopctrl.errors import ScenarioError

    for i, arm in enumerate(scenario.arms):
        if arm.model == "contact_point":
            raise ScenarioError(f"arms[{i}].model", "contact_point", "a robot, a DH table or a planar arm for MuJoCo "
                                "(a contact point has no body to simulate)", scenario.source)
    if scenario.space == "spatial" and scenario.scene.rotations == "charts":
        from coopctrl.loop.charts import RECENTRE_COS
        from coopctrl.scenario.build import trajectory

        sim = scenario.simulation
        times = np.arange(int(round(sim.duration / sim.control_period)) + 1) * sim.control_period
        path = trajectory(scenario)
        pitch = np.zeros(len(times))
        for k, t in enumerate(times):
            try:
                pitch[k] = path.evaluate(float(t))[0][4]
            except ValueError:  # a geodesic path's Euler view within the band of +-90 deg: far out of the chart
                pitch[k] = math.pi / 2
                break
        k = int(np.argmin(np.abs(np.cos(pitch))))
        if abs(math.cos(pitch[k])) < RECENTRE_COS:
            raise ScenarioError("trajectory.via", f"a pitch of {pitch[k]:.3g} rad at t = {times[k]:.3g} s",
                                f"a path within {math.acos(RECENTRE_COS):.3g} rad of level pitch for the mujoco plant "
                                "(further, the loop re-centres its world chart, which the MuJoCo plant cannot "
                                "follow); run this scene on the elastic plant", scenario.source)


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
