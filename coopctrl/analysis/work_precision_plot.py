"""The work-precision plot of a :class:`~coopctrl.analysis.tradeoff.TradeoffResult` (matplotlib Agg, no pyplot).

Two log-log panels, error against wall time: the object position error [m] (left) and the
contact force error [N] (right). One line per integrator through its steps (each point labelled
``n`` of ``h = T/n``; an error-controlled scheme, dashed, through its tolerances, each point
labelled with the exponent of its ``rtol``: ``-6`` for 1e-6), the Pareto front of each panel highlighted and joined, the reference's wall time as a
vertical line. Rows that diverged are not drawn; the legend (below the panels, so that it
hides no curve) counts them. Labels alternate above and below their points.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from coopctrl.io.atomic import atomic_write
from coopctrl.results.plain_axes import plain_tick_labels

if TYPE_CHECKING:
    from coopctrl.analysis.tradeoff import TradeoffResult

_MARKERS = {"euler": "o", "symplectic_euler": "s", "rk4": "D", "implicit_midpoint": "^", "implicit_euler": "v",
            "rk23": "P", "rk45": "X", "trbdf2": "*"}


def point_label(row) -> str:
    """``"4"`` (n of h = T/4) for a fixed step; ``"-6"`` (exponent of rtol = 1e-6) for an error-controlled row."""
    if row.substeps is None:
        exponent = math.log10(row.rtol)
        return f"{exponent:.0f}" if abs(exponent - round(exponent)) < 1e-9 else f"{row.rtol:.1g}"
    return str(row.substeps)


def work_precision_figure(result: "TradeoffResult"):
    """The matplotlib :class:`~matplotlib.figure.Figure` (Agg canvas attached) of ``result``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    fig = Figure(figsize=(12.0, 5.4), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2)
    panels = (("position_error_m", "pareto", "object position error [m]"),
              ("force_error_N", "pareto_force", "contact force error [N]"))
    names = list(dict.fromkeys(r.integrator for r in result.rows))
    colors = {name: f"C{k}" for k, name in enumerate(names)}
    for ax, (metric, front_key, label) in zip(axes, panels):
        drawn = 0  # points with a positive error (a log axis needs at least one)
        for name in names:
            rows = [r for r in result.rows if r.integrator == name]
            shown = [r for r in rows if r.status == "ok" and getattr(r, metric) is not None and getattr(r, metric) > 0]
            failed = len(rows) - len([r for r in rows if r.status == "ok"])
            legend = name + (f" ({failed} diverged)" if failed else "")
            if not shown:
                ax.plot([], [], marker=_MARKERS.get(name, "o"), color=colors[name], label=legend)
                continue
            drawn += len(shown)
            style = "--" if shown[0].substeps is None else "-"
            ax.plot([r.wall_time_s for r in shown], [getattr(r, metric) for r in shown], style,
                    marker=_MARKERS.get(name, "o"), color=colors[name], label=legend, markersize=5)
            for k, r in enumerate(shown):
                ax.annotate(point_label(r), (r.wall_time_s, getattr(r, metric)), textcoords="offset points",
                            xytext=(5, 4) if k % 2 == 0 else (5, -11), fontsize=8, color=colors[name])
        front = sorted((r for r in result.rows if getattr(r, front_key) and getattr(r, metric) > 0),
                       key=lambda r: r.wall_time_s)
        if front:
            ax.plot([r.wall_time_s for r in front], [getattr(r, metric) for r in front], ":", color="k", lw=1.0,
                    zorder=1)
            ax.scatter([r.wall_time_s for r in front], [getattr(r, metric) for r in front], s=140,
                       facecolors="none", edgecolors="k", linewidths=1.5, label="Pareto front", zorder=3)
        ax.axvline(result.reference.wall_time_s, color="0.4", ls="--", lw=1.0,
                   label=f"reference {result.reference.config.method} wall time")
        ax.set_xscale("log")
        if drawn:
            ax.set_yscale("log")
        else:  # every run of the grid diverged: say so instead of an empty log axis (which cannot be drawn)
            ax.set_yticks([])
            ax.text(0.5, 0.5, "no run of the grid finished:\nevery row diverged", transform=ax.transAxes,
                    ha="center", va="center", fontsize=11, color="C3")
        # wall times often span less than a decade: ticks at 1, 2 and 5 per decade, in plain numbers
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
        ax.xaxis.set_minor_locator(LogLocator(subs=tuple(float(k) for k in range(1, 10))))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.margins(x=0.08, y=0.12)  # room for the labels of the outermost points
        ax.set_xlabel("wall time [s]  (labels: n of the step h = T/n; dashed: log10 rtol)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)), fontsize=9)
    fig.suptitle(f"{result.scenario}: work-precision, {result.duration_s:.4g} s simulated, "
                 f"T = {result.control_period_s * 1e3:.4g} ms (error: maximum over the run against the reference)",
                 fontsize=10)
    plain_tick_labels(fig)
    return fig


def plot_work_precision(result: "TradeoffResult", path: str | Path) -> Path:
    """Write the work-precision plot of ``result`` as a PNG to ``path``, atomically."""
    path = Path(path)
    fig = work_precision_figure(result)
    with atomic_write(path, "wb") as f:
        fig.savefig(f, format="png", dpi=100)
    return path
