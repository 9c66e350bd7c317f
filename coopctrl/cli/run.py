"""``coopctrl run``: simulate a scenario and print its summary."""

from __future__ import annotations

import argparse
import sys

from coopctrl.cli._core import (PROG, _add_set_option, _load, _one_line, output_directory, preflight_line,
                                refuse_before_work, stdout_to_stderr, subcommand)
from coopctrl.errors import DivergenceError, InfeasibleLoad
from coopctrl.io.console import OutputWriteError, say, visible, visible_lines


def result_directory(text: str):
    """``--out DIR`` of ``run``: writable (:func:`output_directory`), and a folder that may be replaced as
    a whole (:func:`coopctrl.io.output_folder.check_output_folder`: new, empty, or an earlier result)."""
    from coopctrl.io.output_folder import RESULT_FOLDER, check_output_folder

    path = output_directory(text)
    try:
        return check_output_folder(path, RESULT_FOLDER)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _record_every(text: str) -> int:
    """``--record-every N``: an integer (its range is the scenario's, ``simulation.record_every``)."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: expected an integer N >= 1 "
                                         "(keep every N-th control tick)") from None


def simulate_function():
    """The simulator ``run`` calls (imported lazily: it pulls in numpy, the compiled kernels and the solvers); a test
    replaces this function to observe or fake the simulation."""
    from coopctrl.simulator import simulate

    return simulate


def cmd_run(args) -> int:
    """Load, simulate, print the summary, save and plot with ``--out``."""
    import json

    import numpy as np

    if args.record_every is not None:  # checked against the schema's range with the scenario
        args.sets = [*args.sets, f"simulation.record_every={args.record_every}"]
    if args.plant == "mujoco":  # the missing extra named (exit 2) before any work
        from coopctrl.mujoco.requirement import import_mujoco

        import_mujoco()
    scenario = _load(args)
    if args.plant == "mujoco":
        from coopctrl.mujoco.closed_loop import check_scene

        check_scene(scenario)
    if args.plant == "mujoco" and (scenario.simulation.accuracy is not None or args.estimate_error):
        from coopctrl.cli._core import UsageError

        what = "--estimate-error" if args.estimate_error else "simulation.accuracy"
        raise UsageError(f"--plant mujoco steps MuJoCo at its own fixed step: {what} (the elastic plant's integrator "
                         "settings) cannot apply; drop it or run the elastic plant")
    refuse_before_work(scenario)  # a record that cannot fit, a path through the Euler-angle band: exit 2, as `check`
    loop = None  # built once, for pre-flight and the run
    try:
        if scenario.simulation.accuracy is None:  # the scene as given runs: its loop, built once
            from coopctrl.wiring import closed_loop

            loop = closed_loop(scenario)
        if not args.no_preflight:  # an impossible task is refused before the first tick (exit 1)
            from coopctrl.analysis.preflight import preflight
            from coopctrl.wiring import closed_loop

            loop = loop if loop is not None else closed_loop(scenario)
            report = preflight(scenario, loop)
            if not report.ok:
                print(f"{PROG}: failed: {preflight_line(report)} (--no-preflight runs it anyway)", file=sys.stderr)
                return 1
        choice = None
        if scenario.simulation.accuracy is not None:  # simulation.accuracy: the cheapest setting meeting it
            from coopctrl.analysis.accuracy_target import choose_setting

            try:
                with stdout_to_stderr(args.json):
                    scenario, choice = choose_setting(scenario)
                loop = None  # the chosen setting is another scenario: its own loop
            except ArithmeticError as err:  # TargetUnreachable, ReferenceFailed: nothing to run at that accuracy
                print(f"{PROG}: failed: simulation.accuracy: {_one_line(err)}", file=sys.stderr)
                return 1
            if not args.quiet:
                print(f"{PROG}: simulation.accuracy = {choice.target_m:.3g} m: {choice.sentence()}", file=sys.stderr)
        simulate = simulate_function()
        progress = not (args.quiet or args.json) and sys.stderr.isatty()
        with stdout_to_stderr(args.json):  # stdout holds the JSON only, whatever a library prints
            other_plant = {} if args.plant == "elastic" else {"plant": args.plant, "loop": None}  # its own loop
            result = simulate(scenario, progress=progress, node_poses=args.out is not None,  # only files hold them
                              **{"loop": loop, **other_plant})
            with np.errstate(over="ignore", invalid="ignore"):  # a diverged run's figures overflow: it says so
                summary = result.summary()
            if choice is not None:
                summary["accuracy_choice"] = choice.to_dict()
            estimate = None
            if args.estimate_error and result.status == "ok":
                from coopctrl.analysis.error_estimate import estimate_error

                estimate = estimate_error(scenario)
                summary.update(estimate.to_dict())
            if args.out is not None:  # the whole folder as one unit (an earlier result stays whole until then)
                from coopctrl.results.folder import write_result_folder

                write_result_folder(result, scenario, args.out)
    except (DivergenceError, InfeasibleLoad) as err:
        kind = "diverged" if isinstance(err, DivergenceError) else "qp_failed"
        print(f"{PROG}: {kind}: {_one_line(err)}", file=sys.stderr)
        return 1
    except OutputWriteError as err:
        print(f"{PROG}: failed: {err}; {visible(args.out)} was left as it was", file=sys.stderr)
        return 1
    from coopctrl.results import summary_table

    ticks = summary.get("samples", len(result.t))
    try:
        if args.json:
            say(json.dumps(summary, indent=2, allow_nan=False))
        elif not args.quiet:
            say(visible_lines(summary_table(summary)))
            say(f"{'torque-saturated ticks'.ljust(28)}  {summary.get('torque_saturated_ticks', 0)} of {ticks}")
            if estimate is not None:
                for line in estimate.lines():
                    say(line)
            if args.out is not None:
                say(f"outputs written to {visible(args.out)}")
    except OutputWriteError as err:
        print(f"{PROG}: failed: {err} (the run itself finished; its files, if any, are whole)", file=sys.stderr)
        return 1
    saturated = int(summary.get("torque_saturated_ticks", 0) or 0)
    if saturated and result.status == "ok":  # a failed run's one-line reason names the saturation when it is a cause
        ratio = summary.get("max_torque_ratio")
        shown = "-" if ratio is None else f"{ratio:.3g}"
        print(f"{PROG}: warning: the torques saturated at tau_max on {saturated} of {ticks} ticks "
              f"(max |tau| / tau_max = {shown})", file=sys.stderr)
    if result.status != "ok":
        print(f"{PROG}: {result.status}: {_one_line(result.reason) or 'no reason given'}", file=sys.stderr)
        return 1
    return 0


@subcommand("run")
def _run_parser(sub) -> None:
    parser = sub.add_parser(
        "run",
        help="simulate a scenario and print its summary",
        description="Check the task along its nominal trajectory (pre-flight, as `coopctrl check`), simulate the "
        "scenario (default: the built-in default scene) and print a summary table. Exit 0 if the run is ok, 1 if "
        "pre-flight found the task impossible or the run diverged or the load distribution failed, 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file, or the name of one in scenarios/ (default: built-in default scene)")
    _add_set_option(parser)
    parser.add_argument("--out", type=result_directory, metavar="DIR",
                        help="write result.npz, result.csv, summary.json, PNG plots, replay.html (3-D replay), "
                        "scenario.toml and copies of the scene's own URDF files (robots/) into DIR, as one unit: DIR "
                        "must be new, empty or an earlier result, which stays whole until the new one replaces it")
    parser.add_argument("--record-every", type=_record_every, metavar="N",
                        help="keep every N-th control tick (and the last) in the result and its files "
                        "(simulation.record_every); the summary is computed on every tick")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON on stdout (nothing else on stdout)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary table")
    parser.add_argument("--estimate-error", action="store_true",
                        help="rerun the scene at a tighter setting (half the step; error-controlled: against an RK4 "
                        "reference below its steps, that reference's own error added) and report the estimated "
                        "integration error of the object position [m], orientation [rad] and contact forces [N] "
                        "(maximum over the run; Richardson)")
    parser.add_argument("--plant", choices=("elastic", "mujoco"), default="elastic",
                        help="the plant the controllers drive: the book's elastic plant (default) or MuJoCo's arms and "
                        "object with the scene's grasp elements (needs pip install 'coopctrl[mujoco]'; docs/mujoco.md)")
    parser.add_argument("--no-preflight", action="store_true",
                        help="skip the pre-flight check of the task (see `coopctrl check`) and simulate anyway")
    parser.set_defaults(handler=cmd_run)
