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
numba types of example arguments, which must be those of the kernel's call.
"""

from __future__ import annotations

import contextlib
import warnings

from numba import cfunc, types
from numba.core.errors import NumbaExperimentalFeatureWarning

import coopctrl.loop.argument_types as argument_types

#: The stages compiled in this process, by (function, signature).
_COMPILED: dict = {}


def compile_stage(function, restype: types.Type, *args, runtime: bool = False):
    """``function`` compiled as a numba ``cfunc`` returning ``restype`` for the types of ``args``.

    Args:
        function: A plain Python function in numba's subset returning no array.
        restype: The numba type it returns (a value of another type is converted to it).
        args: Example arguments, or numba types, in the order of the kernel's call.
        runtime: Compile with numba's runtime (reference counting), for a stage that may allocate
            (the implicit integrators' ``pinv`` fallback); without it otherwise, as the kernel.

    Returns:
        The compiled ``cfunc`` (the same object for the same function and types in this process).
    """
    signature = restype(*(a if isinstance(a, types.Type) else argument_types.argument_type(a) for a in args))
    key = (function, signature, runtime)
    compiled = _COMPILED.get(key)
    if compiled is None:
        compiled = _COMPILED[key] = cfunc(signature, cache=True, _nrt=runtime)(function)
    return compiled


@contextlib.contextmanager
def pointers_in_use():
    """Silence numba's notice that first-class functions (the stages' pointers) are experimental,
    while the stages are compiled and the kernel is typed with them: the feature is used on purpose
    and its results are checked against the reference path (``tests/test_closed_loop.py``); the
    notice would reach every user's terminal. Other warnings pass."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="First-class function type feature is experimental",
                                category=NumbaExperimentalFeatureWarning)
        yield
