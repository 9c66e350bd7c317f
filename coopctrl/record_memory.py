"""The memory a run's record needs, checked before it is allocated: a run that cannot fit is refused
with its size (``simulation.duration = 1e300`` would otherwise fail deep inside numpy)."""

from __future__ import annotations

import os

from coopctrl.errors import ScenarioError

#: Bytes the run holds per recorded float beyond the record itself: the summary, the result's derived
#: arrays and the saved files' buffers roughly double it.
OVERHEAD_FACTOR = 2.0


def available_memory_bytes() -> float:
    """Memory this process may still use [B]: ``MemAvailable`` of ``/proc/meminfo`` on Linux, else the
    physical memory (``sysconf``), else infinity (no check possible)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return float("inf")


def _size_text(n_bytes: float) -> str:
    for unit, size in (("EiB", 2.0**60), ("PiB", 2.0**50), ("TiB", 2.0**40), ("GiB", 2.0**30), ("MiB", 2.0**20)):
        if n_bytes >= size:
            return f"{n_bytes / size:.3g} {unit}"
    return f"{n_bytes / 1024.0:.3g} KiB"


def check_record_fits(samples: int, floats_per_sample: int, duration: float, control_period: float,
                      available: float | None = None) -> float:
    """Refuse a record of ``samples`` rows of ``floats_per_sample`` float64 values that does not fit in
    memory; returns its size [B] otherwise.

    Args:
        samples: Recorded samples, ``round(duration / control_period) + 1``.
        floats_per_sample: Values recorded per sample (state, torques, wrenches, ...).
        duration: Simulated time [s] (for the message).
        control_period: Control period [s] (for the message).
        available: Memory allowed [B]; default :func:`available_memory_bytes`.

    Raises:
        ScenarioError: ``OVERHEAD_FACTOR`` times the record exceeds the available memory (exit 2).
    """
    size = float(samples) * float(floats_per_sample) * 8.0
    limit = available_memory_bytes() if available is None else available
    if OVERHEAD_FACTOR * size > limit:
        raise ScenarioError(
            "simulation.duration", duration,
            f"a run whose record fits in memory: {samples:.3g} samples (duration / control_period = "
            f"{duration:g} s / {control_period:g} s) need {_size_text(size)} (x{OVERHEAD_FACTOR:g} while the "
            f"result is made), more than the {_size_text(limit)} available; shorten simulation.duration or "
            "lengthen simulation.control_period")
    return size
