"""``simulate(scenario)``: build the closed loop of a scenario, run it, diagnose a failure, and return
its result.

:func:`closed_loop` is the one builder (:func:`coopctrl.wiring.closed_loop`, the same function). The
failure analysis of the analysis layer (:func:`coopctrl.analysis.diagnosis.diagnose_record`), which the
loop cannot import (:mod:`coopctrl.loop.diagnosis`) and which needs the scenario, runs after the run, on
the facts the run's stop recorded (``LoopRecord.stop``): this module is where the two are composed.
"""

from __future__ import annotations

import numpy as np

from coopctrl import arguments, wiring
from coopctrl.closed_loop import ClosedLoop
from coopctrl.errors import InfeasibleLoad
from coopctrl.results import SimulationResult
from coopctrl.results.thinning import finish_record
from coopctrl.scenario import build
from coopctrl.wiring import closed_loop  # noqa: F401 - the one builder, under its public name


def integration_statistics(steps, control_period: float) -> dict | None:
    """The run's totals of the per-tick step statistics of an error-controlled integrator
    (:attr:`LoopRecord.integration_steps <coopctrl.loop.record.LoopRecord>`), or ``None``."""
    if steps is None or not len(steps):
        return None
    accepted, rejected = int(steps[:, 0].sum()), int(steps[:, 1].sum())
    advanced = steps[:, 0] > 0
    smallest = float(np.min(steps[advanced, 3])) if advanced.any() else float("nan")
    covered = float(np.count_nonzero(advanced)) * control_period  # time integrated [s]
    return {"steps_accepted": accepted, "steps_rejected": rejected,
            "rejected_share": rejected / (accepted + rejected) if accepted + rejected else 0.0,
            "rhs_evaluations": int(steps[:, 2].sum()), "smallest_step_s": smallest,
            "mean_step_s": covered / accepted if accepted else float("nan")}


#: Recorded signals whose values (and sums of squares: the RMS metrics) must be finite in an ok run;
#: the commanded wrenches only when the controllers run (a passive run has no load distribution).
CHECKED_SIGNALS = (("x", "state"), ("tau", "joint torques"), ("F_measured", "measured contact wrenches"),
                   ("Y0_nominal", "nominal object pose"), ("F_commanded", "commanded contact wrenches"))


def non_finite_signal(rec: dict, controlled: bool = True) -> str | None:
    """Why the recorded ``rec`` cannot give finite metrics, or None: the first of :data:`CHECKED_SIGNALS`
    with a non-finite value, or whose sum of squares overflows (an RMS metric would be infinite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        for key, label in CHECKED_SIGNALS:
            if key == "F_commanded" and not controlled:
                continue
            values = np.asarray(rec[key], dtype=float)
            if not values.size:
                continue
            low, high = values.min(), values.max()  # NaN where any value is (then no comparison holds)
            if -1e150 < low and high < 1e150 and max(-low, high) ** 2 * values.size < 1e300:
                continue  # every value finite, and its sum of squares: the checks below pass
            if not np.all(np.isfinite(values)):
                k = int(np.argmax(~np.all(np.isfinite(values.reshape(len(values), -1)), axis=1)))
                return f"{label} not finite at t = {float(rec['t'][k]):.6g} s"
            if not np.isfinite(np.sum(np.square(values))):
                return f"{label} up to {float(np.max(np.abs(values))):.3g}: their metrics overflow"
    return None


def simulate(scenario, progress: bool = False, loop: ClosedLoop | None = None, node_poses: bool = True,
             state=None, plant: str = "elastic") -> SimulationResult:
    """Run a scenario's closed loop for ``simulation.duration`` and return the :class:`SimulationResult`.

    With ``state``, the final state of an earlier run of the same scenario (``result.final_state``, or a
    loop record's ``final_state``), the run continues it for ``simulation.duration`` more (ticks at
    ``t_end + T .. t_end + duration``; :meth:`ClosedLoop.run`): the continuation is a result like any other,
    which can be plotted, saved, reopened, and continued again from its own ``final_state``.

    A run whose recorded signals are not finite, or too large for finite metrics (a sensor noise of
    1e300 N), is never ``ok``: its status is ``diverged`` with the signal named.

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario` to run.
        progress: Show a progress bar on the terminal.
        loop: ``closed_loop(scenario)`` when the caller has already built it (``coopctrl run`` builds it
            once, for pre-flight and the run; a run changes nothing of it), else ``None`` to build it here.
        node_poses: Compute the kept samples' node poses ``Y_nodes`` (one compiled pass over the record);
            ``False`` leaves ``Y_nodes = None`` (``coopctrl run`` without ``--out``: the summary does not read
            them).
        state: ``None`` (start from ``build.initial_state(scenario)``) or the
            :class:`~coopctrl.loop.state.LoopState` of an earlier run's end to continue from.
        plant: ``"elastic"`` (the book's plant, in the compiled loop) or ``"mujoco"`` (MuJoCo's arms and object
            with the scene's grasp elements, :mod:`coopctrl.mujoco`; needs ``pip install 'coopctrl[mujoco]'``).

    Raises:
        TypeError: ``scenario`` is not a :class:`~coopctrl.scenario.Scenario` (a path, a dict: load it
            first), ``progress`` is not a bool, ``loop`` is not a :class:`ClosedLoop` of this scenario's
            plant size, or ``state`` is not a loop state.
        ValueError: ``state`` is the final state of a run that stopped early, or of another loop
            (:meth:`ClosedLoop.run` names it).
    """
    from coopctrl.loop.state import LoopState

    wiring.check_scenario(scenario)
    progress = arguments.flag("progress", progress)
    node_poses = arguments.flag("node_poses", node_poses)
    if state is not None and not isinstance(state, LoopState):
        raise arguments.invalid("state", state, "None or the final_state of an earlier run of this scenario "
                                "(result.final_state)", TypeError)
    from coopctrl.mujoco.closed_loop import check_plant, mujoco_closed_loop

    if check_plant(plant) == "mujoco" and state is not None:
        raise ValueError("state = a final_state is invalid with plant='mujoco': continuing a run is for the elastic "
                         "plant (MuJoCo's own state does not travel in a loop state); run the whole duration at once")
    if plant == "mujoco" and loop is None:
        loop = mujoco_closed_loop(scenario)
    elif loop is not None and (getattr(loop.integrator, "plant_name", "elastic") != plant):
        raise TypeError(f"loop={loop!r} does not run the {plant} plant: pass None to build the loop of plant={plant!r}")
    if loop is None:
        loop = closed_loop(scenario)
    elif not isinstance(loop, ClosedLoop) or loop.plant.state_size != scenario.state_size:
        raise TypeError(f"loop={loop!r} is not closed_loop(scenario) of this scenario: pass the loop built "
                        "from it, or None to build it here")
    # the metrics of every tick (run_result), then the kept samples with their node poses (finish_record)
    return finish_record(run_result(scenario, loop, x0=state, progress=progress), loop.plant if node_poses else None,
                         scenario.simulation.record_every)


def run_result(scenario, loop: ClosedLoop, x0=None, progress: bool = False) -> SimulationResult:
    """One run of ``loop``, the :func:`closed_loop` of ``scenario``, as its :class:`SimulationResult` of
    every tick: what :func:`simulate` returns before it thins the record and adds the node poses (the
    summary is the same). ``x0``: ``build.initial_state(scenario)``, or ``None`` to compute it here. A sweep
    reuses one built loop and its start for the runs that differ only in the sensor noise seed
    (:mod:`coopctrl.sweep.reuse`). ``x0`` may also be a :class:`~coopctrl.loop.state.LoopState`, the end of
    an earlier run: the run continues it (:func:`simulate` with ``state``)."""
    from coopctrl.analysis.diagnosis import diagnose_record

    plant = loop.plant
    sim = scenario.simulation
    try:
        if x0 is None:
            x0 = build.initial_state(scenario, loop)
    except InfeasibleLoad as exc:  # the loaded start already needs a split that does not exist
        rec = loop.empty_record()
        rec.update(status="qp_failed", reason=f"at t = 0 s (loaded start): {exc}",
                   events=[(0.0, "qp_failed", str(exc))])
    else:
        if progress:  # on a terminal: a long error-controlled run says so before it starts
            import sys

            from coopctrl.loop.step_budget import long_run_notice

            notice = long_run_notice(loop, x0.x if hasattr(x0, "x") else x0, sim.duration)
            if notice:
                print(f"coopctrl: {notice}", file=sys.stderr)
        rec = loop.run(x0, sim.duration, progress=progress)
        diagnose_record(scenario, loop, rec)  # a divergence's causes, with the scenario (after the run)
    if rec["status"] == "ok":
        cause = non_finite_signal(rec, controlled=scenario.controllers.enabled)
        if cause is not None:
            rec.update(status="diverged", reason=f"non-finite results: {cause}")
            rec["events"].append((float(rec["t"][-1]) if len(rec["t"]) else 0.0, "diverged", rec["reason"]))
    if rec["status"] == "ok" and scenario.controllers.enabled:  # bounded, but not controlled (analysis.instability)
        from coopctrl.analysis.instability import saturation_failure

        why = saturation_failure(scenario, loop, rec)
        if why:
            rec.update(status="diverged", reason=why)
            rec["events"].append((float(rec["t"][-1]), "diverged", why))
    p, nz = plant.p, plant.nz
    x = rec["x"]
    Y0 = x[:, nz - p:nz]
    squeeze = rec["squeeze"]  # recorded per tick by the kernel (coopctrl.loop.squeeze)
    report = plant.size_report()
    model = {"arms": report["arms"], "dof_per_arm": report["dof_per_arm"], "space": plant.space,
             "unloaded_state": plant.unloaded_state, "state_size": plant.state_size,
             "arm_models": [a.model for a in scenario.arms]}
    stats = integration_statistics(rec.get("integration_steps"), sim.control_period)
    outside = getattr(loop.integrator, "plant_name", None)  # another plant (coopctrl.mujoco): named as the integrator
    result = SimulationResult(
        scenario=scenario.name, space=plant.space, t=rec["t"], x=x, tau=rec["tau"], Y0=Y0,
        object_rotation=rec.get("object_rotation"),
        Y0_nominal=rec["Y0_nominal"], F_measured=rec["F_measured"], F_commanded=rec["F_commanded"],
        F_external=rec["F_external"], F_internal=rec["F_internal"], squeeze=squeeze,
        squeeze_desired=np.asarray(loop.squeeze_desired, dtype=float), tau_max=loop.tau_max,
        qp_status=rec["qp_status"], qp_binding=rec.get("qp_binding", []), qp_iterations=rec["qp_iterations"], qp_active_rows=rec["qp_active_rows"], qp_solve_time_s=rec["qp_solve_time_s"],
        events=rec["events"], status=rec["status"], reason=rec["reason"], model=model,
        integrator=loop.integrator.label if outside else sim.integrator,
        step_s=loop.integrator.timestep if outside else (stats["mean_step_s"] if stats else sim.step), control_period_s=sim.control_period,
        duration_s=sim.duration, integration_statistics=stats,
        wall_time_s=rec["wall_time_s"], startup_s=rec["startup_s"], leader=scenario.leader, followers=list(scenario.followers),
        qp_active_constraints=rec["qp_binding_counts"], qp_time_s=rec["qp_time_s"],
        torque_saturated_ticks=rec["saturated_ticks"], final_state=rec.get("final_state"),
        energy=None if scenario.controllers.enabled else rec["energy"],
        kinetic_energy=None if scenario.controllers.enabled else rec["kinetic_energy"],
        energy_conserving=(not scenario.controllers.enabled and all(
            sp.damping == 0 and sp.torsion_damping == 0 for sp in scenario.springs)))
    return result
