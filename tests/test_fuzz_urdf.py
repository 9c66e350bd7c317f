"""Seeded fuzz of hostile URDF files and DH tables (issue 22: security, hangs, silent garbage).

Every case must be refused as bad input -- a ``ScenarioError`` (the command line's exit 2) whose
message is one line naming the arm's field -- or be accepted as a valid arm (positive torque limits,
ordered joint limits, finite dynamics). Nothing else: no other exception, no hang, no unlimited
torque read from a negative effort. The cases: mutations of the shipped URDFs (numbers replaced by
hostile ones, elements deleted or duplicated, parent and child swapped, the text truncated), entity
bombs and external entities, cycles, a 1000-joint chain, and hostile DH rows. Most run in-process
through ``load_scenario`` and ``make_arm`` (what ``coopctrl run`` and ``check`` call); the two
security cases and a cycle also go through the command line's ``main`` (exit 2, one line on stderr).
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from coopctrl.cli import main as cli_main
from coopctrl.errors import ScenarioError
from coopctrl.io import dumps_toml
from coopctrl.scenario import load_scenario
from coopctrl.scenario.arm import MAX_DH_JOINTS
from coopctrl.scenario.build import pose_matrix, make_arm
from plants.arms import from_urdf
from plants.arms.named_robots import NAMED_ROBOTS, urdf_path
from plants.arms.puma560 import PUMA_TABLE
from plants.errors import ParameterError
from plants.urdf_reader import MAX_CHAIN_JOINTS

REPO = Path(__file__).resolve().parent.parent
SEED = 22
MUTATIONS = 24  # mutated shipped URDFs: enough to meet every mutation kind on each robot

_INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'


def _chain_urdf(n: int, *, cycle_in_chain: bool = False, cycle_in_payload: bool = False) -> str:
    """A revolute chain base -> l1 -> ... -> ln, optionally with a cycle among its links or hanging
    beyond the tip (``urdf_cycle_in_payload`` of the issue)."""
    links = ['<link name="base"/>'] + [f'<link name="l{k}">{_INERTIAL}</link>' for k in range(1, n + 1)]
    joints = [f'<joint name="j{k}" type="revolute"><parent link="{"base" if k == 1 else f"l{k - 1}"}"/>'
              f'<child link="l{k}"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
              '<limit lower="-3" upper="3" effort="50" velocity="1"/></joint>' for k in range(1, n + 1)]
    if cycle_in_payload:  # p0 -> p1 -> p2 -> p0, p0 also ... none of them reachable from base
        links += [f'<link name="p{k}">{_INERTIAL}</link>' for k in range(3)]
        joints += [f'<joint name="c{k}" type="fixed"><parent link="p{k}"/><child link="p{(k + 1) % 3}"/></joint>'
                   for k in range(3)]
    if cycle_in_chain:  # l1 becomes the child of l3 too: joint j1 is replaced by l3 -> l1
        joints[0] = joints[0].replace('<parent link="base"/>', f'<parent link="l{n}"/>')
    return '<?xml version="1.0"?>\n<robot name="chain">' + "".join(links + joints) + "</robot>\n"


def _billion_laughs() -> str:
    ents = ['<!ENTITY lol0 "lol">'] + [f'<!ENTITY lol{i} "{f"&lol{i - 1};" * 10}">' for i in range(1, 10)]
    return f'<?xml version="1.0"?>\n<!DOCTYPE robot [{"".join(ents)}]>\n<robot name="x">&lol9;</robot>\n'


_EXTERNAL = ('<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY ext SYSTEM "secret.txt">]>\n'
             '<robot name="x"><link name="base"/>&ext;</robot>\n')

_HOSTILE_NUMBERS = ("-150", "0", "-0", "nan", "inf", "-inf", "1e300", "-1e300", "", "abc", "1 2", "1e6", "-1")


def _mutate(text: str, rng: np.random.Generator) -> str:
    """One random hostile mutation of a URDF text."""
    kind = rng.integers(6)
    numbers = list(re.finditer(r'(\w+)="(-?[0-9.eE+-]+(?: -?[0-9.eE+-]+)*)"', text))
    if kind <= 1 and numbers:  # a number (or vector) replaced by a hostile value
        m = numbers[rng.integers(len(numbers))]
        return text[:m.start(2)] + str(rng.choice(_HOSTILE_NUMBERS)) + text[m.end(2):]
    if kind == 2:  # an element deleted
        elems = list(re.finditer(r"<(joint|link|inertial|limit|origin|axis|mass|inertia)\b.*?(/>|</\1>)", text, re.S))
        m = elems[rng.integers(len(elems))]
        return text[:m.start()] + text[m.end():]
    if kind == 3:  # a joint duplicated (two parents for one link)
        joints = list(re.finditer(r"<joint\b.*?</joint>", text, re.S))
        m = joints[rng.integers(len(joints))]
        return text[:m.end()] + m.group(0).replace('name="', 'name="dup_', 1) + text[m.end():]
    if kind == 4:  # parent and child of a joint swapped (a cycle or a detached chain)
        joints = list(re.finditer(r"<joint\b.*?</joint>", text, re.S))
        m = joints[rng.integers(len(joints))]
        j = m.group(0)
        p, c = re.search(r'<parent link="([^"]*)"', j), re.search(r'<child link="([^"]*)"', j)
        if p and c:
            j = j.replace(p.group(0), f'<parent link="{c.group(1)}"').replace(c.group(0), f'<child link="{p.group(1)}"', 1)
        return text[:m.start()] + j + text[m.end():]
    return text[:int(rng.integers(len(text)))]  # truncated


def _scene(tmp_path: Path, **arm0) -> Path:
    data = tomllib.loads((REPO / "scenarios" / "spatial_two_puma_carry.toml").read_text())
    data["arms"][0] = {k: v for k, v in data["arms"][0].items() if k in ("role", "base", "grasp", "node_mass", "node_inertia")}
    data["arms"][0].update(arm0)
    path = tmp_path / "scene.toml"
    path.write_text(dumps_toml(data))
    return path


def _refused_or_valid(scene: Path, field: str) -> str:
    """Build arms[0] of ``scene`` as ``run`` does: either a one-line ScenarioError naming
    ``arms[0].<field...>`` (returns "refused") or a valid arm (returns "accepted")."""
    try:
        arm = make_arm(load_scenario(scene), 0)
    except ScenarioError as err:
        message = str(err)
        assert "\n" not in message and "\r" not in message, message
        assert f"arms[0].{field}" in message or "arms[0].tip_link" in message or "arms[0].base_link" in message, message
        return "refused"
    tau = np.asarray(arm.tau_max)
    assert np.all(tau > 0.0) and not np.any(np.isnan(tau))
    assert np.all(np.asarray(arm.q_limits)[:, 0] < np.asarray(arm.q_limits)[:, 1])
    q = np.clip(0.3 + 0.1 * np.arange(arm.dof), arm.q_limits[:, 0] + 1e-3, arm.q_limits[:, 1] - 1e-3)  # generic posture
    terms = arm.terms(q, np.zeros(arm.dof))
    assert np.all(np.isfinite(terms.H)) and np.all(np.isfinite(terms.h))
    return "accepted"


def test_mutated_shipped_urdfs_are_refused_or_valid(tmp_path):
    rng = np.random.default_rng(SEED)
    outcomes = []
    robots = sorted(NAMED_ROBOTS)
    for i in range(MUTATIONS):
        robot = robots[i % len(robots)]
        _, base_link, tip_link = NAMED_ROBOTS[robot]
        text = _mutate(Path(urdf_path(robot)).read_text(), rng)
        (tmp_path / "arm.urdf").write_text(text)
        scene = _scene(tmp_path, model="urdf", urdf="arm.urdf", base_link=base_link, tip_link=tip_link)
        outcomes.append(_refused_or_valid(scene, "urdf"))
    # the fuzz exercises both outcomes (a mutation of an unread element leaves a valid arm)
    assert "refused" in outcomes and "accepted" in outcomes


@pytest.mark.parametrize("case, text, tip, needle, at_load", [
    ("billion laughs", _billion_laughs(), "tip", "document type declaration", True),
    ("external entity", _EXTERNAL, "tip", "document type declaration", True),
    ("cycle in the payload", _chain_urdf(3, cycle_in_payload=True), "l3", "cycle", True),
    ("cycle in the chain", _chain_urdf(3, cycle_in_chain=True), "l3", "cycle", True),
    ("1000-joint chain", _chain_urdf(1000), "l1000", f"at most {MAX_CHAIN_JOINTS} joints", True),
    ("negative effort", _chain_urdf(3).replace('effort="50"', 'effort="-150"', 1), "l3", "effort limit > 0", False),
    ("zero effort", _chain_urdf(3).replace('effort="50"', 'effort="0"', 1), "l3", "effort limit > 0", False),
    ("NaN origin", _chain_urdf(3).replace('xyz="0 0 0.1"', 'xyz="0 nan 0.1"', 1), "l3", "finite", False),
    ("huge mass", _chain_urdf(3).replace('mass value="1"', 'mass value="1e300"', 1), "l3", "magnitude", False),
])
def test_hostile_urdfs_are_refused_in_one_line(tmp_path, case, text, tip, needle, at_load):
    """Refused with one line naming arms[0]; the document and tree checks already when the loaded
    scene counts its joints (plants.urdf_reader: before numba is imported or anything is built, as
    the command line does right after loading), the numbers when the arm is built."""
    (tmp_path / "arm.urdf").write_text(text)
    scene = _scene(tmp_path, model="urdf", urdf="arm.urdf", base_link="base", tip_link=tip)
    with pytest.raises(ScenarioError) as info:
        scenario = load_scenario(scene)
        scenario.dof_per_arm  # what the command line reads right after loading  # noqa: B018
        assert not at_load, case
        make_arm(scenario, 0)
    message = str(info.value)
    assert "\n" not in message and needle in message, (case, message)
    assert "arms[0]." in message


def test_a_chain_of_the_documented_length_is_accepted(tmp_path):
    (tmp_path / "arm.urdf").write_text(_chain_urdf(MAX_CHAIN_JOINTS + 1))
    assert from_urdf(tmp_path / "arm.urdf", "base", f"l{MAX_CHAIN_JOINTS}").dof == MAX_CHAIN_JOINTS
    with pytest.raises(ParameterError, match="tip_link"):
        from_urdf(tmp_path / "arm.urdf", "base", f"l{MAX_CHAIN_JOINTS + 1}")


@pytest.mark.parametrize("text", [_billion_laughs(), _EXTERNAL, _chain_urdf(3, cycle_in_payload=True)],
                         ids=["billion-laughs", "external-entity", "cycle"])
def test_command_line_refuses_hostile_urdf_with_exit_2(tmp_path, capsys, text):
    (tmp_path / "arm.urdf").write_text(text)
    scene = _scene(tmp_path, model="urdf", urdf="arm.urdf", base_link="base", tip_link="l3")
    assert cli_main(["check", str(scene)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("coopctrl: error: ") and "arms[0].urdf = " in err[0], err


@pytest.mark.parametrize("tool", [np.eye(3), np.zeros(5), [0, 0, 0, np.nan, 0, 0], np.full((4, 4), np.inf), "abc"],
                         ids=["3x3", "5", "nan", "inf4x4", "str"])
def test_from_urdf_checks_the_tool(tool):
    with pytest.raises(ValueError, match=r"^tool = .*\n?") as info:
        from_urdf(urdf_path("ur5e"), "base_link", "tool0", tool)
    assert "\n" not in str(info.value)


def test_from_urdf_accepts_a_tool_pose_of_six_numbers():
    """A 6-number tool pose is the scene's pose convention (x, y, z, ZYX psi, theta, phi): the same
    node frame as the scene builder's 4x4 of that pose (exact rotation formulas: rounding level)."""
    pose = [0.01, -0.02, 0.1, 0.2, -0.3, 0.4]
    arm = from_urdf(urdf_path("ur5e"), "base_link", "tool0", pose)
    by_matrix = from_urdf(urdf_path("ur5e"), "base_link", "tool0", pose_matrix(pose))
    assert np.allclose(arm.tool, by_matrix.tool, rtol=0, atol=1e-14)


def _dh_rows():
    return [[a, alpha, d, 0.0, m, *rc, *inertia] for a, alpha, d, m, rc, inertia, *_ in PUMA_TABLE]


def test_hostile_dh_rows_are_refused_or_valid(tmp_path):
    rng = np.random.default_rng(SEED + 1)
    hostile = (-1.0, 0.0, np.nan, np.inf, -np.inf, 1e300, -1e300, 1e7, 1e6, -5.0)
    outcomes = []
    for _ in range(20):
        rows = _dh_rows()
        for _ in range(int(rng.integers(1, 3))):
            rows[rng.integers(len(rows))][rng.integers(14)] = float(rng.choice(hostile))
        scene = _scene(tmp_path, model="dh", dh=[[float(v) for v in r] for r in rows])
        try:
            outcomes.append(_refused_or_valid(scene, "dh"))
        except ScenarioError:  # the TOML writer refuses NaN/inf before the scene exists: refused too
            outcomes.append("refused")
    assert "refused" in outcomes
    scene = _scene(tmp_path, model="dh", dh=_dh_rows() * 20)  # 120 joints
    with pytest.raises(ScenarioError, match=rf"arms\[0\]\.dh.*1 to {MAX_DH_JOINTS} rows"):
        load_scenario(scene)


@pytest.mark.parametrize("path", ["/dev/zero", "."], ids=["device", "directory"])
def test_a_urdf_that_is_not_a_regular_file_is_refused(tmp_path, path):
    """/dev/zero would be read without end; a directory cannot be parsed: both refused before reading."""
    scene = _scene(tmp_path, model="urdf", urdf=path, base_link="base", tip_link="tip")
    with pytest.raises(ScenarioError, match=r"arms\[0\]\.urdf.*a regular URDF file"):
        load_scenario(scene).dof_per_arm  # noqa: B018
