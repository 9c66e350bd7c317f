"""The plots answer the engineer's questions (issue 14): figures returned, titled with scenario and
status, forces and moments apart, saturation and QP binding shown, a failed run marked."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle

from coopctrl.results.plain_axes import plain_tick_labels
from coopctrl.results.plots import (SATURATED, failure_time, plot_force_regulation, plot_limits, plot_qp_solve_times,
                                    plot_tracking)
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
            if ax.get_ylabel() == "solves [-]":
                continue  # a histogram of the QP plot has no time axis
            marks = [ln for ln in ax.lines if len(ln.get_xdata()) == 2 and np.allclose(ln.get_xdata(), 0.18)]
            assert marks, f"no failure marker on {ax.get_title()!r}"
    assert failure_time(synthetic("planar", 2)) is None


def _offset_texts(fig: Figure) -> list[str]:
    """The offset texts (``+2e1``, ``1e-7``) of every axis of ``fig``, once drawn."""
    fig.canvas.draw()
    return [axis.get_offset_text().get_text() for ax in fig.get_axes() for axis in (ax.xaxis, ax.yaxis)
            if axis.get_offset_text().get_text()]


def test_no_axis_has_an_offset_text():
    """A run from t = 1000 s whose pose varies by 1e-7 m around 0.45 m: matplotlib's default would label
    the time axis ``+1e3`` and the pose axis ``1e-7+4.5e-1``; every plot labels ticks with the values."""
    r = synthetic("planar", 2)
    r.t = r.t + 1000.0
    r.Y0[:, 0] = 0.45 + 1e-7 * np.sin(np.linspace(0.0, 3.0, r.t.size))
    r.Y0_nominal[:, 0] = 0.45
    from matplotlib.figure import Figure as _F
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    raw = _F()  # the same data without plain_tick_labels has offsets: the check below can fail
    FigureCanvasAgg(raw)
    ax = raw.subplots()
    ax.plot(r.t, r.Y0[:, 0])
    assert len(_offset_texts(raw)) == 2
    plain_tick_labels(raw)
    assert _offset_texts(raw) == []
    for name, fig in r.figures().items():
        assert _offset_texts(fig) == [], name


def test_qp_plot_has_data_for_the_default_solver():
    """The default (compiled) solver is not timed per solve, but reports its iterations and the active
    inequality rows of its answer on every tick: the QP plot draws both (heavy_payload_torque_limits
    activates a torque-limit row from about 0.11 s) and names the missing solve time."""
    import coopctrl
    from pathlib import Path

    scene = coopctrl.load_scenario(Path(__file__).resolve().parent.parent / "scenarios" / "heavy_payload_torque_limits.toml",
                                   {"simulation.duration": 0.2})
    assert scene.load_distribution.solver == "compiled"
    r = coopctrl.simulate(scene)
    assert r.status == "ok"
    n = r.t.size
    assert r.qp_active_rows.shape == (n,) and np.all(r.qp_active_rows >= 0) and np.all(r.qp_iterations >= 0)
    binding = np.array(["torque_limits" in b for b in r.qp_binding])
    assert binding.any() and np.all(r.qp_active_rows[binding] >= 1)  # a binding row is an active row
    fig = plot_qp_solve_times(r)
    by_label = {ax.get_ylabel(): ax for ax in fig.get_axes()}
    for label in ("QP iterations [-]", "active inequality rows [-]"):
        y = np.asarray(by_label[label].lines[0].get_ydata(), dtype=float)
        assert y.shape == (n,) and np.isfinite(y).all(), label
    assert "solve time [us]" not in by_label  # not timed: no empty panel
    assert "solve time" in fig.get_supxlabel()


def _tick_labels(fig: Figure) -> list[str]:
    fig.canvas.draw()
    return [t.get_text() for ax in fig.get_axes() for t in ax.get_yticklabels() if t.get_text()]


def test_small_values_read_in_scientific_notation_and_errors_in_a_unit_that_fits():
    """An angle that moves by 2e-8 rad is labelled ``2e-08``, not ``0.00000002``, and its error axis is in
    nrad; a millimetre error stays in mm."""
    from coopctrl.results.plots import error_scale

    r = synthetic("spatial", 2)
    r.Y0_nominal[:, 5] = 0.0
    r.Y0[:, 5] = 3e-8 * np.sin(np.linspace(0.0, 6.0, r.t.size))
    fig = plot_tracking(r)
    labels = _tick_labels(fig)
    assert not [t for t in labels if t.startswith(("0.0000", "-0.0000"))], labels
    assert any("e-08" in t for t in labels)
    assert "e_phi [nrad]" in [ax.get_ylabel() for ax in fig.get_axes()]
    assert error_scale(np.array([2e-3, -1e-4]), "m") == (1e3, "mm")
    assert error_scale(np.array([5e-6, np.nan]), "m") == (1e6, "\u00b5m")
    assert error_scale(np.zeros(4), "rad") == (1e3, "mrad")
    assert _offset_texts(fig) == []


def test_qp_plot_says_what_did_not_vary_instead_of_drawing_it():
    """The compiled solver on a carry without inequality rows: 0 iterations and 0 active rows at every solve,
    no solve time. No flat line and no one-bar histogram: one text that says so."""
    r = synthetic("spatial", 2)
    r.qp_status = ["solved"] * r.t.size
    r.qp_iterations = np.zeros(r.t.size, dtype=np.int64)
    r.qp_active_rows = np.zeros(r.t.size, dtype=np.int64)
    r.qp_solve_time_s = np.full(r.t.size, np.nan)
    fig = plot_qp_solve_times(r)
    assert not [ax for ax in fig.get_axes() if ax.lines or ax.patches]
    text = " ".join(t.get_text() for ax in fig.get_axes() for t in ax.texts)
    assert "iterations: 0 at every solve" in text and "active rows: 0 at every solve" in text
    assert "not timed per solve" in text
    # one quantity varies: it gets its panels (integer histogram bins), the constant one a note
    r.qp_iterations[::7] = 2
    fig = plot_qp_solve_times(r)
    labels = {ax.get_ylabel() for ax in fig.get_axes()}
    assert "QP iterations [-]" in labels and "active inequality rows [-]" not in labels
    assert "active rows: 0 at every solve" in fig.get_supxlabel()
