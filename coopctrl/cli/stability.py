"""``coopctrl stability``: omega_max and each integrator's largest stable step, predicted and measured."""

from __future__ import annotations

import sys

from coopctrl.cli._core import PROG, UsageError, _add_set_option, _load, _one_line, subcommand
from coopctrl.io.console import say, visible_lines

#: The built-in integrators (kept here as plain strings so that the parser does not import numpy).
_INTEGRATORS = ("euler", "symplectic_euler", "rk4", "implicit_midpoint", "implicit_euler")


def parse_integrators(text: str) -> list[str]:
    """``"rk4,euler"`` -> ``["rk4", "euler"]``; a :class:`UsageError` naming the bad name otherwise."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in names if n not in _INTEGRATORS]
    if bad or not names:
        raise UsageError(f"--integrators {text!r} is invalid: expected a comma-separated list of "
                         f"{', '.join(_INTEGRATORS)}")
    return list(dict.fromkeys(names))


def cmd_stability(args) -> int:
    """Linearize, predict, measure (unless ``--no-measure``), print the table or the JSON."""
    import json

    names = parse_integrators(args.integrators) if args.integrators is not None else None
    scenario = _load(args)
    from coopctrl.analysis.stability import stability_report

    def progress(message: str) -> None:  # stderr, so that stdout stays clean for --json
        if not args.quiet:
            print(f"{PROG} stability: {message}", file=sys.stderr, flush=True)

    report = stability_report(scenario, names, measure=not args.no_measure, progress=progress)
    if args.json:
        say(json.dumps(report.to_dict(), indent=2, allow_nan=False))
    else:
        say(visible_lines(report.table()))
    ref = report.reference
    if ref and ref["status"] != "ok":
        print(f"{PROG}: failed: the reference run {ref['status']}, nothing measured: {_one_line(ref['reason'])}",
              file=sys.stderr)
        return 1
    return 0


@subcommand("stability")
def _stability_parser(sub) -> None:
    parser = sub.add_parser(
        "stability",
        help="omega_max and each integrator's largest stable step, predicted and measured",
        description="Linearize the scenario's plant about the state the run starts from and print omega_max "
        "(highest elastic mode, generalized eigenvalues of the stiffness against the mass matrix), its damping "
        "ratio, and for each integrator the largest stable step predicted from the open-loop plant's linearization "
        "(with damping), the one predicted from the closed loop's linearized one-period map (controller, ZOH, "
        "steps of h; at the start state and along a nominal run), and the one measured by bisection (2 %%) on the "
        "actual closed loop (controllers on), capped at the control period, with the ratios. Progress goes to "
        "stderr. Exit 0 on success, 1 if the reference run of the measurement failed, 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file or a name in scenarios/ (default: the built-in scene)")
    _add_set_option(parser)
    parser.add_argument("--integrators", metavar="NAMES",
                        help=f"comma-separated integrators (default: {','.join(_INTEGRATORS)})")
    parser.add_argument("--json", action="store_true", help="print the report as JSON on stdout (nothing else)")
    parser.add_argument("--no-measure", action="store_true", help="predict only: no closed-loop bisection")
    parser.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    parser.set_defaults(handler=cmd_stability)
