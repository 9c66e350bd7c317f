"""Small dense linear algebra written as loops for the numba right-hand sides.

Kept for the numba code that still calls it: coopctrl/load_distribution/ and the cooperative numba kernels. It goes
with its last caller (tests/test_plants_without_numba.py lists it).

docs/performance.md: ``np.linalg.solve`` inside numba costs ~7 us with its checks and allocations;
a 6x6 Cholesky written out costs well under 1 us.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, _nrt=False)
def cholesky_solve(A, b, x):
    """Solve ``A x = b`` for symmetric positive-definite ``A`` (n x n, overwritten by its factor).

    Returns False (and leaves ``x`` undefined) if ``A`` is not positive definite.
    """
    return cholesky_solve_n(A, b, x, A.shape[0])


@njit(cache=True, inline="always")
def cholesky_solve_n(A, b, x, n):
    """:func:`cholesky_solve` on the leading ``n x n`` block of ``A`` and the first ``n`` entries of
    ``b`` and ``x`` (larger preallocated arrays, passed whole so that they stay contiguous). Only the
    lower triangle (diagonal included) of ``A`` is read."""
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= A[k, i] * x[k]
        x[i] = s / A[i, i]
    return True
