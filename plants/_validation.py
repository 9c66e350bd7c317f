"""Small parameter checks shared by the physics dataclasses; each raises ParameterError naming the field."""

from __future__ import annotations

import math

import numpy as np

from plants.errors import ParameterError


def finite_array(name: str, value, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """Return ``value`` as a float array, checking finiteness and (optionally) its shape."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a number or an array of numbers") from None
    if shape is not None and arr.shape != shape:
        raise ParameterError(name, value, f"shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(name, value, "finite values (no nan or inf)")
    return arr


def positive(name: str, value) -> float:
    """A finite number > 0."""
    v = finite_scalar(name, value)
    if not v > 0.0:
        raise ParameterError(name, value, "a finite number > 0")
    return v


def non_negative(name: str, value) -> float:
    """A finite number >= 0."""
    v = finite_scalar(name, value)
    if v < 0.0:
        raise ParameterError(name, value, "a finite number >= 0")
    return v


def finite_scalar(name: str, value) -> float:
    """A finite real number."""
    if isinstance(value, bool):
        raise ParameterError(name, value, "a number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a number") from None
    if not math.isfinite(v):
        raise ParameterError(name, value, "a finite number (no nan or inf)")
    return v


def per_axis(name: str, value, n: int, *, allow_zero: bool = True) -> np.ndarray:
    """A scalar broadcast to ``n`` axes, or ``n`` values; all finite and >= 0 (> 0 unless allow_zero)."""
    arr = finite_array(name, value)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ParameterError(name, value, f"a scalar or {n} values")
    if np.any(arr < 0.0) or (not allow_zero and np.any(arr <= 0.0)):
        raise ParameterError(name, value, f"values {'>= 0' if allow_zero else '> 0'}")
    return arr


def sized_vector(name: str, value, size: int, what: str) -> np.ndarray:
    """``value`` as a contiguous float64 vector of ``size`` entries (``what`` says what it is): a
    ``TypeError`` for no numbers at all (``None``, a string), a :class:`ParameterError` (``ValueError``)
    naming ``name`` for another shape. Finiteness is not checked: a diverging run's NaN state must reach
    the physics, which reports it. A float64 array of the right shape passes as it is (cheap)."""
    if type(value) is np.ndarray and value.shape == (size,) and value.dtype == np.float64 and value.flags.c_contiguous:
        return value
    allowed = f"{what}: {size} numbers"
    if value is None or isinstance(value, (str, bytes, dict)):
        raise TypeError(f"{name} = {value!r:.80} is invalid: expected {allowed}")
    try:
        arr = np.ascontiguousarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} = {value!r:.80} is invalid: expected {allowed}") from None
    if arr.shape != (size,):
        raise ParameterError(name, f"<{'x'.join(map(str, arr.shape)) or 'scalar'} values>", f"{allowed}, shape ({size},)")
    return arr
