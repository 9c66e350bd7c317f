"""Values derived from a shipped trajectory, computed once per trajectory object.

:class:`~coopctrl.trajectory.MinimumJerkTrajectory` and :class:`~coopctrl.trajectory.GeodesicTrajectory` are
frozen, their arrays read-only, and a scene's is built once and shared (:func:`coopctrl.scenario.build.trajectory`):
what is computed from one (its target motion at a run's times, the verdict of a path check) is the same every
time it is asked for. :func:`derived` keeps the latest :data:`ENTRIES` such values per trajectory, with the
trajectory (dropped with it); any other trajectory (a user's, which may change) is computed afresh at every call.
"""

from __future__ import annotations

import weakref

#: Values kept per trajectory [-] (the least recently used is dropped first).
ENTRIES = 8

_KEPT: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def immutable(trajectory) -> bool:
    """True for the shipped trajectory classes (exactly: a subclass may add state of its own)."""
    from coopctrl.trajectory import GeodesicTrajectory, MinimumJerkTrajectory

    return type(trajectory) in (MinimumJerkTrajectory, GeodesicTrajectory)


def derived(trajectory, key, compute):
    """``compute()``, the value ``key`` (hashable: what it depends on besides the trajectory) of ``trajectory``:
    computed at the first call for a shipped trajectory and returned again after, else at every call. The caller
    makes the value safe to share (read-only arrays)."""
    if not immutable(trajectory):
        return compute()
    kept = _KEPT.setdefault(trajectory, {})
    if key in kept:
        kept[key] = kept.pop(key)  # now the most recently used
        return kept[key]
    value = compute()
    while len(kept) >= ENTRIES:
        del kept[next(iter(kept))]
    kept[key] = value
    return value
