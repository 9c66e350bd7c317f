"""Tick labels that read alone: no offset (``+2e1``) and no common scale factor (``1e-7``) on an axis.

Matplotlib's default :class:`~matplotlib.ticker.ScalarFormatter` moves a large common offset or
power of ten into a text at the end of the axis (``1e-7+4.5e-1``), which a reader of the PNG easily
misses: a time axis from 20 to 20.5 s then reads 0 to 0.5. Every plot of the project turns both off
with :func:`plain_tick_labels`, so each tick label is the plotted value itself.
"""

from __future__ import annotations


def plain_tick_labels(fig) -> None:
    """Turn off the offset and the scientific scale factor of every linear axis of ``fig``.

    Axes with another formatter (log scales, fixed category labels) are left as they are: they
    have no offset text."""
    from matplotlib.ticker import ScalarFormatter

    for ax in fig.get_axes():
        for axis in (ax.xaxis, ax.yaxis):
            formatter = axis.get_major_formatter()
            if isinstance(formatter, ScalarFormatter):
                formatter.set_useOffset(False)
                formatter.set_scientific(False)
