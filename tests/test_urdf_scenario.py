"""Scene keys of issue 13: ``model = "dh"`` agrees with the same arm from a URDF file, and bad
URDF / DH input is a one-line error naming the field, exit code 2 (CLI)."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from coopctrl.io import dumps_toml
from coopctrl.scenario import load_scenario
from coopctrl.scenario.build import make_arm
from plants.arms import from_urdf
from plants.arms.puma560 import PUMA_TABLE
from plants.frames import euler_zyx_from_rotation

REPO = Path(__file__).resolve().parent.parent
REL = 1e-9  # both sides are exact rigid-body algorithms: rounding-level agreement


def _dh_rows():
    """The Puma 560 as a scene's DH table rows (a, alpha, d, offset, mass, rc, I)."""
    return [[a, alpha, d, 0.0, m, *rc, *inertia] for a, alpha, d, m, rc, inertia, *_ in PUMA_TABLE]


def _fixed(a, alpha, d):
    """``Tz(d) Tx(a) Rx(alpha)``."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0, a], [0.0, c, -s, 0.0], [0.0, s, c, d], [0.0, 0.0, 0.0, 1.0]])


def _origin(T):
    yaw, pitch, roll = euler_zyx_from_rotation(np.ascontiguousarray(T[:3, :3]))
    v = [repr(float(t)) for t in (T[0, 3], T[1, 3], T[2, 3], roll, pitch, yaw)]
    return f'<origin xyz="{v[0]} {v[1]} {v[2]}" rpy="{v[3]} {v[4]} {v[5]}"/>'


def _dh_as_urdf(rows) -> str:
    """The same arm written as URDF by hand: link k's frame sits before DH frame k's fixed part
    ``G_k = Tz(d) Tx(a) Rx(alpha)``; joint k+1's origin is ``G_k``; link k's inertial frame is
    ``G_k`` (COM and inertia as given in DH frame k); the tip is DH frame n."""
    links = ['<link name="base"/>']
    joints = []
    G_prev = np.eye(4)
    for k, r in enumerate(rows, start=1):
        a, alpha, d, _, m = r[:5]
        rc, I = r[5:8], r[8:14]
        G = _fixed(a, alpha, d)
        Tc = G.copy()
        Tc[:3, 3] = G[:3, :3] @ np.array(rc) + G[:3, 3]
        links.append(f'<link name="l{k}"><inertial>{_origin(Tc)}<mass value="{m}"/>'
                     f'<inertia ixx="{I[0]}" iyy="{I[1]}" izz="{I[2]}" ixy="{I[3]}" iyz="{I[4]}" ixz="{I[5]}"/>'
                     '</inertial></link>')
        parent = "base" if k == 1 else f"l{k - 1}"
        joints.append(f'<joint name="j{k}" type="revolute"><parent link="{parent}"/><child link="l{k}"/>{_origin(G_prev)}'
                      '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="1"/></joint>')
        G_prev = G
    links.append('<link name="tip"/>')
    joints.append(f'<joint name="jt" type="fixed"><parent link="l{len(rows)}"/><child link="tip"/>{_origin(G_prev)}</joint>')
    return '<?xml version="1.0"?>\n<robot name="dh_arm">' + "".join(links + joints) + "</robot>\n"


def _scene_data(**arm0):
    data = tomllib.loads((REPO / "scenarios" / "spatial_two_puma_carry.toml").read_text())
    data["arms"][0] = {k: v for k, v in data["arms"][0].items() if k in ("role", "base", "grasp", "node_mass", "node_inertia")}
    data["arms"][0].update(arm0)
    return data


def test_dh_table_in_a_scene_agrees_with_the_urdf_arm(tmp_path):
    rows = _dh_rows()
    urdf = tmp_path / "dh_arm.urdf"
    urdf.write_text(_dh_as_urdf(rows))
    scene = tmp_path / "dh.toml"
    scene.write_text(dumps_toml(_scene_data(model="dh", dh=rows)))
    dh_arm = make_arm(load_scenario(scene), 0)
    urdf_arm = from_urdf(urdf, "base", "tip", base=dh_arm.base)
    rng = np.random.default_rng(17)
    for _ in range(5):
        q = rng.uniform(-2.0, 2.0, 6)
        dq = rng.uniform(-1.0, 1.0, 6)
        a, b = dh_arm.terms(q, dq), urdf_arm.terms(q, dq)
        for name in ("H", "h", "Y", "J", "Jdq"):
            x, y = getattr(a, name), getattr(b, name)
            assert np.linalg.norm(x - y) <= REL * np.linalg.norm(x), name


def test_urdf_scene_resolves_the_path_relative_to_the_scene_file(tmp_path):
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "dh_arm.urdf").write_text(_dh_as_urdf(_dh_rows()))
    scene = tmp_path / "urdf.toml"
    scene.write_text(dumps_toml(_scene_data(model="urdf", urdf="robots/dh_arm.urdf", base_link="base", tip_link="tip",
                                            tool=[0.0, 0.0, 0.05, 0.0, -1.5707963267948966, 0.0])))
    scenario = load_scenario(scene)
    assert scenario.dof_per_arm == [6, 6]
    arm = make_arm(scenario, 0)
    assert arm.dof == 6 and arm.tau_max[0] == 100.0


# ---------------------------------------------------------------------- CLI: bad input
def coopctrl(*args, cwd=None):
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.run([sys.executable, "-m", "coopctrl", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd or REPO, timeout=600)


_BAD_URDF = """<?xml version="1.0"?>
<robot name="bad">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"/>
  <link name="tip"/>
  <joint name="j1" type="JTYPE"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="50" velocity="1"/></joint>
  <joint name="jt" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.2 0 0"/></joint>
</robot>
"""


@pytest.mark.parametrize("case, arm0, needles", [
    ("missing URDF file", dict(model="urdf", urdf="robots/missing.urdf", base_link="base", tip_link="tip"),
     ["arms[0].urdf", "missing.urdf", "an existing URDF file"]),
    ("tip_link not in the tree", dict(model="urdf", urdf="bad.urdf", base_link="base", tip_link="hand"),
     ["arms[0].tip_link", "'hand'"]),
    ("unsupported joint type", dict(model="urdf", urdf="floating.urdf", base_link="base", tip_link="tip"),
     ["arms[0].urdf", "joint 'j1'.type", "floating"]),
    ("link without inertia", dict(model="urdf", urdf="bad.urdf", base_link="base", tip_link="tip"),
     ["arms[0].urdf", "link 'l2'.inertial"]),
    ("DH table of the wrong shape", dict(model="dh", dh=[[0.0, 1.57, 0.3, 0.0, 1.0]]),
     ["arms[0].dh[0]", "14 numbers"]),
])
def test_bad_arm_input_is_one_line_exit_2(tmp_path, case, arm0, needles):
    (tmp_path / "bad.urdf").write_text(_BAD_URDF.replace("JTYPE", "revolute"))
    (tmp_path / "floating.urdf").write_text(_BAD_URDF.replace("JTYPE", "floating"))
    scene = tmp_path / "scene.toml"
    scene.write_text(dumps_toml(_scene_data(**arm0)))
    proc = coopctrl("run", scene)
    assert proc.returncode == 2, (case, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("coopctrl: error: ")
    for needle in needles:
        assert needle in lines[0], (case, lines[0])
    assert proc.stdout == ""
