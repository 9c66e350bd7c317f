"""``replay.html``: one self-contained page (three.js inlined, no network) that replays a run.

The page is ``page.html`` with three.js (``vendor/three.min.js``, r160, MIT) and the frames of
:func:`coopctrl.replay.scene_frames.replay_data` inlined. It plays, pauses, steps with a time
slider and changes speed; ``replay.html#frame=N`` (or ``#t=SECONDS``) opens paused on a frame.
"""

from __future__ import annotations

import html
import json
from importlib import resources
from pathlib import Path

from coopctrl.io.atomic import atomic_write


def _asset(name: str) -> str:
    return resources.files("coopctrl.replay").joinpath(name).read_text(encoding="utf-8")


def replay_html(data: dict) -> str:
    """The page for the frames ``data`` (a dict of :func:`~coopctrl.replay.scene_frames.replay_data`)."""
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    three = _asset("vendor/three.min.js").replace("</script", "<\\/script")
    page = _asset("page.html")
    title = html.escape(f"{data['scenario']} replay ({data['status']})")
    # __DATA__ last: the three.js source must not be searched for the other markers
    return page.replace("__TITLE__", title).replace("__DATA__", payload, 1).replace("__THREE__", three, 1)


def write_replay(result, scenario, directory: str | Path) -> Path:
    """Write ``replay.html`` into ``directory`` atomically and return its path. With it,
    ``scenario.toml`` (the resolved scenario, :func:`coopctrl.scenario.to_toml.scenario_toml`)
    so that ``coopctrl view DIR`` can rebuild the page later."""
    from coopctrl.replay.scene_frames import replay_data
    from coopctrl.scenario.to_toml import scenario_toml

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    text = replay_html(replay_data(result, scenario))
    path = directory / "replay.html"
    with atomic_write(path, "w", encoding="utf-8") as f:
        f.write(text)
    with atomic_write(directory / "scenario.toml", "w", encoding="utf-8") as f:
        f.write(scenario_toml(scenario))
    return path
