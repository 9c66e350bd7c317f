"""A stand-in for :func:`coopctrl.results.plots.plot_result` (tested in tests/test_plots.py) for the tests of
output folders: one tiny PNG, so that a folder holds what a run writes without 1-2 s of matplotlib per figure."""

from __future__ import annotations

from pathlib import Path

import pytest


def stub_plots(result, directory):
    path = Path(directory) / "object_pose.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n")
    return [path]


@pytest.fixture(autouse=True)
def quick_plots(monkeypatch):
    import coopctrl.results.plots as plots

    monkeypatch.setattr(plots, "plot_result", stub_plots)
