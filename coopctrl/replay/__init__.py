"""The 3-D replay of a run in the browser: ``replay.html`` (``coopctrl run --out``, ``coopctrl view``)."""

from coopctrl.replay.page import replay_html, write_replay
from coopctrl.replay.scene_frames import replay_data

__all__ = ["replay_data", "replay_html", "write_replay"]
