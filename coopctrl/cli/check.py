"""``coopctrl check``: validate a scenario without simulating it."""

from __future__ import annotations

from coopctrl.cli._core import _add_set_option, _load, subcommand

def cmd_check(args) -> int:
    """Validate a scenario without simulating it: its fields, then the physics it implies (every grasp
    within reach, torque limits above the arms' own gravity load, the loaded initial state, a nominal
    path clear of the Euler-angle singularity)."""
    scenario = _load(args)
    scenario.plant()
    scenario.initial_state()
    from coopctrl.simulator import closed_loop

    closed_loop(scenario)  # refuses a nominal path near the Euler-angle singularity (coopctrl.analysis.euler_singularity)
    print(
        f"ok: {scenario.name} ({scenario.space}, {len(scenario.arms)} arms, state size {scenario.state_size}, "
        f"{scenario.simulation.control_steps} control steps of {scenario.simulation.control_period:g} s)"
    )
    return 0


@subcommand
def _check_parser(sub) -> None:
    parser = sub.add_parser(
        "check", help="validate a scenario file", description="Validate a scenario (and overrides) without simulating. Exit 0 if valid, 2 if not."
    )
    parser.add_argument("scenario", help="scenario .toml file, or the name of one in scenarios/")
    _add_set_option(parser)
    parser.set_defaults(handler=cmd_check)
