"""A tight reference integration of a passive plant whose nodes' angles are in charts: DOP853 in short
segments, re-centring the charts between segments where a node's ``|cos theta|`` gets small."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

# DOP853 at rtol = atol = 1e-12: its local error per step is ~1e-12 of the state, so the energy of a
# smooth passive motion drifts by ~1e-11 relative over a few hundred steps, well below the 1e-8 that
# issue 20 asks for; a wrong force (not the gradient of the potential) drifts by ~1e-3.
RTOL = ATOL = 1e-12
#: Re-centre a chart once its |cos theta| falls below this (its angles are then > 45 deg from it).
RECENTRE_COS = 0.7


def integrate_passive(plant, x0, rhs, recentre, chart_cos, duration, segment):
    """``(times, states, plants)`` at the ends of segments of ``segment`` [s] over ``duration`` [s].

    ``rhs(plant, t, x)``: the plant's right-hand side; ``recentre(plant, x) -> (plant, x)``;
    ``chart_cos(plant, x)``: the smallest ``|cos theta|`` of the charted nodes' angles (``plant.chart_cos``)."""
    t, x = 0.0, np.asarray(x0, dtype=float).copy()
    times, states, plants = [t], [x.copy()], [plant]
    while t < duration - 1e-12:
        if chart_cos(plant, x) < RECENTRE_COS:
            plant, x = recentre(plant, x)
        t1 = min(duration, t + segment)
        sol = solve_ivp(lambda s, y: rhs(plant, s, y), (t, t1), x, method="DOP853", rtol=RTOL, atol=ATOL)
        assert sol.success, sol.message
        t, x = t1, sol.y[:, -1].copy()
        times.append(t)
        states.append(x.copy())
        plants.append(plant)
    return np.array(times), states, plants


def pitch_about_y(R):
    """``beta = atan2(R_02, R_00)``: the angle of a rotation about the world y axis (the pitch of
    ``R_y(beta)``: 90 deg puts the body x axis vertical)."""
    return float(np.arctan2(R[0, 2], R[0, 0]))
