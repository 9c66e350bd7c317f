"""An elastic interconnection between two nodes: springs and dampers (docs/model.md s.3, 106-111)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from plants import _validation as v
from plants.elastic._layout import DAMPING_FORMS, ELEMENTS
from plants.errors import ParameterError


@dataclass(frozen=True)
class Interconnection:
    """Springs and dampers joining nodes ``i`` and ``j`` of the elastic system.

    Elements (``element``):

    ``"central"``
        The book's element (106-107, 119): a spring with rest length ``l`` and per-axis
        stiffness ``c^k`` weighted by ``beta = (1 - l/|r_i - r_j|)^2``, plus torsion springs
        ``cA^k`` on the Euler-angle difference ``A_i - A_j - A0``. It has no lateral stiffness
        except through pre-tension (the buckling limit of docs/model.md s.3).
    ``"offset"``
        Ours: the rest offset ``rho`` of node j is fixed in node i's frame, so the spring
        resists shear as well as stretch, and the orientation spring acts on the exact relative
        rotation ``R_i^T R_j R0^T``; both are invariant under rigid rotations.

    Attributes:
        pair: Node indices ``(i, j)``, ``i != j`` (0 = object). For ``"offset"`` node i's frame
            carries the offset (use the object as i).
        stiffness: Translational stiffness [N/m], scalar or per world axis (3 spatial, 2 planar).
        torsion: Torsion stiffness [N m/rad], scalar or per axis (3 spatial, 1 planar); 0 drops
            the torsion springs.
        damping: Translational damping [N s/m] (along the line for "central", isotropic for
            "offset").
        torsion_damping: Rotational damping [N m s/rad] (see ``damping_form``).
        damping_form: ``"frame_invariant"`` (default, docs/model.md s.3 [ours]): the dampers act on the
            rate of the deformation only, so they do no work when the whole system moves rigidly.
            The offset element damps the rate of its elongation vector in node i's frame,
            ``e_dot = R_i^T (dr_j - dr_i) + rho x omega_i`` (``rho = R_i^T (r_j - r_i)``, ``omega_i``
            in node i's frame), and every element damps the relative angular velocity
            ``R_j^T (omega_j - omega_i)`` (node j's frame). ``"book"`` (110-111): the offset
            element damps ``d I`` on the world velocity difference and the torsion dampers act on
            the Euler-rate difference ``dA_i - dA_j``; both do work under a rigid rotation. The
            central element's line damper is the book's in both forms (it is frame invariant).
        rest_length: Rest distance ``l_ij`` [m]; ``None`` takes it from the reference poses.
        rest_angles: Rest angle difference ``A0_ij`` [rad]; ``None`` = from the reference poses.
        rest_offset: Rest offset ``rho_ij`` [m] in node i's frame; ``None`` = from the reference.
        name: Label used in error messages (``"springs[0]"``).
    """

    pair: tuple[int, int]
    stiffness: float | Sequence[float]
    torsion: float | Sequence[float] = 0.0
    damping: float = 0.0
    torsion_damping: float = 0.0
    element: str = "central"
    damping_form: str = "frame_invariant"
    rest_length: float | None = None
    rest_angles: Sequence[float] | None = None
    rest_offset: Sequence[float] | None = None
    name: str = "interconnection"

    def __post_init__(self):
        n = self.name
        try:
            i, j = (int(k) for k in self.pair)
        except (TypeError, ValueError):
            raise ParameterError(f"{n}.pair", self.pair, "two node indices [i, j]") from None
        if i == j or i < 0 or j < 0:
            raise ParameterError(f"{n}.pair", self.pair, "two different non-negative node indices")
        object.__setattr__(self, "pair", (i, j))
        if self.element not in ELEMENTS:
            raise ParameterError(f"{n}.element", self.element, f"one of {sorted(ELEMENTS)}")
        if self.damping_form not in DAMPING_FORMS:
            raise ParameterError(f"{n}.damping_form", self.damping_form, f"one of {sorted(DAMPING_FORMS)}")
        for field in ("stiffness", "torsion"):
            arr = v.finite_array(f"{n}.{field}", getattr(self, field))
            if np.any(arr < 0):
                raise ParameterError(f"{n}.{field}", getattr(self, field), "values >= 0")
        v.non_negative(f"{n}.damping", self.damping)
        v.non_negative(f"{n}.torsion_damping", self.torsion_damping)
        if self.rest_length is not None:
            v.non_negative(f"{n}.rest_length", self.rest_length)
        if self.rest_angles is not None:
            v.finite_array(f"{n}.rest_angles", self.rest_angles)
        if self.rest_offset is not None:
            v.finite_array(f"{n}.rest_offset", self.rest_offset)
