"""PNG plots of a :class:`~coopctrl.results.SimulationResult` (matplotlib's Agg canvas, no pyplot)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from coopctrl.io.atomic import atomic_write
from coopctrl.results.storage import pose_names, wrench_names
from coopctrl.results.summary import orientation_error, position_error, qp_failed

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult


def _figure(rows: int, cols: int, height: float = 2.2, width: float = 6.0):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * cols, max(3.0, height * rows)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False, sharex=True)
    return fig, axes


def _save(fig, path: Path) -> Path:
    with atomic_write(path, "wb") as f:
        fig.savefig(f, format="png", dpi=100)
    return path


def _pose_unit(name: str) -> str:
    return "[m]" if name in ("x", "y", "z") else "[rad]"


def _wrench_unit(name: str) -> str:
    return "[N]" if name.startswith("f") else "[N m]"


def plot_object_pose(r: "SimulationResult", path: Path) -> Path:
    """Object pose vs nominal (left) and the position / orientation errors (right)."""
    names = pose_names(r.pose_size)
    fig, axes = _figure(len(names), 2)
    for k, name in enumerate(names):
        ax = axes[k, 0]
        ax.plot(r.t, r.Y0[:, k], label="actual")
        ax.plot(r.t, r.Y0_nominal[:, k], "--", label="nominal")
        ax.set_ylabel(f"{name} {_pose_unit(name)}")
    axes[0, 0].legend(loc="best")
    axes[0, 0].set_title("object pose")
    axes[-1, 0].set_xlabel("t [s]")
    axes[0, 1].plot(r.t, position_error(r.Y0, r.Y0_nominal) * 1e3)
    axes[0, 1].set_ylabel("position error [mm]")
    axes[0, 1].set_title("tracking error")
    axes[1, 1].plot(r.t, orientation_error(r.Y0, r.Y0_nominal) * 1e3)
    axes[1, 1].set_ylabel("orientation error [mrad]")
    for ax in axes[2:, 1]:
        ax.set_visible(False)
    axes[1, 1].set_xlabel("t [s]")
    axes[1, 1].xaxis.set_tick_params(labelbottom=True)
    return _save(fig, path)


def plot_contact_forces(r: "SimulationResult", path: Path) -> Path:
    """Per contact: commanded vs measured wrench (left); QP split into external and internal (right)."""
    names = wrench_names(r.pose_size)
    fig, axes = _figure(r.arms, 2, height=3.0)
    for k in range(r.arms):
        role = "leader" if k == r.leader else "follower"
        left, right = axes[k, 0], axes[k, 1]
        for c, name in enumerate(names):
            line, = left.plot(r.t, r.F_measured[:, k, c], label=f"{name} measured")
            left.plot(r.t, r.F_commanded[:, k, c], "--", color=line.get_color(), label=f"{name} commanded")
            line, = right.plot(r.t, r.F_external[:, k, c], label=f"{name} external")
            right.plot(r.t, r.F_internal[:, k, c], ":", color=line.get_color(), label=f"{name} internal")
        left.set_ylabel(f"contact {k + 1} ({role})\n[N], [N m]")
        left.set_title(f"contact {k + 1}: measured (solid) vs commanded (dashed)")
        right.set_title(f"contact {k + 1}: QP split, external (solid) / internal (dotted)")
    axes[0, 0].legend(loc="best", fontsize="x-small", ncol=2)
    axes[0, 1].legend(loc="best", fontsize="x-small", ncol=2)
    axes[-1, 0].set_xlabel("t [s]")
    axes[-1, 1].set_xlabel("t [s]")
    return _save(fig, path)


def plot_joint_torques(r: "SimulationResult", path: Path) -> Path:
    """Joint torques per arm, with their limits as dashed lines."""
    dofs = list(r.model.get("dof_per_arm", [])) if r.model else []
    if not dofs or sum(dofs) != r.tau.shape[1]:
        dofs = [r.tau.shape[1]]
    fig, axes = _figure(len(dofs), 1, height=2.8)
    start = 0
    for a, n in enumerate(dofs):
        ax = axes[a, 0]
        for j in range(start, start + n):
            line, = ax.plot(r.t, r.tau[:, j], label=f"joint {j - start + 1}")
            if r.tau_max is not None and np.isfinite(r.tau_max[j]):
                for sign in (1.0, -1.0):
                    ax.axhline(sign * r.tau_max[j], linestyle="--", linewidth=0.8, color=line.get_color())
        ax.set_ylabel("torque [N m]")
        ax.set_title(f"arm {a + 1}" if len(dofs) > 1 else "joint torques")
        ax.legend(loc="best", fontsize="x-small", ncol=3)
        start += n
    axes[-1, 0].set_xlabel("t [s]")
    return _save(fig, path)


def plot_qp_solve_times(r: "SimulationResult", path: Path) -> Path:
    """QP solve time per control period (failed solves marked) and its histogram."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 3.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax_t, ax_h = fig.subplots(1, 2)
    times_us = r.qp_solve_time_s * 1e6
    n = min(times_us.shape[0], r.t.shape[0])
    ax_t.plot(r.t[:n], times_us[:n], linewidth=0.8)
    failed = [k for k, s in enumerate(r.qp_status[:n]) if qp_failed(s)]
    if failed:
        ax_t.plot(r.t[failed], times_us[failed], "rx", label="failed")
        ax_t.legend(loc="best")
    ax_t.set_xlabel("t [s]")
    ax_t.set_ylabel("solve time [us]")
    ax_t.set_title("load-distribution QP")
    finite = times_us[np.isfinite(times_us)]
    if finite.size:
        ax_h.hist(finite, bins=50)
    ax_h.set_xlabel("solve time [us]")
    ax_h.set_ylabel("count [-]")
    return _save(fig, path)


def plot_result(result: "SimulationResult", directory: str | Path) -> list[Path]:
    """Write ``object_pose.png``, ``contact_forces.png``, ``joint_torques.png`` and
    ``qp_solve_times.png`` into ``directory`` (created if needed)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    return [
        plot_object_pose(result, directory / "object_pose.png"),
        plot_contact_forces(result, directory / "contact_forces.png"),
        plot_joint_torques(result, directory / "joint_torques.png"),
        plot_qp_solve_times(result, directory / "qp_solve_times.png"),
    ]
