"""``coopctrl view``: write the 3-D replay ``replay.html`` of a saved result."""

from __future__ import annotations

from pathlib import Path

from coopctrl.cli._core import UsageError, parse_sets, resolve_scenario, subcommand


def cmd_view(args) -> int:
    """Rebuild ``DIR/replay.html`` from ``DIR/result.npz`` and the scenario it ran
    (``DIR/scenario.toml``, written by ``coopctrl run --out``, or ``--scenario``)."""
    directory = Path(args.directory)
    npz = directory / "result.npz"
    if not npz.is_file():
        raise UsageError(f"DIR = {str(directory)!r} is invalid: expected a directory with result.npz "
                         "(written by `coopctrl run SCENARIO --out DIR`)")
    from coopctrl.scenario import load_scenario

    if args.scenario:
        scenario = load_scenario(resolve_scenario(args.scenario), parse_sets(args.sets))
    else:
        if args.sets:
            raise UsageError("--set needs --scenario: the scenario of DIR is DIR/scenario.toml as it ran")
        saved = directory / "scenario.toml"
        if not saved.is_file():
            raise UsageError(f"{saved} is missing: give the scenario the result ran with, --scenario FILE [--set ...]")
        scenario = load_scenario(saved)
    from coopctrl.results import SimulationResult

    try:
        result = SimulationResult.load(directory)
    except (OSError, ValueError, KeyError) as err:
        raise UsageError(f"{npz} cannot be read ({' '.join(str(err).split())}): expected a result.npz of `coopctrl run --out`") from None
    expected = sum(scenario.dof_per_arm) * 2 + 2 * scenario.pose_size
    if result.scenario != scenario.name or result.x.shape[1] != expected:
        raise UsageError(f"--scenario = {scenario.name!r} is invalid: expected the scenario of the result "
                         f"({result.scenario!r}, state size {result.x.shape[1]})")
    from coopctrl.replay import write_replay

    try:
        path = write_replay(result, scenario, directory)
    except OSError as err:
        raise UsageError(f"DIR = {str(directory)!r} is invalid: expected a writable directory "
                         f"({err.strerror or err})") from None
    print(f"replay written to {path} (open it in a browser; works offline)")
    return 0


@subcommand
def _view_parser(sub) -> None:
    parser = sub.add_parser(
        "view",
        help="write the 3-D replay (replay.html) of a saved result",
        description="Write DIR/replay.html, a self-contained page (no network) that replays the run of "
        "DIR/result.npz in 3-D: arms, contact nodes, springs, object and contact forces, with play, pause, "
        "a time slider and speed. `coopctrl run ... --out DIR` writes it too. Exit 0, 2 for bad input.",
    )
    parser.add_argument("directory", metavar="DIR", help="output directory of `coopctrl run --out DIR`")
    parser.add_argument("--scenario", metavar="FILE", help="the scenario of the run (default: DIR/scenario.toml)")
    parser.add_argument("--set", dest="sets", action="append", default=[], metavar="PATH=VALUE",
                        help="override of --scenario, as for `coopctrl run`; repeatable")
    parser.set_defaults(handler=cmd_view)
