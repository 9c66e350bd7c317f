"""The 3-D replay (issue 14): the frames it draws, the page, ``coopctrl view``, and the page in a
real headless browser (Debian's ``chromium``; skipped with the reason when it is absent)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl.replay import replay_data, write_replay

REPO = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Both full runs (the carry moves 0.3 m, the lift 0.3 m: frames far apart differ)."""
    out = {}
    for name in ("spatial_two_puma_carry", "planar_two_arm_lift"):
        scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml")
        result = coopctrl.simulate(scenario)
        directory = tmp_path_factory.mktemp(name)
        result.save(directory)
        write_replay(result, scenario, directory)
        out[name] = (scenario, result, directory)
    return out


def test_frames_follow_the_run(runs):
    scenario, result, _ = runs["spatial_two_puma_carry"]
    data = replay_data(result, scenario)
    frames = data["frames"]
    assert 2 <= len(frames) <= 400 and frames[-1]["t"] == pytest.approx(result.t[-1])
    # each Puma: base, then per joint the Tz(d) point and the frame origin, then the node (2*6 + 2)
    assert [len(a) // 3 for a in frames[0]["arms"]] == [14, 14]
    for f, k in ((frames[0], 0), (frames[-1], len(result.t) - 1)):
        Y = scenario.plant().node_poses(result.x[k]).reshape(3, 6)
        # the arm's last point is its node, the node list holds the same (rounding of the page: 1e-5 m)
        np.testing.assert_allclose(np.reshape(f["arms"][0], (-1, 3))[-1], Y[1, :3], atol=2e-5)
        np.testing.assert_allclose(np.reshape(f["nodes"], (-1, 3)), Y[1:, :3], atol=2e-5)
        np.testing.assert_allclose(f["object"][:3], Y[0, :3], atol=2e-6)
        np.testing.assert_allclose(np.reshape(f["forces"], (-1, 3)), result.F_measured[k][:, :3], atol=1e-3)
    # the object moved, as the trajectory says (0.3 m in all), and the springs are drawn with it
    assert np.linalg.norm(np.subtract(frames[-1]["object"][:3], frames[0]["object"][:3])) > 0.25
    assert frames[-1]["springs"] != frames[0]["springs"]
    json.dumps(data, allow_nan=False)  # embeddable as is


def test_planar_frames_lie_in_their_plane(runs):
    scenario, result, _ = runs["planar_two_arm_lift"]
    data = replay_data(result, scenario)
    for f in data["frames"][:: max(1, len(data["frames"]) // 10)]:
        for arm in f["arms"]:
            assert np.allclose(np.reshape(arm, (-1, 3))[:, 1], 0.0)  # y = 0: the x-z plane
        Y = scenario.plant().node_poses(result.x[0]).reshape(3, 3)
    np.testing.assert_allclose(np.reshape(data["frames"][0]["nodes"], (-1, 3))[:, [0, 2]], Y[1:, :2], atol=2e-5)


def test_page_is_self_contained(runs):
    _, _, directory = runs["planar_two_arm_lift"]
    text = (directory / "replay.html").read_text(encoding="utf-8")
    assert "three.js" in text.lower() and "var DATA = {" in text
    # offline: no script, style or image is fetched from anywhere
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=", text)
    assert "http://" not in text.split("var DATA")[1] and "https://" not in text.split("var DATA")[1]
    assert (directory / "scenario.toml").is_file()


def test_view_rebuilds_the_page_of_a_saved_result(runs, tmp_path):
    _, _, directory = runs["planar_two_arm_lift"]
    target = tmp_path / "saved"
    shutil.copytree(directory, target)
    (target / "replay.html").unlink()
    proc = subprocess.run([sys.executable, "-m", "coopctrl", "view", str(target)], capture_output=True, text=True,
                          timeout=300, cwd=REPO)
    assert proc.returncode == 0, proc.stderr
    assert (target / "replay.html").read_text(encoding="utf-8") == (directory / "replay.html").read_text(encoding="utf-8")
    missing = subprocess.run([sys.executable, "-m", "coopctrl", "view", str(tmp_path / "nothing")],
                             capture_output=True, text=True, timeout=300, cwd=REPO)
    assert missing.returncode == 2 and "result.npz" in missing.stderr and "Traceback" not in missing.stderr


# ---------------------------------------------------------------------- the page in a browser
def _chromium(url: str, *extra: str) -> subprocess.CompletedProcess:
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
             "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run",
             f"--user-data-dir={profile}", "--hide-scrollbars", "--window-size=1000,700",
             "--virtual-time-budget=4000", *extra, url],
            capture_output=True, text=True, timeout=120)


def _screenshot(page: Path, frame: int, png: Path) -> np.ndarray:
    from matplotlib.image import imread

    proc = _chromium(f"{page.as_uri()}#frame={frame}", f"--screenshot={png}")
    assert png.is_file(), proc.stderr[-2000:]
    image = imread(png)[:, :, :3]
    return (image * 255).astype(int)[70:630]  # the 3-D view: below the legend, above the controls


def _coloured(image: np.ndarray) -> tuple[int, int]:
    """Pixels of the leader (blue) and follower (orange) arms: shaded, so hue tests with margins."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    blue = (b > r + 50) & (b > 90)
    orange = (r > 140) & (r > b + 80) & (g > b + 20)
    return int(blue.sum()), int(orange.sum())


needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian: apt-get install chromium)")


@needs_chromium
def test_browser_spatial_frames_differ_and_show_the_bodies(runs, tmp_path):
    _, _, directory = runs["spatial_two_puma_carry"]
    page = directory / "replay.html"
    dom = _chromium(page.as_uri() + "#frame=0", "--dump-dom").stdout
    assert 'data-ready="1"' in dom, "the page's script did not finish"
    assert "spatial_two_puma_carry replay (ok)" in dom
    assert 'data-frame="0"' in dom  # "#frame=0" opens paused on the first frame
    # without a frame in the URL the page plays: within 1.5 s of (virtual) time it has moved on
    played = _chromium(page.as_uri(), "--dump-dom").stdout
    frame = re.search(r'data-frame="(\d+)"', played)
    assert frame and int(frame.group(1)) > 0, "the replay did not play"
    assert 'data-frame="7"' in _chromium(page.as_uri() + "#frame=7&speed=4", "--dump-dom").stdout
    last = len(json.loads(page.read_text(encoding="utf-8").split("var DATA = ", 1)[1].split(";\n</script>", 1)[0])["frames"]) - 1
    first = _screenshot(page, 0, tmp_path / "spatial_0.png")
    end = _screenshot(page, last, tmp_path / "spatial_end.png")
    for image in (first, end):
        blue, orange = _coloured(image)
        # both arms drawn: measured 4700 (leader) and 7500 (follower) px at 1000x700; 500 allows any renderer
        assert blue > 500 and orange > 500, (blue, orange)
        assert (image.min(axis=-1) < 200).mean() > 0.01  # bodies and grid on the white background
    # the arms moved: 4.3 % of the view's pixels changed between the first and last frames here; a
    # tenth of a percent (about 500 px) would still be a visible move, a static page gives 0
    assert (np.abs(first - end).max(axis=-1) > 40).mean() > 0.002


@needs_chromium
def test_browser_planar_scene_is_drawn_in_its_plane(runs, tmp_path):
    _, _, directory = runs["planar_two_arm_lift"]
    page = directory / "replay.html"
    first = _screenshot(page, 0, tmp_path / "planar_0.png")
    end = _screenshot(page, 10_000, tmp_path / "planar_end.png")  # past the end: the last frame
    for image in (first, end):
        blue, orange = _coloured(image)
        assert blue > 500 and orange > 500, (blue, orange)  # measured about 3000 each
    assert (np.abs(first - end).max(axis=-1) > 40).mean() > 0.002  # measured 3.3 %
    # seen along y, the two arms stand apart left and right (leader base at x = -0.6, follower +0.6)
    r, b = first[..., 0], first[..., 2]
    cols_blue = np.nonzero(((b > r + 50) & (b > 90)).any(axis=0))[0]
    cols_orange = np.nonzero(((r > 140) & (r > b + 80)).any(axis=0))[0]
    assert np.median(cols_blue) < np.median(cols_orange)


@pytest.mark.parametrize("path", sorted((REPO / "scenarios").glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_scene_gives_frames(path):
    # 20 control periods: enough to build every part of the page; the drawing is what is tested
    scenario = coopctrl.load_scenario(path, {"simulation.duration": 20 * coopctrl.load_scenario(path).simulation.control_period})
    result = coopctrl.simulate(scenario)
    data = replay_data(result, scenario)
    assert data["frames"] and len(data["frames"][0]["springs"]) == len(scenario.springs)
    for k, arm in enumerate(scenario.arms):
        points = np.reshape(data["frames"][0]["arms"][k], (-1, 3))
        assert (len(points) == 0) == (arm.model == "contact_point")
        if scenario.space == "planar":
            assert np.all(points[:, 1] == 0.0)


def test_the_replay_of_a_run_in_charts_shows_the_turn():
    """Issue 20: two_panda_flip tips its box 100 deg in pitch in rotation charts (its record in the book's
    angles on the branch past pitch 90 deg). Every frame poses the box with its true rotation,
    ``result.object_rotation``, also the frames next to pitch 90 deg, and the last has turned it past 90 deg."""
    from coopctrl.trajectory.quaternion import matrix

    scenario = coopctrl.load_scenario(REPO / "scenarios" / "two_panda_flip.toml")
    assert scenario.scene.rotations == "charts"
    result = coopctrl.simulate(scenario)
    assert result.status == "ok" and result.object_rotation is not None
    frames = replay_data(result, scenario)["frames"]
    samples = [int(np.argmin(np.abs(result.t - f["t"]))) for f in frames]
    assert samples[-1] == len(result.t) - 1
    true = matrix(np.asarray(result.object_rotation)[samples])
    drawn = np.array([np.reshape(f["object"][3:], (3, 3)) for f in frames])
    # the page keeps 6 decimals of each rotation entry (5e-7); the rest is the book angles' rounding
    np.testing.assert_allclose(drawn, true, atol=1e-6)
    # some frame within 1.2 deg of pitch 90 deg (cos(theta) = |R[:2, 0]| < 0.02): the check covers the band
    assert np.min(np.hypot(true[:, 0, 0], true[:, 1, 0])) < 0.02
    # the box's x and z axes turned through more than 90 deg from the first frame to the last
    turn = np.degrees(np.arccos(np.clip(np.sum(drawn[0] * drawn[-1], axis=0), -1.0, 1.0)))
    assert turn[0] > 90.0 and turn[2] > 90.0


# ---------------------------------------------------------------------- URDF arms (issue 21)
@pytest.fixture(scope="module")
def panda_still():
    """Replay data of the two Pandas at rest over 2.5 s of 1 ms samples (no simulation)."""
    from _replay_data import still_result

    scenario = coopctrl.load_scenario(REPO / "scenarios" / "two_panda_carry.toml")
    return scenario, replay_data(still_result(scenario, np.arange(2501) * 1e-3), scenario)


def _moving_links(urdf: Path, base: str, tip: str) -> list[str]:
    """The child links of the moving joints from ``base`` to ``tip``, read here with the
    standard library's parser: the oracle of the page's ``arm_links``."""
    import xml.etree.ElementTree as ET

    joints = {j.find("child").get("link"): j for j in ET.parse(urdf).getroot().findall("joint")}
    out, link = [], tip
    while link != base:
        j = joints[link]
        if j.get("type") != "fixed":
            out.append(link)
        link = j.find("parent").get("link")
    return out[::-1]


def test_urdf_arm_is_drawn_through_its_joint_frames(panda_still):
    from plants.arms.named_robots import urdf_path

    scenario, data = panda_still
    plant = scenario.plant()
    moving = _moving_links(Path(urdf_path("panda")), "panda_link0", "panda_hand_tcp")
    assert len(moving) == 7
    f = data["frames"][0]
    x0 = coopctrl.scenario.build.unloaded_state(scenario)
    for i, arm in enumerate(plant.arms):
        # one segment per body: the fixed base link, then each moving link (7 for a Panda)
        assert data["arm_links"][i] == ["panda_link0", *moving]
        points = np.reshape(f["arms"][i], (-1, 3))
        assert len(points) - 1 == arm.dof + 1 == len(data["arm_links"][i])
        T, _ = arm.tip_transform(x0[plant.q_slice(i)])  # the compiled kinematics
        np.testing.assert_allclose(points[-1], T[:3, 3], atol=1e-5)  # page rounding: 1e-5 m
        np.testing.assert_allclose(points[0], arm.base[:3, 3], atol=1e-5)
        # the last body's pose (12 numbers: position, rotation rows) times the tool is the node frame
        pose = np.reshape(f["bodies"][i], (-1, 12))[-1]
        last = np.eye(4)
        last[:3, 3], last[:3, :3] = pose[:3], pose[3:].reshape(3, 3)
        np.testing.assert_allclose((last @ arm.tool)[:3, :4], T[:3, :4], atol=3e-5)
        # every link of the shipped Panda has a shape; the hand and fingers ride on link 7
        bodies = {v["body"] for v in data["arm_visuals"][i]}
        assert bodies == set(range(8)), bodies
        hand = [v for v in data["arm_visuals"][i] if v["link"] in ("panda_hand", "panda_leftfinger")]
        assert hand and all(v["body"] == 7 for v in hand)
    assert data["bar_arms"] == [] and data["notes"] == []


def test_frames_fall_on_round_times(panda_still):
    _, data = panda_still
    times = [f["t"] for f in data["frames"]]
    # 2501 samples of 1 ms, at most 400 frames: every 10 ms (7 ms would do, but 1.0 s would be missed)
    assert len(times) == 251 and times[100] == 1.0 and times[-1] == 2.5
    from coopctrl.replay.scene_frames import frame_step

    assert frame_step(np.arange(2501) * 1e-3, 2501) == 10
    assert frame_step(np.arange(301) * 7e-3, 301) == 1  # few samples: all kept
    assert frame_step(np.cumsum(np.r_[0.0, np.full(999, 1e-3), 0.5e-3]), 1001) == 3  # uneven: the smallest


def test_user_urdf_visuals_boxes_spheres_and_meshes(tmp_path):
    """A user's URDF: primitives, an STL (binary) and an OBJ mesh at hand, one missing and one in
    a format that is not read: drawn or said why."""
    from coopctrl.replay.urdf_visuals import read_stl, urdf_arm_visuals

    meshes = tmp_path / "my_robot" / "meshes"
    meshes.mkdir(parents=True)
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0], [0, 1, 0], [0, 0, 1]], dtype="<f4").reshape(2, 3, 3)
    record = np.zeros(2, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    record["v"] = tri
    (meshes / "part.stl").write_bytes(b"\0" * 80 + np.uint32(2).tobytes() + record.tobytes())
    (meshes / "part.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n")
    urdf = tmp_path / "my_robot" / "urdf" / "arm.urdf"
    urdf.parent.mkdir()
    urdf.write_text("""<robot name="r">
      <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
      <link name="l1"><visual><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.05" length="0.2"/></geometry></visual>
        <visual><geometry><mesh filename="package://my_robot/meshes/part.stl" scale="2 2 2"/></geometry></visual></link>
      <link name="l2"><visual><geometry><sphere radius="0.04"/></geometry></visual>
        <visual><geometry><mesh filename="../meshes/part.obj"/></geometry></visual>
        <visual><geometry><mesh filename="../meshes/absent.stl"/></geometry></visual>
        <visual><geometry><mesh filename="../meshes/part.dae"/></geometry></visual></link>
      <link name="tip"><visual><origin xyz="0 0 0.05"/><geometry><box size="0.01 0.01 0.01"/></geometry></visual></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/>
        <limit lower="-1" upper="1" effort="10"/></joint>
      <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3"/>
        <limit lower="-1" upper="1" effort="10"/></joint>
      <joint name="jt" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.1 0 0"/></joint>
    </robot>""")
    shapes = urdf_arm_visuals(urdf, "base", "tip")
    assert shapes.links == ("base", "l1", "l2")
    kinds = [(v.link, v.body, v.shape) for v in shapes.visuals]
    assert sorted(kinds) == sorted([("base", 0, "box"), ("l1", 1, "cylinder"), ("l1", 1, "mesh"), ("l2", 2, "sphere"),
                                    ("l2", 2, "mesh"), ("tip", 2, "box")])
    stl = next(v for v in shapes.visuals if v.shape == "mesh" and v.link == "l1")
    assert len(stl.vertices) == 4 and stl.triangles.shape == (2, 3)  # shared corners merged, scale 2 applied
    assert stl.vertices.max() == 2.0
    obj = next(v for v in shapes.visuals if v.shape == "mesh" and v.link == "l2")
    # the quad fanned into two triangles (vertices are merged and sorted: compare the corners)
    assert obj.vertices[obj.triangles].tolist() == [[[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]]]
    tip = next(v for v in shapes.visuals if v.link == "tip")
    np.testing.assert_allclose(tip.transform[:3, 3], [0.1, 0.0, 0.05])  # fixed joint folded into body 2
    assert len(shapes.notes) == 2 and any("absent.stl" in n for n in shapes.notes) and any("part.dae" in n for n in shapes.notes)
    ascii_stl = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1e-1 0\nendloop\nendfacet\nendsolid"
    v, t = read_stl(ascii_stl)
    assert v.shape == (3, 3) and v[2, 1] == 0.1 and t.tolist() == [[0, 1, 2]]


def test_urdf_visuals_refuse_entities(tmp_path):
    """defusedxml: an entity declaration is refused (no billion laughs), the arm drawn without shapes."""
    from coopctrl.replay.urdf_visuals import urdf_arm_visuals

    bomb = tmp_path / "bomb.urdf"
    bomb.write_text('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;">]>'
                    '<robot name="&b;"><link name="base"/></robot>')
    shapes = urdf_arm_visuals(bomb, "base", "tip")
    assert shapes.links == () and shapes.visuals == () and "not read" in shapes.notes[0]


def test_user_urdf_scene_is_drawn_joint_by_joint(tmp_path):
    """A scene with ``model = "urdf"`` (the Puma written as a user's URDF file, no visuals): one
    segment per moving link plus the base."""
    from _replay_data import still_result
    from coopctrl.io import dumps_toml
    from test_urdf_scenario import _dh_as_urdf, _dh_rows, _scene_data

    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "my_arm.urdf").write_text(_dh_as_urdf(_dh_rows()))
    scene = tmp_path / "user.toml"
    scene.write_text(dumps_toml(_scene_data(model="urdf", urdf="robots/my_arm.urdf", base_link="base", tip_link="tip")))
    scenario = coopctrl.load_scenario(scene)
    data = replay_data(still_result(scenario, [0.0, 0.01]), scenario)
    assert data["arm_links"][0] == ["base", "l1", "l2", "l3", "l4", "l5", "l6"]
    assert len(np.reshape(data["frames"][0]["arms"][0], (-1, 3))) == 8  # base, 6 link frames, node
    assert data["arm_visuals"][0] == [] and data["arm_labels"][0] == "arms[0] urdf robots/my_arm.urdf (leader)"
    assert data["arm_links"][1] == []  # the Puma (DH) is drawn by its DH frames


def _page(tmp_path: Path, data: dict) -> Path:
    from coopctrl.replay import replay_html

    page = tmp_path / "replay.html"
    page.write_text(replay_html(data), encoding="utf-8")
    return page


@needs_chromium
def test_browser_urdf_arm_draws_a_segment_per_moving_link(panda_still, tmp_path):
    _, data = panda_still
    page = _page(tmp_path, data)
    dom = _chromium(page.as_uri() + "#t=1.0", "--dump-dom").stdout
    assert 'data-ready="1"' in dom, "the page's script did not finish"
    # per arm: the base link and the 7 moving links, and every visual shape of the data drawn
    assert 'data-arm-segments="8,8"' in dom
    shapes = ",".join(str(len(v)) for v in data["arm_visuals"])
    assert f'data-arm-shapes="{shapes}"' in dom and min(len(v) for v in data["arm_visuals"]) >= 8
    # "#t=1.0" opens on the frame at 1 s (frames every 10 ms) and says so exactly
    assert 'data-frame="100"' in dom and ">t = 1.000 s<" in dom
    image = _screenshot(page, 100, tmp_path / "panda.png")
    blue, orange = _coloured(image)
    assert blue > 500 and orange > 500, (blue, orange)  # both Pandas' links in their role colours


@needs_chromium
def test_browser_time_in_the_url_opens_the_nearest_frame(tmp_path):
    from _replay_data import still_result

    scenario = coopctrl.load_scenario(REPO / "scenarios" / "planar_two_arm_lift.toml")
    # frames every 7 ms: 0.994 s and 1.001 s are the neighbours of 1.0 s, the second the nearer
    data = replay_data(still_result(scenario, np.arange(301) * 7e-3), scenario)
    assert [f["t"] for f in data["frames"][142:144]] == [0.994, 1.001]
    dom = _chromium(_page(tmp_path, data).as_uri() + "#t=1.0", "--dump-dom").stdout
    assert 'data-frame="143"' in dom and ">t = 1.001 s (nearest frame to 1 s)<" in dom


@needs_chromium
def test_browser_hostile_strings_stay_text(panda_still, tmp_path):
    """A name that closes the script, opens a comment and names the page's markers: the page
    still runs (html.parser cannot model the browsers' script-escape states; chromium does) and
    shows the name as text. An STL-like mesh visual is drawn with the other shapes."""
    import copy

    _, data = panda_still
    data = copy.deepcopy(data)
    name = "</script><!--<script>__DATA__ __THREE__ \u2028</title><b>"
    data["scenario"] = name
    data["arm_labels"][0] = "<img src=x onerror=document.body.setAttribute('data-pwned','1')>"
    tetra = {"body": 7, "link": "extra", "shape": "mesh", "size": [], "dark": False,
             "pose": [0, 0, 0.1, 1, 0, 0, 0, 1, 0, 0, 0, 1],
             "vertices": [0, 0, 0, 0.05, 0, 0, 0, 0.05, 0, 0, 0, 0.05], "triangles": [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]}
    data["arm_visuals"][0].append(tetra)
    dom = _chromium(_page(tmp_path, data).as_uri() + "#frame=0", "--dump-dom").stdout
    assert 'data-ready="1"' in dom and 'data-pwned="1"' not in dom  # the label is text, not an element
    assert "&lt;/script&gt;&lt;!--&lt;script&gt;__DATA__ __THREE__" in dom  # the title div, as text
    assert f'data-arm-shapes="{len(data["arm_visuals"][0])},{len(data["arm_visuals"][1])}"' in dom
