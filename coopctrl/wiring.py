"""Wire the closed loop of a scenario: every part built from the scenario and connected explicitly.

:func:`closed_loop` is the one builder: the one place where a :class:`~coopctrl.scenario.Scenario`
becomes a :class:`~coopctrl.closed_loop.ClosedLoop` (plant, trajectory, grasp compliance, leader and
followers, sensors, load distribution, integrator). Users meet it as :func:`coopctrl.simulator.closed_loop`
(the same function). Nothing is attached to the built loop: the failure analysis, which needs the
scenario, runs after the run, in :func:`coopctrl.simulator.simulate`
(:func:`coopctrl.analysis.diagnosis.diagnose_record`).
"""

from __future__ import annotations

import coopctrl.arguments as arguments
from coopctrl.closed_loop import ClosedLoop
from coopctrl.controllers import FollowerForceController, GraspCompliance, LeaderController
from coopctrl.integrators import get_integrator
from coopctrl.load_distribution import LoadDistribution
from coopctrl.loop.parts import LoopControllers, LoopGuards, LoopTiming
from coopctrl.scenario import build
from coopctrl.sensors import SensorConfig, SensorSuite


def _sensor(cfg) -> SensorConfig:
    return SensorConfig(noise_std=cfg.noise_std, quantization=cfg.quantization)


def check_scenario(scenario, name: str = "scenario") -> None:
    """``TypeError`` unless ``scenario`` is a :class:`~coopctrl.scenario.Scenario` (the message says how to
    get one from a file, a scene's name or a dict)."""
    from coopctrl.scenario import Scenario

    arguments.instance(name, scenario, Scenario,
                       "a coopctrl.scenario.Scenario: coopctrl.load_scenario(path) loads one from a .toml file, "
                       "coopctrl.scenario.scenario_from_dict(data) builds one from a dict")


def check_arguments(scenario, integrator=None, step=None, uniform_step: bool = False, controllers=None,
                    trajectory=None) -> None:
    """The argument checks of :func:`closed_loop` (``TypeError``/``ValueError`` naming the argument), made
    before anything is built."""
    from coopctrl.integrators import INTEGRATORS

    check_scenario(scenario)
    if integrator is not None and not isinstance(integrator, str) and not callable(getattr(integrator, "step", None)):
        raise arguments.invalid("integrator", integrator, f"None, a name ({', '.join(INTEGRATORS)}) or an "
                                "integrator (with step(f, t, x, u, h), as coopctrl.integrators.Integrator)", TypeError)
    if step is not None:
        h, T = arguments.number("step", step, positive=True, unit="s"), scenario.simulation.control_period
        if h > T * (1.0 + 1e-12):  # as ClosedLoop.set_step, but before the loop is built
            raise arguments.invalid("step", step, f"0 < step <= simulation.control_period = {T:g} s")
    arguments.flag("uniform_step", uniform_step)
    arguments.callable_or_none("controllers", controllers, "None or f(leader, followers) -> (leader, followers)")
    if trajectory is not None and not callable(getattr(trajectory, "evaluate", None)):
        raise arguments.invalid("trajectory", trajectory, "None or a trajectory with evaluate(t) -> (Y, dY, ddY) "
                                "(as coopctrl.trajectory.MinimumJerkTrajectory)", TypeError)


def closed_loop(scenario, *, integrator=None, step: float | None = None, uniform_step: bool = False,
                controllers=None, trajectory=None, leader_law=None, follower_law=None) -> ClosedLoop:
    """The :class:`ClosedLoop` of a scenario, every part built and wired explicitly: the one builder.

    Tuning and analysis build a loop with other parts instead of patching a built one. Nothing is
    attached to the loop afterwards; a divergence's scenario-aware diagnosis runs after the run, in
    :func:`coopctrl.simulator.simulate` (``loop.run`` alone names the failure with the loop's own,
    open-loop, diagnosis: :mod:`coopctrl.loop.diagnosis`).

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario`.
        integrator: An integrator name or :class:`~coopctrl.integrators.Integrator` instead of
            ``simulation.integrator``.
        step: A free plant step ``0 < h <= T`` [s] instead of ``T / substeps`` (see
            :meth:`ClosedLoop.set_step`; ``uniform_step`` splits the period into equal steps).
        controllers: ``f(leader, followers) -> (leader, followers)``, applied to the scenario's
            controllers before they are wired (e.g. wrapped by the probes of
            :mod:`coopctrl.tuning.loop_probes`).
        trajectory: A nominal object trajectory (``evaluate(t) -> (Y, dY, ddY)``) instead of the
            scenario's ``trajectory.via`` (e.g. the scenario's read from a later time: the closed-loop
            linearization, :mod:`coopctrl.analysis.closed_loop_stability`).
        leader_law: A user control law for the leader, passed to the
            :class:`~coopctrl.closed_loop.ClosedLoop` (``None``: the shipped computed-torque law).
        follower_law: A user control law for the followers' nodes, likewise (``None``: their computed torque).

    Raises:
        TypeError, ValueError: An argument of the wrong type or value (the message names it).
    """
    check_arguments(scenario, integrator, step, uniform_step, controllers, trajectory)
    plant = build.build_plant(scenario)
    space, m = scenario.space, len(scenario.arms)
    if trajectory is None:
        trajectory = build.trajectory(scenario)
    compliance = GraspCompliance(plant)
    ctrl = scenario.controllers
    leader = LeaderController(plant, scenario.leader, ctrl.leader.natural_frequency, ctrl.leader.damping_ratio)
    f = ctrl.followers
    followers = {i: FollowerForceController(plant, i, compliance, f.force_kp, f.force_ki, f.natural_frequency,
                                            f.damping_ratio, f.force_loop) for i in scenario.followers}
    if controllers is not None:
        leader, followers = controllers(leader, followers)
    s = scenario.sensors
    sensors = SensorSuite(_sensor(s.joints), _sensor(s.forces), _sensor(s.object), scenario.simulation.seed)
    sim = scenario.simulation
    if integrator is None:
        integrator = sim.integrator
    if isinstance(integrator, str):
        from coopctrl.integrators import ERROR_CONTROLLED

        options = (dict(rtol=sim.rtol, atol=sim.atol, atol_velocity=sim.atol_velocity, min_step=sim.min_step)
                   if integrator in ERROR_CONTROLLED else {})
        integrator = get_integrator(integrator, **options)
    loop = ClosedLoop(plant, trajectory, build.nominal_grasps(scenario),
                      LoadDistribution(scenario.load_distribution, space, m),
                      LoopControllers(leader, followers, compliance, leader_law=leader_law, follower_law=follower_law,
                                      enabled=scenario.controllers.enabled),
                      sensors, LoopTiming(integrator, sim.control_period, sim.substeps),
                      LoopGuards(sim.max_deformation, sim.max_energy), name=scenario.name,
                      rotations=scenario.scene.rotations)
    if step is not None:
        loop.set_step(step, uniform=uniform_step)
    return loop
