"""Abstract base of the fixed-step integrators.

A plant is a right-hand side ``f(t, x, u) -> dx`` with the first-order state
``x = (z, dz)`` of size ``2 n`` (positions, then velocities) and ``dx = (dz, ddz)``. The input
``u`` is held constant over a step (zero-order hold). ``f`` must return a **new** array on each
call (the integrators keep several evaluations alive at once).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, Callable

import numpy as np

#: A plant right-hand side ``f(t, x, u) -> dx``: ``t`` in [s], ``x = (z, dz)``, ``dx = (dz, ddz)``.
RightHandSide = Callable[[float, np.ndarray, Any], np.ndarray]


def check_omega_max(omega_max: float) -> float:
    """Validate ``omega_max`` [rad/s] (finite, >= 0) and return it as a float."""
    omega = float(omega_max)
    if not math.isfinite(omega) or omega < 0.0:
        raise ValueError(
            f"omega_max = {omega_max!r} is invalid: expected a finite angular frequency >= 0 [rad/s]"
        )
    return omega


class Integrator(ABC):
    """One fixed-step scheme for ``dx/dt = f(t, x, u)`` with ``u`` held over the step.

    Attributes:
        name: Registry name (``"rk4"``).
        order: Order of global accuracy [-].
    """

    name: str = ""
    order: int = 0

    @abstractmethod
    def step(self, f: RightHandSide, t: float, x: np.ndarray, u: Any, h: float) -> np.ndarray:
        """Advance the state by one step.

        Args:
            f: Right-hand side ``f(t, x, u) -> dx``.
            t: Time at the start of the step in [s].
            x: State ``(z, dz)`` at ``t``, a 1-D float64 array of size ``2 n`` (not modified).
            u: Input, held constant over the step.
            h: Step in [s].

        Returns:
            A new array: the state at ``t + h``.
        """

    @abstractmethod
    def predicted_max_step(self, omega_max: float) -> float:
        """Largest stable step [s] for an undamped oscillator of frequency ``omega_max`` [rad/s].

        ``math.inf`` when the scheme is unconditionally stable (or ``omega_max = 0``), ``0.0``
        when it is unstable at every step.
        """

    def reset(self) -> None:
        """Forget any state cached between steps (no-op for the explicit schemes)."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
