"""Frequency-domain figures of SISO loops: margins and bandwidth, continuous or discrete.

Two workarounds for python-control 0.10.2, both checked in ``tests/test_tuning.py``:

- ``control.bandwidth`` evaluates a discrete system at ``z = j w`` instead of
  ``z = exp(j w T)`` (fixed upstream in python-control PR #1212, not yet released), so the
  bandwidth of a discrete system is found here on its frequency response.
- ``control.stability_margins`` of a high-order discrete state-space model goes through its
  transfer function, whose polynomial coefficients lose every digit when the poles cluster
  near ``z = 1`` (the 20 to 40 states of a closed loop at 1 kHz). The margins are therefore
  computed by ``control.stability_margins`` on an FRD (frequency response data) of the
  state-space model, sampled densely up to the Nyquist frequency and interpolated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from coopctrl.compact_repr import compact_repr

#: Frequency samples per decade of the response used for the margins and the bandwidth.
POINTS_PER_DECADE = 400

#: Lowest frequency sampled [rad/s].
LOWEST_FREQUENCY = 1e-2


def frequency_grid(sys, highest: float | None = None) -> np.ndarray:
    """Log-spaced frequencies [rad/s] from :data:`LOWEST_FREQUENCY` to ``highest`` (default:
    just below the Nyquist frequency ``pi / T`` of a discrete system, or 1e4 rad/s)."""
    if highest is None:
        highest = 0.999 * np.pi / sys.dt if sys.isdtime(strict=True) else 1e4
    decades = np.log10(highest / LOWEST_FREQUENCY)
    return np.logspace(np.log10(LOWEST_FREQUENCY), np.log10(highest), int(POINTS_PER_DECADE * decades) + 1)


def frequency_response(sys, omega) -> np.ndarray:
    """Complex SISO response at ``omega`` [rad/s] (``z = exp(j w T)`` for discrete systems).

    From the state-space matrices, without a transfer function: with the complex Schur form
    ``A = Z U Z^H`` (``U`` upper triangular), ``(s I - A)^-1 B = Z (s I - U)^-1 Z^H B``, solved by
    back substitution for every frequency at once.
    """
    import control
    from scipy.linalg import schur

    ss = control.ss(sys)
    omega = np.asarray(omega, dtype=float)
    s = np.exp(1j * omega * ss.dt) if ss.isdtime(strict=True) else 1j * omega
    A, B, C, D = (np.asarray(M, dtype=float) for M in (ss.A, ss.B, ss.C, ss.D))
    n = A.shape[0]
    if n == 0:
        return np.full(omega.shape, D[0, 0], dtype=complex)
    U, Z = schur(A, output="complex")
    b = Z.conj().T @ B[:, 0]
    X = np.empty((omega.size, n), dtype=complex)
    for i in range(n - 1, -1, -1):
        X[:, i] = (b[i] + X[:, i + 1:] @ U[i, i + 1:]) / (s - U[i, i])
    return X @ (C[0] @ Z) + D[0, 0]


@dataclass(frozen=True)
class Margins:
    """Stability margins of a loop transfer function ``L`` (negative feedback).

    Attributes:
        gain_margin: Factor on the loop gain that reaches instability [-] (``inf`` if the
            phase never crosses -180 deg below the Nyquist frequency).
        phase_margin: [deg].
        stability_margin: Smallest distance of ``L`` to -1 [-].
        phase_crossover: Frequency of the gain margin [rad/s]; gain_crossover: of the phase
            margin [rad/s]; stability_crossover: of the stability margin [rad/s].
        delay_margin: Extra loop delay that reaches instability, ``phase_margin / gain_crossover`` [s].
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    gain_margin: float
    phase_margin: float
    stability_margin: float
    phase_crossover: float
    gain_crossover: float
    stability_crossover: float

    @property
    def delay_margin(self) -> float:
        if not np.isfinite(self.phase_margin) or not self.gain_crossover > 0:
            return float("inf")
        return float(np.deg2rad(self.phase_margin) / self.gain_crossover)

    @property
    def gain_margin_db(self) -> float:
        return float(20 * np.log10(self.gain_margin)) if self.gain_margin > 0 else float("-inf")


def margins(loop) -> Margins:
    """:class:`Margins` of the SISO loop ``loop`` by ``control.stability_margins`` on its
    frequency response (see the module docstring)."""
    import control

    omega = frequency_grid(loop)
    frd = control.FRD(frequency_response(loop, omega), omega, smooth=True)
    gm, pm, sm, wpc, wgc, wsm = (float(v) for v in control.stability_margins(frd))
    if loop.isdtime(strict=True):
        # At the Nyquist frequency z = -1 the response of a real system is real: a negative
        # L(-1) is a -180 deg crossing there, which the sampled grid (open at pi / T) misses.
        w_nyq = np.pi / loop.dt
        L_nyq = complex(frequency_response(loop, np.array([w_nyq]))[0])
        if L_nyq.real < 0 and abs(L_nyq.imag) <= 1e-9 * abs(L_nyq) and (not gm <= -1.0 / L_nyq.real):
            gm, wpc = -1.0 / L_nyq.real, w_nyq
    return Margins(gm, pm, sm, wpc, wgc, wsm)


def bandwidth(sys, drop_db: float = -3.0) -> float:
    """First frequency [rad/s] where ``|G|`` falls ``drop_db`` below its DC gain.

    ``control.bandwidth`` for a continuous system; for a discrete one the first crossing on
    :func:`frequency_grid`, refined by Brent's method on ``|G(exp(j w T))|``. ``inf`` if the
    gain never falls that far below the Nyquist frequency.
    """
    import control
    from scipy.optimize import brentq

    if not sys.isdtime(strict=True):
        return float(control.bandwidth(sys, drop_db))
    dc = abs(complex(np.squeeze(sys.dcgain())))
    target = dc * 10 ** (drop_db / 20)
    omega = frequency_grid(sys)
    mag = np.abs(frequency_response(sys, omega))
    below = np.flatnonzero(mag < target)
    if below.size == 0:
        return float("inf")
    k = below[0]
    if k == 0:
        return float(omega[0])
    f = lambda w: abs(frequency_response(sys, np.array([w]))[0]) - target  # noqa: E731
    return float(brentq(f, omega[k - 1], omega[k], xtol=1e-10, rtol=1e-10))


def phase_margin_from_response(omega, response) -> tuple[float, float]:
    """``(phase margin [deg], gain crossover [rad/s])`` from a sampled loop response: the smallest
    margin over the crossings of ``|L| = 1``, located by linear interpolation in log frequency
    (``nan`` if ``|L|`` never crosses 1). A fast estimate for design iterations; the reported
    figures come from :func:`margins`."""
    mag = np.abs(response)
    k = np.flatnonzero(np.diff(np.sign(mag - 1.0)) != 0)
    if k.size == 0:
        return float("nan"), float("nan")
    best = (float("inf"), float("nan"))
    for i in k:
        lm0, lm1 = np.log(mag[i]), np.log(mag[i + 1])
        f = lm0 / (lm0 - lm1)
        w = float(np.exp(np.log(omega[i]) + f * (np.log(omega[i + 1]) - np.log(omega[i]))))
        ph = np.angle(response[i]) + f * np.angle(response[i + 1] / response[i])
        pm = float((np.degrees(ph) + 180.0 + 180.0) % 360.0 - 180.0)
        if pm < best[0]:
            best = (pm, w)
    return best
