"""``coopctrl check``: validate a scenario and check that its task is possible, without simulating it."""

from __future__ import annotations

import sys

from coopctrl.cli._core import (PROG, _add_set_option, _load, _one_line, preflight_line, refuse_before_work,
                                refuse_record, subcommand)
from coopctrl.io.console import say


def cmd_check(args) -> int:
    """Validate a scenario without simulating it: its fields, then the physics it implies (every grasp
    within reach, torque limits above the arms' own gravity load, a nominal path clear of the Euler-angle
    singularity), then pre-flight along the nominal trajectory (:mod:`coopctrl.analysis.preflight`: every
    node pose within reach, a feasible load distribution, the torques it needs within tau_max, a
    statically stable grasp) and the loaded initial state."""
    scenario = _load(args)
    refuse_before_work(scenario)  # as `run`: the same refusals, in the same order, with the same lines
    scenario.plant()
    from coopctrl.analysis.preflight import preflight
    from coopctrl.scenario.scenario import rotations_text
    from coopctrl.simulator import closed_loop

    loop = closed_loop(scenario)  # refuses a nominal path near the Euler-angle singularity (coopctrl.analysis.euler_singularity)
    refuse_record(scenario, loop)  # the loop's own check before its first tick
    report = preflight(scenario, loop)
    if not report.ok:
        print(f"{PROG}: failed: {preflight_line(report)}", file=sys.stderr)
        return 1
    scenario.initial_state()
    torque = ("" if report.torque_ratio_max != report.torque_ratio_max else
              f"; planned max |tau| / tau_max {report.torque_ratio_max:.3g} at t = {report.torque_ratio_time_s:.4g} s")
    rotations = rotations_text(scenario)
    say(
        f"ok: {_one_line(scenario.name)} ({scenario.space}, {len(scenario.arms)} arms, state size {scenario.state_size}, "
        f"{scenario.simulation.control_steps} control steps of {scenario.simulation.control_period:g} s); "
        f"pre-flight passed at {report.samples} instants{torque}" + (f"; {_one_line(rotations)}" if rotations else "")
    )
    return 0


@subcommand("check")
def _check_parser(sub) -> None:
    parser = sub.add_parser(
        "check", help="validate a scenario and check that its task is possible",
        description="Validate a scenario (and overrides) without simulating, then check its task along the nominal "
        "trajectory (pre-flight: every waypoint and a fine sampling between them; every arm's node pose within "
        "reach and joint limits, a feasible load distribution, the joint torques it needs within tau_max, a "
        "statically stable grasp). Exit 0 if the scenario is valid and its task possible; 1 if pre-flight finds "
        "the task impossible (one line on stderr with the first time and what binds, e.g. 'at t = 0.42 s arm 2 "
        "joint 3 needs 187 N m > tau_max 97.6 N m'); 2 for bad input (one line naming the field).",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file or a name in scenarios/ (default: the built-in scene)")
    _add_set_option(parser)
    parser.set_defaults(handler=cmd_check)
