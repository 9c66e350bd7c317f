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
