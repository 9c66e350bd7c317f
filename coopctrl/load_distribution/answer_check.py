"""The check of a QP answer and its binding families (docs/model.md section 6): the compiled tick and
:class:`~coopctrl.load_distribution.LoadDistribution` run it in the C++ core (coopctrl/core/qp_answer_check.h:
``coopctrl._core.answer_ok``, ``answer_violation``, ``answer_tolerance``, ``binding_families``).

On the stacked problem of :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`,
``M = [G; C]`` (``k`` balance rows, then the inequality rows), ``lo = [w_N; l]``, ``hi = [w_N; u]``, an
answer ``F`` (n,) [N, N m] is accepted when it is finite and

.. math::

    v = \\max_r \\max(lo_r - (M F)_r,\\; (M F)_r - hi_r) \\le tol, \\qquad
    tol = \\min\\big(100\\, eps_{abs} (1 + s),\\; \\rho L\\big), \\quad s = \\max_r |(M F)_r|,

    L = \\max(1, |w_N|_\\infty, |l|_\\infty, |u|_\\infty) \\text{ (finite bounds only)}:

the solver's own tolerance, never more than the fraction ``rho`` (``ANSWER_TOLERANCE_OF_LOAD``) of the
load [N, N m]. The cap is evaluated only when ``v`` exceeds ``min(100 eps_abs (1 + s), rho)`` (``L >= 1``, so
below that it cannot bind).

The binding families of an accepted answer are those with a multiplier ``|z_r| > 1e-7 (1 + |g|_inf)``
(``g`` the QP's linear term), as a mask of :data:`FAMILY_MIN_GRIP`, :data:`FAMILY_FRICTION`,
:data:`FAMILY_TORQUE` (the record's ``qp_binding``).
"""

from __future__ import annotations

#: Bits of the binding-families mask, in the row order of the problem.
FAMILY_MIN_GRIP = 1
FAMILY_FRICTION = 2
FAMILY_TORQUE = 4
#: The family of each bit, by the names of ``LoadDistributionProblem.rows``.
FAMILY_NAMES = ((FAMILY_MIN_GRIP, "min_grip"), (FAMILY_FRICTION, "friction"), (FAMILY_TORQUE, "torque_limits"))
