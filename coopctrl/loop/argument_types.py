"""The numba types of a run's arguments, remembered by what decides them.

A run hands the compiled tick and its stages about 490 arrays (in tuples). numba's ``typeof`` types
each of them in Python, about 12 us an array: 7 to 14 ms a run, most of a sweep run's set-up
beside its ticks. The type of a value depends only on a few of its properties:

* an ``ndarray``: its dtype, its number of dimensions, its layout (``C`` if C-contiguous, else ``F`` if
  Fortran-contiguous, else ``A``) and whether it is writable (``numba.typeof`` reads nothing else);
* a tuple or named tuple: its class and the types of its items;
* a ``bool``, a ``float`` or a numpy scalar: its class; an ``int``: whether it fits in an int64;
* a compiled stage (a numba ``cfunc``): the object itself, compiled once per signature and kept for
  the process.

:func:`argument_type` computes that key (a few hundred nanoseconds an array) and types each key once
with ``numba.typeof``: the result is numba's own type, equal to ``numba.typeof(value)`` (checked in
``tests/test_loop_argument_types.py``). Anything else is typed by ``numba.typeof`` every time.
"""

from __future__ import annotations

import numpy as np
from numba import typeof, types
from numba.core.ccallback import CFunc

#: key -> numba type, for the keys of :func:`_key`.
_TYPES: dict = {}
#: id of a compiled stage -> the stage, held for the process so that its id stays its own.
_STAGES: dict = {}


def _key(value):
    """What decides ``numba.typeof(value)``, hashable; ``None`` where this module does not know."""
    cls = type(value)
    if cls is np.ndarray:
        flags = value.flags
        return value.dtype, value.ndim, flags.c_contiguous, flags.f_contiguous, flags.writeable
    if cls is bool or cls is float:
        return cls
    if cls is int:  # int64, or uint64 beyond it (numba.typeof)
        return cls, -2 ** 63 <= value < 2 ** 63
    if isinstance(value, (np.integer, np.floating, np.bool_)):  # a numpy scalar: its dtype decides
        return cls
    if isinstance(value, tuple) and (cls is tuple or hasattr(cls, "_fields")):
        items = []
        for item in value:
            k = _key(item)
            if k is None:
                return None
            items.append(k)
        return cls, tuple(items)
    if isinstance(value, CFunc):
        if _STAGES.setdefault(id(value), value) is not value:  # cannot happen while held; typed afresh then
            return None
        return "stage", id(value)
    return None


def argument_type(value):
    """``numba.typeof(value)`` (as an argument of a compiled function), from a memo for arrays, tuples
    of them, bools, ints, floats, numpy scalars and compiled stages."""
    key = _key(value)
    if key is None:
        return typeof(value)
    ty = _TYPES.get(key)
    if ty is None:
        ty = _TYPES[key] = typeof(value)
    return ty


def signature_key(args):
    """What decides the numba types of ``args`` (numba types among them stand for themselves), hashable
    in C; ``None`` where :func:`_key` does not know an argument: equal keys give equal signatures."""
    keys = []
    for a in args:
        k = ("type", a) if isinstance(a, types.Type) else _key(a)
        if k is None:
            return None
        keys.append(k)
    return tuple(keys)


def _holds_type(value) -> bool:
    """Whether ``value`` is a numba type or a (named) tuple holding one, at any depth."""
    if isinstance(value, types.Type):
        return True
    return isinstance(value, tuple) and any(_holds_type(v) for v in value)


def _type_with_types(value):
    """:func:`argument_type` of ``value``, where numba types in it (at any depth of its tuples) stand for
    themselves: the type of the same value holding, in their place, objects of those types (as
    ``numba.typeof`` types a tuple: ``BaseTuple.from_types`` of its items' types and its class)."""
    if isinstance(value, types.Type):
        return value
    if isinstance(value, tuple) and _holds_type(value):
        return types.BaseTuple.from_types([_type_with_types(v) for v in value], type(value))
    return argument_type(value)


def signature_of(args) -> tuple:
    """The numba types of the arguments ``args``, in order (:func:`argument_type` of each); a numba type
    among them, or in their tuples, stands for itself (a compiled stage's type before it is compiled:
    :mod:`coopctrl.loop.compile_ahead`)."""
    return tuple(_type_with_types(a) for a in args)
