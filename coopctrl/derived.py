"""Values derived from an immutable model object, computed once per object.

A shipped trajectory (:class:`~coopctrl.trajectory.MinimumJerkTrajectory`,
:class:`~coopctrl.trajectory.GeodesicTrajectory`) is frozen, its arrays read-only, and a scene's is built once and
shared (:func:`coopctrl.scenario.build.trajectory`); a :class:`~plants.cooperative.CooperativePlant` is not changed
after it is built, and a scene's is built once and shared by every loop built from it
(:func:`coopctrl.scenario.build.build_plant`). What is computed from one (a trajectory's target motion at a run's
times, the verdict of a path check, a plant's grasp stiffness) is the same every time it is asked for.
:func:`derived` keeps the latest :data:`ENTRIES` such values per object, with the object (dropped with it); any
other object (a user's trajectory, which may change) is computed afresh at every call. A changed scenario is
another scenario, with its own plant (and, for another path, its own trajectory): nothing kept here is served for it.
"""

from __future__ import annotations

import weakref

#: Values kept per object [-] (the least recently used is dropped first).
ENTRIES = 8

_KEPT: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def immutable(owner) -> bool:
    """True for the model objects whose derived values are kept: the shipped trajectory classes and the cooperative
    plant (exactly: a subclass may add state of its own)."""
    from coopctrl.trajectory import GeodesicTrajectory, MinimumJerkTrajectory
    from plants.cooperative import CooperativePlant

    return type(owner) in (MinimumJerkTrajectory, GeodesicTrajectory, CooperativePlant)


def derived(owner, key, compute):
    """``compute()``, the value ``key`` (hashable: what it depends on besides ``owner``) of ``owner``: computed at
    the first call for an :func:`immutable` owner and returned again after, else at every call. The caller makes
    the value safe to share (read-only arrays, or a copy to each caller)."""
    try:
        hash(key)
    except TypeError:  # a part of the key that may change (an unhashable configuration): not kept
        return compute()
    if not immutable(owner):
        return compute()
    kept = _KEPT.setdefault(owner, {})
    if key in kept:
        kept[key] = kept.pop(key)  # now the most recently used
        return kept[key]
    value = compute()
    while len(kept) >= ENTRIES:
        del kept[next(iter(kept))]
    kept[key] = value
    return value
