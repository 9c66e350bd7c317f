"""Structures checked as structures (issue 45 item 3; coopctrl.scenario.structure): a spring whose stiffness
leaves a grasp without support is bad input, exit 2, naming the spring and the property, in ``coopctrl check``
and ``coopctrl run`` alike; a value the scene reference allows never ends in "internal error"."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from coopctrl import cli
from coopctrl.errors import ScenarioError
from coopctrl.scenario import build, load_scenario
from coopctrl.scenario.structure import RTOL, check_structure

BEAM = ["springs[0].element='beam'", "springs[0].E=2e11", "springs[0].G=8e10", "springs[0].A=1e-4",
        "springs[0].Iy=1e-8"]
ZEROS = "[" + ",".join(["[0,0,0,0,0,0]"] * 6) + "]"


def sets(*items):
    return [a for item in items for a in ("--set", item)]


def run_cli(args, capsys):
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def assert_refused(code, out, err, field):
    assert code == 2, err
    assert "Traceback" not in err and "internal error" not in err
    lines = err.strip().splitlines()
    assert lines[-1].startswith(f"coopctrl: error: {field} = "), err
    assert "supports" in lines[-1] and "N/m" in lines[-1]


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("overrides, field", [
    (BEAM[:4] + ["springs[0].Iy=1e-300"], "springs[0].Iy"),
    (BEAM[:1] + ["springs[0].E=1e-300", "springs[0].G=1e-300", "springs[0].A=1e-4", "springs[0].Iy=1e-8"],
     "springs[0].E"),
    (["springs[0].element='matrix'", f"springs[0].matrix={ZEROS}"], "springs[0].matrix"),
    (["springs[1].stiffness=1e-300"], "springs[1].stiffness"),
])
def test_degenerate_structure_is_bad_input(command, overrides, field, capsys):
    """The issue's cases, through both commands: refused before any run (``run`` is refused where its plant
    is built, before pre-flight and the first tick), naming the spring and the property."""
    assert_refused(*run_cli([command, *sets(*overrides)], capsys), field)


def test_shipped_scenes_pass():
    for path in sorted((Path(__file__).resolve().parent.parent / "scenarios").glob("*.toml")):
        build.build_plant(load_scenario(path))


def test_support_threshold_is_where_the_check_refuses():
    """Just above RTOL x the stiffest support passes, just below is refused (the criterion, not a guess):
    springs[1] (1e4 N/m) against springs[0] scaled."""
    for factor, refused in ((RTOL * 10, False), (RTOL / 10, True)):
        scene = load_scenario(None, {"springs[0].stiffness": 1e4 * factor})
        if refused:
            with pytest.raises(ScenarioError, match=r"springs\[0\]\.stiffness"):
                build.build_plant(scene)
        else:
            build.build_plant(scene)


def test_fuzz_beam_properties_through_check(capsys):
    """Seeded: beam sections drawn log-uniformly over the reference's whole ranges (down to 1e-300); each
    ``coopctrl check`` ends with exit 0, or exit 2 and one line naming springs[0] and a beam property, or
    exit 1 (pre-flight: the task impossible), never an internal error. The exponents are drawn over
    [-300, 12] (E, G) and [-300, 0] (A, Iy) in halves: one half the reference's whole range, the other its
    upper decades, so that both outcomes are met."""
    rng = np.random.default_rng(45)
    outcomes = set()
    for draw in range(8):
        low = -300 if draw % 2 else -8
        E, G = 10 ** rng.uniform(low + 12, 12), 10 ** rng.uniform(low + 12, 12)
        A, Iy = 10 ** rng.uniform(low, 0), 10 ** rng.uniform(low, 0)
        code, out, err = run_cli(["check", *sets(BEAM[0], f"springs[0].E={E!r}", f"springs[0].G={G!r}",
                                                 f"springs[0].A={A!r}", f"springs[0].Iy={Iy!r}")], capsys)
        assert code in (0, 1, 2), err
        assert "internal error" not in err and "Traceback" not in err
        if code == 2:
            assert err.startswith("coopctrl: error: springs[0].") and len(err.strip().splitlines()) == 1, err
        outcomes.add(code)
    assert 2 in outcomes and outcomes & {0, 1}  # degenerate sections refused, sound ones passed


def test_check_structure_names_the_unsupported_direction():
    scene = load_scenario(None, {"springs[0].element": "beam", "springs[0].E": 2e11, "springs[0].G": 8e10,
                                 "springs[0].A": 1e-4, "springs[0].Iy": 1e-300})
    with pytest.raises(ScenarioError) as info:
        build.build_plant(scene)
    assert info.value.path == "springs[0].Iy" and "z: +1.00" in info.value.allowed
    ok = load_scenario(None, {})
    check_structure(ok, build.build_plant(ok).elastic)  # the default scene is supported
