"""The plots answer the engineer's questions (issue 14): figures returned, titled with scenario and
status, forces and moments apart, saturation and QP binding shown, a failed run marked."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle

from coopctrl.results.plots import (SATURATED, failure_time, plot_force_regulation, plot_limits, plot_tracking)
from test_results import synthetic


def _titles(fig: Figure) -> str:
    return fig.get_suptitle()


@pytest.mark.parametrize("space", ["planar", "spatial"])
def test_figures_are_returned_titled_and_written_only_on_request(tmp_path, space):
    r = synthetic(space, 2)
    figs = r.figures()
    assert set(figs) == {"object_pose.png", "contact_forces.png", "joint_torques.png", "qp_solve_times.png"}
    for fig in figs.values():
        assert isinstance(fig, Figure)
        assert "synthetic" in _titles(fig) and "status: ok" in _titles(fig)
    assert list(tmp_path.iterdir()) == []  # nothing written without a path
    plot_tracking(r, tmp_path / "t.png")
    assert (tmp_path / "t.png").read_bytes()[:4] == b"\x89PNG"


def test_tracking_has_no_empty_panel_and_errors_per_coordinate():
    r = synthetic("spatial", 2)
    fig = plot_tracking(r)
    axes = fig.get_axes()
    assert len(axes) == 12 and all(ax.get_visible() and ax.lines for ax in axes)
    labels = [ax.get_ylabel() for ax in axes]
    assert "e_x [mm]" in labels and "e_psi [mrad]" in labels and "z [m]" in labels


def test_forces_and_moments_on_separate_axes_with_frame_and_squeeze():
    r = synthetic("spatial", 3)
    fig = plot_force_regulation(r)
    labels = [ax.get_ylabel() for ax in fig.get_axes()]
    assert sum("force [N]" in y for y in labels) == 3 and sum("moment [N m]" in y for y in labels) == 3
    assert not any("[N], [N m]" in y for y in labels)
    assert "world frame" in _titles(fig)
    squeeze_ax = next(ax for ax in fig.get_axes() if ax.get_ylabel() == "squeeze [N]")
    # 3 pairs measured + 3 setpoint lines (+ the legend's proxy line)
    assert len(squeeze_ax.lines) == 7
    # no legend inside a panel covers the curves: every legend is anchored outside, right of its axes
    for ax in fig.get_axes():
        legend = ax.get_legend()
        if legend is not None:
            assert legend.get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1


def test_limits_shade_saturated_stretches_and_show_qp_binding():
    r = synthetic("planar", 2)
    r.tau[50:60, 1] = r.tau_max[1]  # a stretch at the limit (the loop clips exactly there)
    r.tau[120:125, 4] = -r.tau_max[4]
    r.qp_binding = [""] * r.t.size
    for k in range(30, 80):
        r.qp_binding[k] = "torque_limits"
    r.qp_binding[90] = "friction+min_grip"
    fig = plot_limits(r)
    axes = fig.get_axes()
    shaded = [[p for p in ax.patches if isinstance(p, (Polygon, Rectangle)) and p.get_label() != "_nolegend_"]
              for ax in axes[:2]]
    assert len(shaded[0]) >= 1 and len(shaded[1]) >= 1  # one saturated stretch on each arm
    assert all(ax.get_ylabel().endswith("|tau| / tau_max [-]") for ax in axes[:2])
    assert all(ax.get_ylim()[1] >= 1.1 - 1e-12 for ax in axes[:2])  # the limit line (1) is in view
    bind = axes[2]
    ticks = [t.get_text() for t in bind.get_yticklabels()]
    assert ticks == ["failed / held solve", "friction", "min_grip", "torque_limits"]  # synthetic: one failed solve


def test_saturation_threshold_is_at_the_limit():
    assert 0.999999 < SATURATED < 1.0


def test_failed_run_is_marked_on_every_panel():
    r = synthetic("planar", 2, status="diverged")
    r.events.append((0.18, "diverged", "deformation"))
    assert failure_time(r) == pytest.approx(0.18)
    for fig in r.figures().values():
        assert "DIVERGED" in _titles(fig)
        for ax in fig.get_axes():
            if ax.get_xlabel() == "solve time [us]":
                continue  # the histogram has no time axis
            marks = [ln for ln in ax.lines if len(ln.get_xdata()) == 2 and np.allclose(ln.get_xdata(), 0.18)]
            assert marks, f"no failure marker on {ax.get_title()!r}"
    assert failure_time(synthetic("planar", 2)) is None
