"""plants: the physics of the elastic cooperative model (Zivanovic & Vukobratovic, ch. 4).

Stateless: every function takes (t, x, u) or (Y, dY) and returns arrays. Subpackages:

- :mod:`plants.frames` - ZYX Euler angles, ``R(A)``, ``L(A)`` and its derivative;
- :mod:`plants.charts` - rotation charts: the angles taken about a constant rotation, re-centring,
  and the book's world angles back;
- :mod:`plants.arms` - serial chains (DH tables), ``puma560()``, ``planar3r()``;
- :mod:`plants.elastic` - nodes, interconnections, the elastic system (113, 115) and its
  immobile linear model (4.5);
- :mod:`plants.cooperative` - the cooperative system ``Gamma z'' + phi = (tau, 0)`` (177, 183);
- :mod:`plants.kernels` - the compiled (numba) kernels by public name, for compiled callers.

This package never imports :mod:`coopctrl`.
"""

from plants import numba_cache as _numba_cache

_numba_cache.configure()  # before any compiled kernel is defined: the cache keyed on every kernel source

from plants.errors import (  # noqa: E402
    EulerSingularityError,
    ParameterError,
    PlantError,
    SingularJacobianError,
    UnreachablePoseError,
)

__all__ = [
    "EulerSingularityError",
    "ParameterError",
    "PlantError",
    "SingularJacobianError",
    "UnreachablePoseError",
]
