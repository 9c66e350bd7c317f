"""Fixed-step integration over a time grid (a convenience for tests and scripts)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from coopctrl.errors import DivergenceError
from coopctrl.integrators.base import Integrator, RightHandSide


@dataclass(frozen=True, eq=False)
class IntegrationResult:
    """States on a uniform time grid.

    Attributes:
        t: Times [s], shape ``(n_steps + 1,)``, ``t[k] = t0 + k h``.
        x: States, shape ``(n_steps + 1, 2 n)``; ``x[0]`` is the initial state.
        integrator: Name of the scheme used.
    """

    t: np.ndarray
    x: np.ndarray
    integrator: str


def integrate(f: RightHandSide, x0, u: Any, t0: float, h: float, n_steps: int,
              integrator: "Integrator | str") -> IntegrationResult:
    """Integrate ``dx/dt = f(t, x, u)`` over ``n_steps`` fixed steps.

    Args:
        f: Right-hand side ``f(t, x, u) -> dx`` (a new array per call).
        x0: Initial state ``(z, dz)``, size ``2 n``.
        u: Input, constant; or a callable ``u(t)`` sampled at the start of each step and held
            over it (zero-order hold).
        t0: Initial time [s].
        h: Step [s], > 0.
        n_steps: Number of steps, >= 0.
        integrator: An :class:`Integrator` or a registry name (``"rk4"``).

    Returns:
        The :class:`IntegrationResult`.

    Raises:
        DivergenceError: When the state becomes non-finite.
    """
    from coopctrl.integrators import get_integrator

    scheme = get_integrator(integrator) if isinstance(integrator, str) else integrator
    h = float(h)
    if not (h > 0.0 and math.isfinite(h)):
        raise ValueError(f"h = {h!r} is invalid: expected a finite step > 0 [s]")
    if int(n_steps) != n_steps or n_steps < 0:
        raise ValueError(f"n_steps = {n_steps!r} is invalid: expected an integer >= 0")
    n_steps = int(n_steps)
    x = np.array(x0, dtype=float)
    if x.ndim != 1 or x.shape[0] % 2:
        raise ValueError(f"x0 has shape {x.shape}: expected a 1-D state (z, dz) of even size")
    t = t0 + h * np.arange(n_steps + 1)
    X = np.empty((n_steps + 1, x.shape[0]))
    X[0] = x
    sampled = callable(u)
    step = scheme.step
    isfinite = np.isfinite
    with np.errstate(over="ignore", invalid="ignore"):  # divergence is detected below
        for k in range(n_steps):
            tk = float(t[k])
            x = step(f, tk, x, u(tk) if sampled else u, h)
            if not isfinite(x).all():
                raise DivergenceError(float(t[k + 1]), "state max-norm", float(np.max(np.abs(x))))
            X[k + 1] = x
    return IntegrationResult(t=t, x=X, integrator=scheme.name)
