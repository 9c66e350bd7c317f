"""Linear modes of a cooperative plant at a state: ``omega_max``, damping, and step limits.

About a state ``x`` (with the input ``tau_eq`` that holds the arms still, see :func:`linear_modes`)
the plant is linearized by central differences, ``A = df/dx`` (:meth:`CooperativePlant.jacobians`),
in the state order ``x = (z, dz)``, ``z = (q, Y_0)`` (docs/model.md s.5). Its acceleration rows give the
generalized stiffness and damping [#]_:

.. math::

    K_z = -\\Gamma A_{\\ddot z z}, \\qquad D_z = -\\Gamma A_{\\ddot z \\dot z}, \\qquad
    K_z v = \\omega^2 \\Gamma v

with ``Gamma = plant.mass_matrix(x)``. ``omega_max`` [rad/s] is the square root of the largest
generalized eigenvalue of the symmetric part of ``K_z`` against ``Gamma`` (:func:`scipy.linalg.eigh`).
What is done with the rest:

- **Asymmetry.** ``K_z`` is symmetric for conservative forces; the finite differences, and forces
  that are not the gradient of a potential (the controllers are not in the plant; at rest there
  are no gyroscopic terms), leave an antisymmetric part. It is dropped for ``omega``, and its size
  ``|K_z - K_z^T| / |K_z|`` (Frobenius) is reported as :attr:`ModalAnalysis.stiffness_asymmetry`.
- **Negative eigenvalues** ``omega^2 < 0`` are static instabilities (gravity on the arms, or a
  squeezed object buckling out of the grasp line, which :meth:`ClosedLoop.diagnose` explains):
  they are counted (:attr:`ModalAnalysis.unstable_stiffness_modes`) but are not oscillations, and
  no step cures them.
- **Damping ratio** of the highest mode, from the eigenvalues of ``A`` (the exact coupled, damped
  modes): the complex eigenvalue ``lambda`` whose eigenvector's position part is closest (in the
  ``Gamma`` inner product) to the highest undamped mode shape ``v``, and ``zeta = -Re(lambda) / |lambda|``.
  If that eigenvalue is real (the mode is overdamped), the classical modal damping
  ``zeta = v^T D_s v / (2 omega)`` (``v`` ``Gamma``-normalized, ``D_s`` the symmetric part of ``D_z``)
  is used instead; it is also reported as :attr:`ModalAnalysis.modal_damping_ratio` (exact when the
  damping is proportional, an approximation otherwise).

The **predicted largest stable step** of an integrator is taken on the full linearization ``A``,
with damping and coupling: :meth:`Integrator.max_stable_step` (the stability function on every
eigenvalue of ``A`` that is not physically unstable; the one-step matrix for symplectic Euler).

.. [#] ``A_{zz}`` blocks are ``(nz, nz)``: rows ``nz:`` (accelerations), columns ``:nz``
   (positions) and ``nz:`` (velocities).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from coopctrl.compact_repr import compact_repr


@dataclass(frozen=True, eq=False)
class ModalAnalysis:
    """The linear modes of a plant about one state.

    Attributes:
        x: The state ``(z, dz)`` linearized about.
        tau: The input [N m] held during the linearization (the arms' static torques).
        A: ``df/dx`` at ``(x, tau)``, ``(2 nz, 2 nz)``.
        eigenvalues: Eigenvalues of ``A`` [1/s]; ``eigenvectors`` the matching columns.
        omega_squared: Generalized eigenvalues of ``(sym K_z, Gamma)`` [rad^2/s^2], ascending.
        omega_max: ``sqrt`` of the largest of them [rad/s] (0 if none is positive).
        damping_ratio: Damping ratio [-] of the ``omega_max`` mode, from the eigenvalues of ``A``.
        modal_damping_ratio: Its classical modal damping ratio ``v^T D_s v / (2 omega)`` [-].
        stiffness_asymmetry: ``|K_z - K_z^T|_F / |K_z|_F`` [-].
        unstable_stiffness_modes: Number of negative ``omega^2`` (static instabilities).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    x: np.ndarray
    tau: np.ndarray
    A: np.ndarray
    eigenvalues: np.ndarray
    eigenvectors: np.ndarray
    omega_squared: np.ndarray
    omega_max: float
    damping_ratio: float
    modal_damping_ratio: float
    stiffness_asymmetry: float
    unstable_stiffness_modes: int

    @property
    def fastest_damping_ratio(self) -> float:
        """``-Re(lambda) / |lambda|`` [-] of :attr:`fastest_eigenvalue` (0 within the marginal band)."""
        return damping_ratio_of(self.fastest_eigenvalue)

    @property
    def fastest_eigenvalue(self) -> complex:
        """The eigenvalue of ``A`` [1/s] of largest magnitude."""
        return complex(self.eigenvalues[np.argmax(np.abs(self.eigenvalues))]) if self.eigenvalues.size else 0j

    def limiting_mode(self, integrator) -> int | None:
        """Index (into :attr:`eigenvalues`) of the mode that sets ``integrator``'s limit, or ``None``.

        For schemes with a stability function, the eigenvalue with the smallest
        :meth:`Integrator.eigenvalue_max_step`; otherwise (symplectic Euler) the one with the
        smallest single-oscillator limit ``predicted_max_step(|lambda|, zeta)``, a label (the coupled
        limit is :meth:`predicted_max_step`). Physically unstable and zero modes are skipped.
        """
        from coopctrl.integrators.base import MARGINAL_REAL_PART, ZERO_MODE

        lam = self.eigenvalues
        if lam.size == 0:
            return None
        mag = np.abs(lam)
        candidates = [k for k in range(lam.size) if mag[k] > ZERO_MODE * mag.max()
                      and lam[k].real <= MARGINAL_REAL_PART * mag[k] and lam[k].imag >= 0.0]
        if not candidates:
            return None
        try:
            limits = [integrator.eigenvalue_max_step(lam[k]) for k in candidates]
        except NotImplementedError:
            limits = [integrator.predicted_max_step(mag[k], max(-lam[k].real / mag[k], 0.0)) for k in candidates]
        best = int(np.argmin(limits))
        return candidates[best] if math.isfinite(limits[best]) else None

    def predicted_max_step(self, integrator) -> float:
        """Largest stable step [s] of ``integrator`` on this linearization (``math.inf``: no limit,
        ``0.0``: unstable at every step); :meth:`Integrator.max_stable_step` of ``A``."""
        return float(integrator.max_stable_step(self.A))

    def seeded_along(self, k: int, size: float, nz: int | None = None) -> np.ndarray:
        """The linearization state :attr:`x` plus a perturbation along mode ``k``'s eigenvector.

        The perturbation is the real part of the eigenvector (positions and rates), scaled so that
        its largest position component is ``size`` [m or rad]: a test that expects an unstable mode
        to grow seeds it on purpose with this, instead of leaving it to round-off (which varies
        with the CPU and the library versions). ``nz``: number of positions (default half of ``x``).
        """
        nz = self.x.size // 2 if nz is None else int(nz)
        v = np.asarray(self.eigenvectors[:, k])
        re = v.real if np.max(np.abs(v.real[:nz])) >= np.max(np.abs(v.imag[:nz])) else v.imag
        scale = float(np.max(np.abs(re[:nz])))
        if not scale > 0.0:
            raise ValueError(f"mode {k} has no position component to scale to size = {size!r}")
        return self.x + (size / scale) * re


def holding_torque(plant, x) -> np.ndarray:
    """The input [N m] that zeroes the joint accelerations at ``x`` in the least-squares sense.

    ``f`` is affine in ``tau``: ``ddz = a_0 + B tau``; ``tau = argmin |a_0 + B tau|``. It holds
    the arms still at a state at rest, so the linearization is about a (near) equilibrium rather
    than about arms falling under gravity.
    """
    x = np.asarray(x, dtype=float)
    nz, nu = plant.nz, plant.input_size
    tau0 = np.zeros(nu)
    a0 = plant.rhs(0.0, x, tau0)[nz:]
    B = np.empty((nz, nu))
    for k in range(nu):
        e = np.zeros(nu)
        e[k] = 1.0
        B[:, k] = plant.rhs(0.0, x, e)[nz:] - a0
    return np.linalg.lstsq(B, -a0, rcond=None)[0]


def linear_modes(plant, x, tau=None) -> ModalAnalysis:
    """:class:`ModalAnalysis` of ``plant`` about state ``x`` (input ``tau``, default :func:`holding_torque`)."""
    from scipy.linalg import eigh

    x = np.asarray(x, dtype=float)
    tau = holding_torque(plant, x) if tau is None else np.asarray(tau, dtype=float)
    A, _ = plant.jacobians(x, tau)
    nz = plant.nz
    Gamma = plant.mass_matrix(x)
    Gamma = 0.5 * (Gamma + Gamma.T)
    K = -Gamma @ A[nz:, :nz]
    D = -Gamma @ A[nz:, nz:]
    norm = float(np.linalg.norm(K))
    asym = float(np.linalg.norm(K - K.T) / norm) if norm > 0 else 0.0
    w2, V = eigh(0.5 * (K + K.T), Gamma)
    top = int(np.argmax(w2))
    omega = math.sqrt(w2[top]) if w2[top] > 0 else 0.0
    v = V[:, top]
    modal = max(float(v @ (0.5 * (D + D.T)) @ v / (2.0 * omega)), 0.0) if omega > 0 else 0.0
    # eigh's negative-eigenvalue count, with a tolerance against round-off of the symmetric part
    tol = 1e-9 * max(abs(float(w2[-1])), 1.0)
    lam, vec = np.linalg.eig(A)
    zeta = modal
    if omega > 0 and lam.size:
        u = vec[:nz, :]  # position parts of the eigenvectors
        gv = Gamma @ v
        norms = np.sqrt(np.abs(np.einsum("ik,ij,jk->k", u.conj(), Gamma, u))) + 1e-300
        match = int(np.argmax(np.abs(u.conj().T @ gv) / norms))
        if abs(lam[match].imag) > 0.0:
            zeta = damping_ratio_of(complex(lam[match]))
    return ModalAnalysis(x=x, tau=tau, A=A, eigenvalues=lam, eigenvectors=vec, omega_squared=w2, omega_max=omega,
                         damping_ratio=zeta, modal_damping_ratio=modal, stiffness_asymmetry=asym,
                         unstable_stiffness_modes=int(np.sum(w2 < -tol)))


def damping_ratio_of(lam: complex) -> float:
    """``-Re(lambda) / |lambda|`` [-], 0 when ``|Re(lambda)| <= MARGINAL_REAL_PART |lambda|`` (undamped)."""
    from coopctrl.integrators.base import MARGINAL_REAL_PART

    r = abs(lam)
    if r == 0.0 or abs(lam.real) <= MARGINAL_REAL_PART * r:
        return 0.0
    return max(-lam.real / r, 0.0)
