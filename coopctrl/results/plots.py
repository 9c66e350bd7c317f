"""Plots of a :class:`~coopctrl.results.SimulationResult` that answer the engineer's questions.

Each function returns a matplotlib :class:`~matplotlib.figure.Figure` (Agg canvas, no pyplot, no
window) titled with the scenario and the status, and writes it as a PNG only when given a
``path``. A failed run gets a red vertical line where it stopped on every panel.

- :func:`plot_tracking`: did the object track? Pose against nominal, and the error per coordinate.
- :func:`plot_force_regulation`: were the forces regulated? Measured against commanded per
  contact, forces [N] and moments [N m] on separate axes (world frame, on the object, at the
  contact node), the squeeze of each pair against its setpoint and the force error per contact.
- :func:`plot_limits`: where did the limits bind? Torque as a fraction of its limit per arm,
  saturated stretches shaded, and the QP's binding constraint families over time.
- :func:`plot_qp_solve_times`: what did the QP cost? Its iterations and active rows per period
  (the compiled solver reports both) and its solve time (timed on the reference path), with histograms.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from coopctrl.io.atomic import atomic_write
from coopctrl.results.plain_axes import plain_tick_labels
from coopctrl.results.signals import dof_per_arm, pair_labels, pose_names, pose_unit, wrench_names
from coopctrl.results.summary import qp_failed

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: Where the contact wrenches are expressed (stated on the force plot).
WRENCH_FRAME = "world frame, wrench on the object at the contact node"
#: |tau| / tau_max at or above this counts as saturated (the loop clips torques exactly at the limit).
SATURATED = 1.0 - 1e-9
#: Failure kinds of ``result.events`` whose time marks where a run stopped.
FAILURE_EVENTS = ("diverged", "qp_failed", "euler_singularity")


def _figure(rows: int, cols: int, height: float = 2.2, width: float = 6.0, sharex: bool = True):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * cols, max(3.0, height * rows)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False, sharex=sharex)
    return fig, axes


#: An axis whose every value is below this in magnitude labels its ticks in scientific notation (``2e-08``):
#: written plainly they read ``0.00000002``.
SMALL_AXIS = 1e-3


def _small_axes_scientific(fig) -> None:
    """Label the ticks of an axis whose values are all small (< :data:`SMALL_AXIS`) in scientific notation,
    each label on its own (``2e-08``), so no offset text is needed (:func:`plain_tick_labels`)."""
    from matplotlib.ticker import FuncFormatter, ScalarFormatter

    for ax in fig.get_axes():
        if not ax.get_visible():
            continue
        for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            if axis.get_scale() != "linear" or not isinstance(axis.get_major_formatter(), ScalarFormatter):
                continue
            if 0.0 < max(abs(limits[0]), abs(limits[1])) < SMALL_AXIS:
                axis.set_major_formatter(FuncFormatter(lambda v, _: "0" if v == 0 else f"{v:.3g}"))


#: SI prefixes for an error axis: (factor, prefix), from milli down to pico.
_PREFIXES = ((1e3, "m"), (1e6, "\u00b5"), (1e9, "n"), (1e12, "p"))


def error_scale(values: np.ndarray, unit: str) -> tuple[float, str]:
    """``(factor, unit)`` for plotting an error series of ``unit`` (``m`` or ``rad``): the largest prefix
    (milli to pico) under which the largest finite magnitude is at least 1, e.g. a 2e-8 rad error in
    ``nrad`` (20) rather than ``mrad`` (0.00002). Milli for a series of zeros or no finite value."""
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite)]
    peak = float(finite.max()) if finite.size else 0.0
    for factor, prefix in _PREFIXES:
        if peak == 0.0 or peak * factor >= 1.0:
            return factor, prefix + unit
    return _PREFIXES[-1][0], _PREFIXES[-1][1] + unit


def _save(fig, path: str | Path | None):
    plain_tick_labels(fig)  # every tick label is the value itself: no "+2e1" offset on an axis
    _small_axes_scientific(fig)
    if path is not None:
        with atomic_write(Path(path), "wb") as f:
            fig.savefig(f, format="png", dpi=100)
    return fig


def failure_time(r: "SimulationResult") -> float | None:
    """Time [s] where a failed run stopped (its failure event, else its last finite sample), or
    ``None`` for an ok run."""
    if r.status == "ok":
        return None
    times = [t for t, kind, _ in r.events if kind in FAILURE_EVENTS]
    if times:
        return float(times[-1])
    finite = np.nonzero(np.isfinite(r.Y0).all(axis=1))[0]
    return float(r.t[finite[-1]]) if finite.size else (float(r.t[0]) if r.t.size else 0.0)


def _title(fig, r: "SimulationResult", question: str) -> None:
    status = r.status if r.status == "ok" else f"{r.status.upper()}"
    scene = r.scenario
    if (r.integrator or "").startswith("mujoco plant"):  # another plant than the elastic one: named (coopctrl.mujoco)
        scene += " on the mujoco plant"
    line = f"{scene}  |  status: {status}  |  {question}"
    if r.status != "ok" and r.reason:
        reason = " ".join(r.reason.split())
        line += "\n" + (reason if len(reason) < 140 else reason[:137] + "...")
    fig.suptitle(line, color="black" if r.status == "ok" else "#b00000", fontsize="medium")


def _mark_failure(axes, r: "SimulationResult") -> None:
    t = failure_time(r)
    if t is None:
        return
    for k, ax in enumerate(np.ravel(axes)):
        if not ax.get_visible():
            continue
        ax.axvline(t, color="#d00000", linewidth=1.5, linestyle="-", zorder=5,
                   label=f"{r.status} at t = {t:.4g} s" if k == 0 else None)
        if k == 0:
            ax.annotate(f"{r.status} at t = {t:.4g} s", xy=(t, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(-4, -4), textcoords="offset points", ha="right", va="top", color="#d00000",
                        fontsize="small")


def _legend_outside(ax, **kwargs) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", borderaxespad=0.0, **kwargs)


# ---------------------------------------------------------------------- tracking
def plot_tracking(r: "SimulationResult", path: str | Path | None = None):
    """Did the object track? Left: each pose coordinate against its nominal. Right: its error
    (actual - nominal) in the unit that makes its largest value at least 1 (``mm`` down to ``pm``,
    ``mrad`` down to ``prad``: :func:`error_scale`)."""
    names = pose_names(r.pose_size)
    fig, axes = _figure(len(names), 2, height=1.9)
    for k, name in enumerate(names):
        unit = pose_unit(name)
        ax = axes[k, 0]
        ax.plot(r.t, r.Y0[:, k], label="actual", color="C0")
        ax.plot(r.t, r.Y0_nominal[:, k], "--", label="nominal", color="k", linewidth=1.0)
        ax.set_ylabel(f"{name} [{unit}]")
        err = r.Y0[:, k] - r.Y0_nominal[:, k]
        if unit == "rad":
            err = (err + np.pi) % (2 * np.pi) - np.pi
        factor, err_unit = error_scale(err, unit)
        axes[k, 1].plot(r.t, err * factor, color="C3")
        axes[k, 1].axhline(0.0, color="0.6", linewidth=0.8)
        axes[k, 1].set_ylabel(f"e_{name} [{err_unit}]")
    _legend_outside(axes[0, 0])
    axes[0, 0].set_title("object pose against its nominal trajectory")
    axes[0, 1].set_title("tracking error (actual - nominal)")
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    _title(fig, r, "did the object track?")
    _mark_failure(axes, r)
    return _save(fig, path)


# ---------------------------------------------------------------------- forces
def plot_force_regulation(r: "SimulationResult", path: str | Path | None = None):
    """Were the forces regulated? One row per contact: forces [N] (left) and moments [N m]
    (right), measured (solid) against commanded (dashed). Last row: the squeeze of each pair
    against its setpoint, and the force error |f_measured - f_commanded| per contact."""
    names = wrench_names(r.pose_size)
    nf = 2 if r.pose_size == 3 else 3
    m = r.arms
    fig, axes = _figure(m + 1, 2, height=2.3)
    for k in range(m):
        role = "leader" if k == r.leader else "follower"
        for col, comps in ((0, range(nf)), (1, range(nf, r.pose_size))):
            ax = axes[k, col]
            for c in comps:
                color = f"C{c % nf}"
                ax.plot(r.t, r.F_measured[:, k, c], color=color, label=names[c])
                ax.plot(r.t, r.F_commanded[:, k, c], "--", color=color, linewidth=1.0)
            ax.set_ylabel(f"arm {k + 1} ({role})\n{'force [N]' if col == 0 else 'moment [N m]'}")
            if k == 0:
                ax.plot([], [], "k-", label="measured")
                ax.plot([], [], "k--", linewidth=1.0, label="commanded")
                _legend_outside(ax)
    axes[0, 0].set_title("contact forces")
    axes[0, 1].set_title("contact moments")
    ax = axes[m, 0]
    pairs = pair_labels(m) if r.squeeze.shape[1] == m * (m - 1) // 2 else [str(i + 1) for i in range(r.squeeze.shape[1])]
    for i, label in enumerate(pairs):
        line, = ax.plot(r.t, r.squeeze[:, i], label=f"pair {label.replace('_', '-')}")
        ax.axhline(r.squeeze_desired[i], color=line.get_color(), linestyle="--", linewidth=1.0)
    ax.plot([], [], "k--", linewidth=1.0, label="setpoint")
    ax.set_ylabel("squeeze [N]")
    ax.set_title("internal squeeze against its setpoint")
    _legend_outside(ax)
    ax = axes[m, 1]
    for k in range(m):
        err = np.linalg.norm(r.F_measured[:, k, :nf] - r.F_commanded[:, k, :nf], axis=1)
        ax.plot(r.t, err, label=f"arm {k + 1}")
    ax.set_ylabel("|f_meas - f_cmd| [N]")
    ax.set_title("force error per contact")
    _legend_outside(ax)
    for a in axes[-1]:
        a.set_xlabel("t [s]")
    _title(fig, r, f"were the forces regulated? ({WRENCH_FRAME})")
    _mark_failure(axes, r)
    return _save(fig, path)


# ---------------------------------------------------------------------- limits
def _stretches(mask: np.ndarray, t: np.ndarray) -> list[tuple[float, float]]:
    """(start, width) [s] of the runs of True in ``mask`` (each sample covers one period)."""
    if not mask.any():
        return []
    dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    return [(float(t[s]), float(t[e - 1] - t[s] + dt)) for s, e in zip(starts, ends)]


def plot_limits(r: "SimulationResult", path: str | Path | None = None):
    """Where did the limits bind? Per arm, each joint's |tau| / tau_max (1 = the limit),
    saturated stretches shaded red (torque in [N m] for an arm without limits). Last panel: the
    constraint families the QP reported binding, and its failed or held solves, over time."""
    dofs = dof_per_arm(r)
    fig, axes = _figure(len(dofs) + 1, 1, height=2.3, width=10.0)
    start = 0
    tau_max = r.tau_max if r.tau_max is not None else np.full(r.tau.shape[1], np.inf)
    for a, n in enumerate(dofs):
        ax = axes[a, 0]
        cols = range(start, start + n)
        limited = np.isfinite(tau_max[start:start + n]).any()
        shaded = False
        for j in cols:
            style = "-" if (j - start) < 3 else "--"
            if limited and np.isfinite(tau_max[j]):
                ratio = np.abs(r.tau[:, j]) / tau_max[j]
                ax.plot(r.t, ratio, style, color=f"C{j - start}", label=f"joint {j - start + 1}")
                for s, w in _stretches(ratio >= SATURATED, r.t):
                    ax.axvspan(s, s + w, color="#d00000", alpha=0.25, linewidth=0,
                               label=None if shaded else "saturated")
                    shaded = True
            else:
                ax.plot(r.t, r.tau[:, j], style, color=f"C{j - start}", label=f"joint {j - start + 1}")
        if limited:
            ax.axhline(1.0, color="#d00000", linewidth=1.0, label="limit")
            ax.set_ylim(0.0, max(1.1, float(np.nanmax(np.abs(r.tau[:, cols]) / tau_max[start:start + n], initial=0.0)) * 1.05))
            ax.set_ylabel(f"arm {a + 1}\n|tau| / tau_max [-]")
        else:
            ax.set_ylabel(f"arm {a + 1}\ntau [N m] (no limit)")
        role = "leader" if a == r.leader else "follower"
        ax.set_title(f"arm {a + 1} ({role}): joint torque" + (" as a fraction of its limit" if limited else ""))
        _legend_outside(ax)
        start += n
    ax = axes[-1, 0]
    n_solves = min(len(r.qp_status), r.t.size)
    rows: dict[str, np.ndarray] = {}
    for k, fams in enumerate(r.qp_binding[:n_solves]):
        for fam in filter(None, fams.split("+")):
            rows.setdefault(fam, np.zeros(r.t.size, bool))[k] = True
    failed = np.zeros(r.t.size, bool)
    failed[:n_solves] = [qp_failed(s) for s in r.qp_status[:n_solves]]
    if failed.any():
        rows["failed / held solve"] = failed
    for i, (fam, mask) in enumerate(sorted(rows.items())):
        color = "#d00000" if fam.startswith("failed") else f"C{i}"
        ax.broken_barh(_stretches(mask, r.t), (i - 0.35, 0.7), color=color)
    if rows:
        ax.set_yticks(range(len(rows)), sorted(rows))
        ax.set_ylim(-0.7, len(rows) - 0.3)
    else:
        ax.set_yticks([])
        ax.text(0.5, 0.5, f"no constraint family bound and no solve failed ({n_solves} QP solves)",
                transform=ax.transAxes, ha="center", va="center")
    ax.set_title("load-distribution QP: binding constraint families")
    ax.set_xlabel("t [s]")
    if r.t.size:
        ax.set_xlim(float(r.t[0]), float(r.t[-1]))
    _title(fig, r, "where did the limits bind?")
    _mark_failure(axes, r)
    return _save(fig, path)


# ---------------------------------------------------------------------- QP effort
def _per_tick(values, n: int) -> np.ndarray:
    """The first ``n`` entries of a per-solve series as floats, NaN where unknown (``None``, -1 or NaN)."""
    if values is None:
        return np.full(n, np.nan)
    v = np.asarray(values, dtype=float)[:n]
    v = np.where(v < 0, np.nan, v)
    return np.concatenate([v, np.full(n - v.shape[0], np.nan)])


def plot_qp_solve_times(r: "SimulationResult", path: str | Path | None = None):
    """What did the load-distribution QP cost? One row per quantity the run's solver reports: its
    iterations per control period (active-set changes of the compiled solver, 0 when the last
    active set was still optimal), the inequality rows active at its answer (the compiled solver)
    and the solve time [us] (timed per solve for a backend outside the compiled loop, e.g.
    ``load_distribution.solver = "proxsuite"``); left over time (failed or held solves marked),
    right as a histogram. A quantity the solver does not report, or that is the same at every solve
    (no iteration because the warm-started active set stayed optimal, no active row), is said in a note
    below the panels, never drawn as a flat line; when nothing varies the note is the figure."""
    n = min(r.t.shape[0], len(r.qp_status)) if r.qp_status else 0
    t = r.t[:n]
    candidates = [
        ("iterations", "QP iterations [-]", _per_tick(r.qp_iterations, n), True),
        ("active rows", "active inequality rows [-]", _per_tick(getattr(r, "qp_active_rows", None), n), True),
        ("solve time", "solve time [us]", _per_tick(r.qp_solve_time_s, n) * 1e6, False),
    ]
    reported = [c for c in candidates if np.isfinite(c[2]).any()]
    missing = [c[0] for c in candidates if c not in reported]
    constant = [c for c in reported if np.nanmin(c[2]) == np.nanmax(c[2])]
    series = [c for c in reported if c not in constant]
    notes = [f"{name}: {np.nanmin(values):.4g} at every solve" for name, _, values, _ in constant]
    if missing:
        notes.append(f"not reported by this run's solver: {', '.join(missing)}"
                     + (" (the compiled solver is not timed per solve; load_distribution.solver = \"proxsuite\" is)"
                        if "solve time" in missing else ""))
    if series:
        fig, axes = _figure(len(series), 2, height=2.4, width=5.0, sharex=False)
    else:  # one line of text says what the run's QP did: no empty axes, no flat line
        fig, axes = _figure(1, 1, height=0.6, width=10.0)
    failed = [k for k, s in enumerate(r.qp_status[:n]) if qp_failed(s)]
    from matplotlib.ticker import MaxNLocator

    for row, (name, label, values, integer) in enumerate(series):
        ax_t, ax_h = axes[row]
        known = np.isfinite(values)
        ax_t.plot(t, values, linewidth=0.8, drawstyle="steps-post" if integer else "default")
        marked = [k for k in failed if known[k]]
        if marked:
            ax_t.plot(t[marked], values[marked], "rx", label="failed / held")
            _legend_outside(ax_t)
        finite = values[known]
        if integer:  # counts: one bar per value, integer ticks
            _, _, bars = ax_h.hist(finite, bins=np.arange(int(finite.min()), int(finite.max()) + 2) - 0.5)
            ax_h.bar_label(bars, fmt="%d", fontsize="small")  # a bar of 2 among 2500 is still read
            ax_t.yaxis.set_major_locator(MaxNLocator(integer=True))
            ax_h.xaxis.set_major_locator(MaxNLocator(integer=True))
        else:
            ax_h.hist(finite, bins=50)
        ax_t.set_ylabel(label)
        ax_t.set_title(f"QP {name} per control period")
        ax_h.set_xlabel(label)
        ax_h.set_ylabel("solves [-]")
        ax_h.set_title(f"median {np.median(finite):.3g}, max {finite.max():.3g} ({finite.size} solves)")
    if not series:
        ax = axes[0, 0]
        ax.set_axis_off()
        text = "no QP solve in this run" if n == 0 else f"nothing varied over the {n} QP solves:\n" + "\n".join(notes)
        ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center")
    else:
        for ax in axes[:, 0]:
            ax.set_xlabel("t [s]")
            if r.t.size > 1:
                ax.set_xlim(float(r.t[0]), float(r.t[-1]))
    if notes and series:
        fig.supxlabel("; ".join(notes), fontsize="small", color="0.3")
    _title(fig, r, "what did the load-distribution QP cost?")
    _mark_failure(axes[:, 0], r)
    return _save(fig, path)


# Names of the files the plots are written to, and the functions that draw them.
PLOTS = {
    "object_pose.png": plot_tracking,
    "contact_forces.png": plot_force_regulation,
    "joint_torques.png": plot_limits,
    "qp_solve_times.png": plot_qp_solve_times,
}

# Former names, kept for callers of the previous API.
plot_object_pose = plot_tracking
plot_contact_forces = plot_force_regulation
plot_joint_torques = plot_limits


def figures(result: "SimulationResult") -> dict:
    """Every plot as ``{file name: Figure}`` (nothing written)."""
    return {name: draw(result) for name, draw in PLOTS.items()}


def plot_result(result: "SimulationResult", directory: str | Path) -> list[Path]:
    """Write ``object_pose.png``, ``contact_forces.png``, ``joint_torques.png`` and
    ``qp_solve_times.png`` into ``directory`` (created if needed); returns the paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, draw in PLOTS.items():
        draw(result, directory / name)
        paths.append(directory / name)
    return paths
