"""``coopctrl view``: write the 3-D replay ``replay.html`` of a saved result."""

from __future__ import annotations

from pathlib import Path

from coopctrl.cli._core import UsageError, parse_sets, resolve_scenario, subcommand


def cmd_view(args) -> int:
    """Rebuild ``DIR/replay.html`` from ``DIR/result.npz`` and the scenario it ran
    (``DIR/scenario.toml``, written by ``coopctrl run --out``, or ``--scenario``), after checking that the
    folder is whole and consistent (:func:`coopctrl.results.folder.open_result_folder`)."""
    import sys

    from coopctrl.io.console import OutputWriteError, say, visible
    from coopctrl.results.folder import open_result_folder, rewrite_replay

    directory = Path(args.directory)
    scenario = None
    if args.scenario:
        from coopctrl.scenario import load_scenario

        scenario = load_scenario(resolve_scenario(args.scenario), parse_sets(args.sets))
    elif args.sets:
        raise UsageError("--set needs --scenario: the scenario of DIR is DIR/scenario.toml as it ran")
    result, scenario, _ = open_result_folder(directory, scenario)
    try:
        path = rewrite_replay(result, scenario, directory)
    except OutputWriteError as err:  # a full disk, a folder that cannot be written: the system's refusal, exit 1
        print(f"coopctrl: failed: {err}; {visible(directory)} was left as it was", file=sys.stderr)
        return 1
    try:
        say(f"replay written to {visible(path)} (open it in a browser; works offline)")
    except OutputWriteError as err:
        print(f"coopctrl: failed: {err} (the replay itself was written whole)", file=sys.stderr)
        return 1
    return 0


@subcommand("view")
def _view_parser(sub) -> None:
    parser = sub.add_parser(
        "view",
        help="write the 3-D replay (replay.html) of a saved result",
        description="Write DIR/replay.html, a self-contained page (no network) that replays the run of "
        "DIR/result.npz in 3-D: arms, contact nodes, springs, object and contact forces, with play, pause, "
        "a time slider and speed. `coopctrl run ... --out DIR` writes it too. The folder is checked first: a damaged "
        "result.npz, a scenario.toml changed after the run or data that contradict the run's status are refused. "
        "Exit 0, 1 when the page cannot be written (a full disk, a folder that cannot be written), 2 for bad input.",
    )
    parser.add_argument("directory", metavar="DIR", help="output directory of `coopctrl run --out DIR`")
    parser.add_argument("--scenario", metavar="FILE", help="the scenario of the run (default: DIR/scenario.toml)")
    parser.add_argument("--set", dest="sets", action="append", default=[], metavar="PATH=VALUE",
                        help="override of --scenario, as for `coopctrl run`; repeatable")
    parser.set_defaults(handler=cmd_view)
