"""``coopctrl compare-plants``: run a scene on the elastic plant and on MuJoCo, and print where they differ."""

from __future__ import annotations

from coopctrl.cli._core import _add_set_option, _load, subcommand


def cmd_compare_plants(args) -> int:
    """Both runs, then the comparison table (or JSON); exit 1 when either run failed."""
    import json
    import sys

    from coopctrl.io.console import say
    from coopctrl.mujoco.requirement import import_mujoco

    import_mujoco()  # exit 2 naming the extra, before any work
    scenario = _load(args)
    from coopctrl.mujoco.comparison import compare_plants
    from coopctrl.mujoco.closed_loop import check_scene
    from coopctrl.scenario.build import check_path

    check_scene(scenario)
    check_path(scenario)
    comparison = compare_plants(scenario, progress=not args.json and sys.stderr.isatty())
    if args.json:
        say(json.dumps(comparison.to_dict(), indent=2, default=float))
    else:
        for line in comparison.lines():
            say(line)
    failed = [name for name, s in (("elastic", comparison.elastic), ("mujoco", comparison.mujoco)) if s["status"] != "ok"]
    for name in failed:
        s = getattr(comparison, name)
        print(f"coopctrl: {s['status']}: the {name} plant's run: {s['reason']}", file=sys.stderr)
    return 1 if failed else 0


@subcommand("compare-plants")
def _compare_plants_parser(sub) -> None:
    parser = sub.add_parser(
        "compare-plants",
        help="run a scenario on the elastic plant and on MuJoCo and print where they differ",
        description="Run the scenario twice with the same controller: on the book's elastic plant and on MuJoCo "
        "(needs pip install 'coopctrl[mujoco]'). Print each run's tracking figures and, per signal (object position "
        "and orientation, contact forces and couples, joint torques), the largest difference with its time. "
        "docs/mujoco.md explains which differences are the models'. Exit 0, 1 if either run failed, 2 for bad input.",
    )
    parser.add_argument("scenario", help="scenario .toml file, or the name of one in scenarios/")
    _add_set_option(parser)
    parser.add_argument("--json", action="store_true", help="print the comparison as JSON on stdout")
    parser.set_defaults(handler=cmd_compare_plants)
