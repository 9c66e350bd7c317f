"""The compiled loop's large stages, each compiled on its own and called through a function pointer.

numba links the code of every function a kernel calls into the kernel and optimizes the whole
again: a stage called directly from :func:`coopctrl.loop.kernel.run_ticks` (the plant's control
terms, the QP rows, the QP answer, the controllers, the plant's period advance) would be optimized
and emitted a second time inside the tick on an empty cache. Passed in as a numba ``cfunc`` (a C
function with the argument types of the run, cached on disk like a ``@njit(cache=True)`` function),
a stage is compiled once, ``run_ticks`` calls it through its address (a few nanoseconds per call;
the arithmetic is the same), and a stage a run does not need (the energy of a run without an energy
guard) is replaced by one that does nothing with the same signature, so it is never compiled.

:func:`compile_stage` is the one place a stage is made: ``function`` is a plain Python function
(not ``@njit``: its cache entries would share a file name with the ``cfunc``'s), compiled for the
numba types of example arguments, which must be those of the kernel's call. :class:`TickStages` holds a
run's stages by name: the tick reads each by its name, and numba types the named tuple field by field
(a plain tuple of functions would be unified into one function type, numba's experimental path).
"""

from __future__ import annotations

from collections import namedtuple

from numba import cfunc, types

import coopctrl.loop.argument_types as argument_types

#: The stages compiled in this process, by (function, signature, runtime), and by (function, restype, the
#: arguments' :func:`~coopctrl.loop.argument_types.signature_key`, runtime).
_COMPILED: dict = {}


def compile_stage(function, restype: types.Type, *args, runtime: bool = False, types_only: bool = False):
    """``function`` compiled as a numba ``cfunc`` returning ``restype`` for the types of ``args``.

    Args:
        function: A plain Python function in numba's subset returning no array.
        restype: The numba type it returns (a value of another type is converted to it).
        args: Example arguments, or numba types, in the order of the kernel's call.
        runtime: Compile with numba's runtime (reference counting), for a stage that may allocate
            (the implicit integrators' ``pinv`` fallback); without it otherwise, as the kernel.
        types_only: Compile nothing: return the numba type the compiled stage has as an argument of
            the tick (``numba.typeof`` of it: the function type of its signature).

    Returns:
        The compiled ``cfunc`` (the same object for the same function and types in this process), or
        with ``types_only`` its numba type.
    """
    if types_only:
        return types.FunctionType(restype(*(a if isinstance(a, types.Type) else argument_types.argument_type(a)
                                            for a in args)))
    quick = argument_types.signature_key(args)  # hashed in C, not numba's types (a run's set-up pays it)
    if quick is not None:
        compiled = _COMPILED.get((function, restype, quick, runtime))
        if compiled is not None:
            return compiled
    signature = restype(*(a if isinstance(a, types.Type) else argument_types.argument_type(a) for a in args))
    key = (function, signature, runtime)
    compiled = _COMPILED.get(key)
    if compiled is None:
        compiled = _COMPILED[key] = cfunc(signature, cache=True, _nrt=runtime)(function)
    if quick is not None:
        _COMPILED[(function, restype, quick, runtime)] = compiled
    return compiled


#: A run's stages, by name (``LoopModel.stages``; built by :func:`coopctrl.loop.kernel.tick_stages`).
TickStages = namedtuple("TickStages", "advance terms qp_rows qp_answer control energy elastic_split")
TickStages.__doc__ = """The compiled stages one run's tick calls (``LoopModel.stages``), by name.

``advance``: the plant over one control period (:func:`coopctrl.integrators.compiled.zoh_advance`); ``terms``: the
plant's control terms at a state; ``qp_rows``: the QP's rows of a tick; ``qp_answer``: the compiled solve and
its check; ``control``: the leader's and the followers' laws; ``energy``: the plant's energy (or a stage
that does nothing, for a run that needs none); ``elastic_split``: the elastic split's inputs (or nothing,
for a pseudo-inverse split). Each is a numba ``cfunc`` (:func:`compile_stage`).
"""
