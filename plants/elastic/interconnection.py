"""An elastic interconnection between two nodes: springs and dampers (docs/model.md s.3, 106-111)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from plants import _validation as v
from plants.elastic._layout import DAMPING_FORMS, ELEMENTS, ROTATION_FORMS
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
        rotation_form: The rotational spring of a spatial ``"central"`` or ``"offset"`` element.
            ``"book"`` (default this release): the central element's torsion springs on the Euler
            difference ``A_i - A_j - A0`` (106-107; it depends on the angles' chart and is singular
            where they are), the offset element's ``kappa`` form. ``"geodesic"`` (docs/model.md s.3
            [ours]): ``1/2 e^T C_A e`` on the relative rotation vector ``e = log(R_i^T R_j R0^T)``
            (node i's frame, ``R0`` the rest relative rotation, ``C_A = diag(cA_phi, cA_theta,
            cA_psi)``: the book's ``torsion`` per ``(psi, theta, phi)`` is about z, y, x), exact
            gradient; it depends on the rotations only, so it allows rotation charts
            (:class:`plants.elastic.ElasticSystem` ``charts``). Matrix and beam elements are always
            on the exact relative rotation (either value). The immobile model (4.5) is the book's
            linear model whatever the form.
        rest_length: Rest distance ``l_ij`` [m]; ``None`` takes it from the reference poses.
        rest_angles: Rest angle difference ``A0_ij`` [rad]; ``None`` = from the reference poses.
        rest_offset: Rest offset ``rho_ij`` [m] in node i's frame; ``None`` = from the reference.
        name: Label used in error messages (``"springs[0]"``).
        matrix: ``element="matrix"``: the element's stiffness (12x12 spatial, 6x6 planar) on the
            displacements ``(u, v, w, rx, ry, rz)`` of node i then node j in the element frame
            [N/m, N, N m/rad]: symmetric, positive semi-definite, with the element's rigid-body
            motions in its null space (a free element, as :mod:`plants.elastic.fem` builds them).
            The plant uses it co-rotationally (docs/model.md s.3): exact under large rigid
            motions, and exactly this matrix in the immobile model.
        matrix_damping: ``element="matrix"``: an optional damping matrix of the same shape and
            conditions [N s/m, N s, N m s/rad], on the rates of the same displacements (frame
            invariant).
        frame: ``element="matrix"``: the element frame at rest, a rotation (3x3 spatial, 2x2
            planar; its columns the element axes in the world); ``None``: x along the line from
            node i to node j (:func:`plants.elastic.fem.line_frame`).
        beam: ``element="beam"``: a :class:`plants.elastic.fem.BeamElement` (its section and
            internal nodes; its ``nodes`` are this pair). Its length and axis are the line between
            the nodes at rest; the plant uses its element matrix, internal nodes condensed by
            (53)-(54), as a matrix element.
        rayleigh_damping: ``element="matrix"`` or ``"beam"``: ``beta`` [s] of the damping matrix
            ``beta K`` when ``matrix_damping`` is not given.
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
    matrix: Sequence[Sequence[float]] | None = None
    matrix_damping: Sequence[Sequence[float]] | None = None
    frame: Sequence[Sequence[float]] | None = None
    beam: object | None = None
    rayleigh_damping: float = 0.0
    rotation_form: str = "book"

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
        if self.rotation_form not in ROTATION_FORMS:
            raise ParameterError(f"{n}.rotation_form", self.rotation_form, f"one of {sorted(ROTATION_FORMS)}")
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
        v.non_negative(f"{n}.rayleigh_damping", self.rayleigh_damping)
        if self.element == "beam":
            from plants.elastic.fem import BeamElement

            if not isinstance(self.beam, BeamElement):
                raise ParameterError(f"{n}.beam", type(self.beam).__name__, "a plants.elastic.fem.BeamElement with element = 'beam'")
            if self.damping_form != "frame_invariant":
                raise ParameterError(f"{n}.damping_form", self.damping_form, "'frame_invariant' for a beam element")
        elif self.beam is not None:
            raise ParameterError(f"{n}.beam", "given", f"only with element = 'beam' (element is {self.element!r})")
        if self.element == "matrix":
            if self.matrix is None:
                raise ParameterError(f"{n}.matrix", None, "a 12x12 (spatial) or 6x6 (planar) stiffness matrix with element = 'matrix'")
            if self.damping_form != "frame_invariant":
                raise ParameterError(f"{n}.damping_form", self.damping_form,
                                     "'frame_invariant' for a matrix element (its dampers act on the deformation rates)")
            K = _element_matrix(f"{n}.matrix", self.matrix)
            object.__setattr__(self, "matrix", _frozen(K))
            if self.matrix_damping is not None:
                C = _element_matrix(f"{n}.matrix_damping", self.matrix_damping)
                if C.shape != K.shape:
                    raise ParameterError(f"{n}.matrix_damping", C.shape, f"the shape of matrix, {K.shape}")
                object.__setattr__(self, "matrix_damping", _frozen(C))
            if self.frame is not None:
                R = v.finite_array(f"{n}.frame", self.frame)
                size = 3 if K.shape == (12, 12) else 2
                if R.shape != (size, size) or not np.allclose(R.T @ R, np.eye(size), atol=1e-9) or np.linalg.det(R) < 0:
                    raise ParameterError(f"{n}.frame", np.shape(self.frame), f"a {size}x{size} rotation matrix (orthonormal, det +1)")
                object.__setattr__(self, "frame", _frozen(R))
        else:
            for field in ("matrix", "matrix_damping", "frame"):
                if getattr(self, field) is not None:
                    raise ParameterError(f"{n}.{field}", "given", f"only with element = 'matrix' (element is {self.element!r})")


def _frozen(a: np.ndarray) -> tuple:
    """A matrix as nested tuples (hashable, as a frozen dataclass's fields should be)."""
    return tuple(tuple(float(x) for x in row) for row in a)


def _element_matrix(name: str, value) -> np.ndarray:
    """A finite, symmetric, positive semi-definite 12x12 or 6x6 matrix, or ParameterError."""
    K = v.finite_array(name, value)
    if K.shape not in ((12, 12), (6, 6)):
        raise ParameterError(name, K.shape, "a 12x12 (spatial) or 6x6 (planar) matrix")
    scale = float(np.max(np.abs(K))) or 1.0
    if not np.allclose(K, K.T, rtol=0.0, atol=1e-12 * scale):
        raise ParameterError(name, "not symmetric", "a symmetric matrix (K = K^T to 1e-12 of its largest entry)")
    if float(np.linalg.eigvalsh(0.5 * (K + K.T))[0]) < -1e-10 * scale:
        raise ParameterError(name, "indefinite", "a positive semi-definite matrix (it has a negative eigenvalue)")
    return 0.5 * (K + K.T)
