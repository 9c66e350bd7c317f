"""plants: the physics of the elastic cooperative model (Zivanovic & Vukobratovic, ch. 4).

Stateless: every function takes (t, x, u) or (Y, dY) and returns arrays. Subpackages:

- :mod:`plants.frames` - ZYX Euler angles, ``R(A)``, ``L(A)`` and its derivative;
- :mod:`plants.charts` - rotation charts: the angles taken about a constant rotation, re-centring,
  and the book's world angles back;
- :mod:`plants.arms` - serial chains (DH tables), ``puma560()``, ``planar3r()``;
- :mod:`plants.elastic` - nodes, interconnections, the elastic system (113, 115) and its
  immobile linear model (4.5);
- :mod:`plants.cooperative` - the cooperative system ``Gamma z'' + phi = (tau, 0)`` (177, 183).

The numerics run in the compiled core (``plants._core``, built from plants/core at install).

This package never imports :mod:`coopctrl`.
"""

from plants.errors import (
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
