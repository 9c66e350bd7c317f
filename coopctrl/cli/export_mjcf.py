"""``coopctrl export-mjcf``: write a scene's MuJoCo model (MJCF), to open in MuJoCo's own viewer."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from coopctrl.cli._core import _add_set_option, _load, one_line, subcommand


def xml_file(text: str) -> Path:
    """``OUT.xml`` of ``export-mjcf`` (an ``argparse`` type, checked before any work): a ``.xml`` name that is not
    a directory, in an existing writable directory."""
    path = Path(text).expanduser()
    allowed = "a .xml file path in an existing writable directory"
    if path.suffix.lower() != ".xml":
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: expected {allowed} (the name must end in .xml)")
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: it is a directory; expected {allowed}")
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir() or not os.access(directory, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: its directory does not exist or cannot be written; "
                                         f"expected {allowed}")
    return path


def cmd_export_mjcf(args) -> int:
    """Build the scene's MJCF (with its start as the keyframe ``start``), compile it with MuJoCo, write it whole."""
    from coopctrl.io.atomic import atomic_write
    from coopctrl.io.console import say
    from coopctrl.mujoco.requirement import import_mujoco

    mujoco = import_mujoco()  # exit 2 naming the extra, before any work
    scenario = _load(args)
    from coopctrl.mujoco.mjcf import scene_mjcf
    from coopctrl.scenario.build import build_plant, check_path, initial_state

    check_path(scenario)
    plant = build_plant(scenario)
    scene_mjcf(scenario, plant=plant)  # an arm MuJoCo cannot hold (contact_point) is refused before the start's solve
    xml = scene_mjcf(scenario, x_start=initial_state(scenario), plant=plant)
    mujoco.MjModel.from_xml_string(xml)  # the file written always loads
    with atomic_write(args.out) as handle:
        handle.write(xml)
    say(f"MuJoCo model written to {one_line(args.out)} (view it: python -m mujoco.viewer --mjcf "
        f"{one_line(args.out)}; keyframe 'start' is the run's start)")
    return 0


@subcommand("export-mjcf")
def _export_mjcf_parser(sub) -> None:
    parser = sub.add_parser(
        "export-mjcf",
        help="write a scenario's MuJoCo model (MJCF) to open in MuJoCo's viewer",
        description="Write the MJCF model of a scenario: its arms (from the same joint tables as coopctrl's arm "
        "kernels), contact nodes, object, force-torque sensors at the nodes, a motor per joint, the grasp elements "
        "drawn as tendons, and the run's start as the keyframe 'start'. The grasps' springs are applied as forces by "
        "`coopctrl run --plant mujoco`, not by the file (docs/mujoco.md). Needs pip install 'coopctrl[mujoco]'. "
        "Exit 0, 2 for bad input.",
    )
    parser.add_argument("scenario", help="scenario .toml file, or the name of one in scenarios/")
    parser.add_argument("out", type=xml_file, metavar="OUT.xml", help="the MJCF file to write (replaced whole)")
    _add_set_option(parser)
    parser.set_defaults(handler=cmd_export_mjcf)
