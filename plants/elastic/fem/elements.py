"""Elements between two nodes of an elastic structure, each with its stiffness ``K_e^i`` (47) in
its own frame and the rotation from that frame to the world.

- :class:`BeamElement`: a prismatic beam (Euler-Bernoulli, or Timoshenko with ``shear=True``) whose
  length and axis are the line between its nodes' rest positions, optionally divided by
  ``internal_nodes`` equally spaced massless nodes: the book's kinematically indeterminate
  quantities ``k`` (50), eliminated by (53)-(54) in :mod:`plants.elastic.fem.assembly`.
- :class:`MatrixElement`: a user's symmetric stiffness matrix (12x12 spatial, 6x6 planar) in the
  frame ``frame_rotation`` (default: local x along the line between the nodes).

Displacements of a node in the world: spatial ``(x, y, z, rx, ry, rz)`` (translations [m], small
rotations [rad] about the world axes); planar ``(x, z, theta)`` (docs/model.md s.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from plants.elastic.fem.beam_element import planar_beam_stiffness, spatial_beam_stiffness


def line_frame(p_a: np.ndarray, p_b: np.ndarray) -> np.ndarray:
    """Rotation (3x3, columns the local axes in the world) of the frame whose x axis runs from
    ``p_a`` to ``p_b`` [m]; local y is horizontal (``world z x local x``), or along world y when
    the line is vertical."""
    d = np.asarray(p_b, float) - np.asarray(p_a, float)
    length = float(np.linalg.norm(d))
    if not length > 0.0:
        raise ValueError(f"element length = {length!r} m is invalid: the two nodes' rest positions coincide")
    ex = d / length
    ref = np.array([0.0, 0.0, 1.0]) if abs(ex[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    ey = np.cross(ref, ex)
    ey /= np.linalg.norm(ey)
    return np.column_stack((ex, ey, np.cross(ex, ey)))


def world_to_local(rotation: np.ndarray, planar: bool) -> np.ndarray:
    """The matrix taking one node's world displacements into the element frame: ``blockdiag(R^T,
    R^T)`` (6x6) in space, the in-plane rotation by the line's angle (3x3) in the plane."""
    if planar:
        c, s = rotation[0, 0], rotation[1, 0]
        return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    T = np.zeros((6, 6))
    T[:3, :3] = T[3:, 3:] = rotation.T
    return T


def _planar_rotation(p_a: np.ndarray, p_b: np.ndarray) -> np.ndarray:
    d = np.asarray(p_b, float) - np.asarray(p_a, float)
    length = float(np.hypot(d[0], d[1]))
    if not length > 0.0:
        raise ValueError(f"element length = {length!r} m is invalid: the two nodes' rest positions coincide")
    c, s = d[0] / length, d[1] / length
    return np.array([[c, -s], [s, c]])


@dataclass(frozen=True)
class BeamElement:
    """A beam between structure nodes ``nodes = (a, b)`` with section ``E`` [Pa], ``G`` [Pa],
    ``A`` [m^2], ``Iy``, ``Iz``, ``J`` [m^4] (planar: ``Iy`` is the bending moment of area, ``Iz``
    and ``J`` unused), ``internal_nodes`` >= 0 equally spaced massless nodes."""

    nodes: tuple[int, int]
    E: float
    G: float
    A: float
    Iy: float
    Iz: float
    J: float
    shear: bool = False
    internal_nodes: int = 0
    kappa: float = 5.0 / 6.0

    def __post_init__(self) -> None:
        _check_nodes(self.nodes)
        if not (isinstance(self.internal_nodes, int) and 0 <= self.internal_nodes <= 64):
            raise ValueError(f"internal_nodes = {self.internal_nodes!r} is invalid: expected an integer from 0 to 64")
        for name in ("E", "G", "A", "Iy", "Iz", "J", "kappa"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} = {value!r} is invalid: expected a finite number > 0")

    def pieces(self, p_a: np.ndarray, p_b: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """The stiffness (own frame) and frame rotation of each of the ``internal_nodes + 1``
        equal pieces between the rest positions ``p_a`` and ``p_b``."""
        planar = len(p_a) == 2
        rotation = _planar_rotation(p_a, p_b) if planar else line_frame(p_a, p_b)
        length = float(np.linalg.norm(np.asarray(p_b, float) - np.asarray(p_a, float))) / (self.internal_nodes + 1)
        if planar:
            K = planar_beam_stiffness(self.E, self.A, self.Iy, length, G=self.G, shear=self.shear, kappa=self.kappa)
        else:
            K = spatial_beam_stiffness(self.E, self.G, self.A, self.Iy, self.Iz, self.J, length,
                                       shear=self.shear, kappa=self.kappa)
        return [(K, rotation)] * (self.internal_nodes + 1)


@dataclass(frozen=True)
class MatrixElement:
    """A symmetric positive semi-definite stiffness ``K`` (12x12 spatial, 6x6 planar) between
    ``nodes = (a, b)`` in the frame ``frame_rotation`` (3x3, its columns the element axes in the
    world; planar: 2x2 in the x-z plane; default: x along the line between the nodes)."""

    nodes: tuple[int, int]
    K: np.ndarray
    frame_rotation: np.ndarray | None = field(default=None)

    def __post_init__(self) -> None:
        _check_nodes(self.nodes)
        K = np.asarray(self.K, dtype=float)
        if K.shape not in ((12, 12), (6, 6)) or not np.all(np.isfinite(K)):
            raise ValueError(f"K of shape {K.shape} is invalid: expected finite 12x12 (spatial) or 6x6 (planar) [SI]")
        scale = float(np.max(np.abs(K))) or 1.0
        if not np.allclose(K, K.T, rtol=0.0, atol=1e-12 * scale):
            raise ValueError("K is invalid: expected a symmetric matrix (K = K^T to 1e-12 of its largest entry)")
        if float(np.min(np.linalg.eigvalsh(0.5 * (K + K.T)))) < -1e-10 * scale:
            raise ValueError("K is invalid: expected a positive semi-definite matrix (it has a negative eigenvalue)")
        object.__setattr__(self, "K", 0.5 * (K + K.T))
        if self.frame_rotation is not None:
            R = np.asarray(self.frame_rotation, dtype=float)
            n = 2 if K.shape == (6, 6) else 3
            if R.shape != (n, n) or not np.allclose(R.T @ R, np.eye(n), atol=1e-9) or np.linalg.det(R) < 0:
                raise ValueError(f"frame_rotation is invalid: expected a {n}x{n} rotation matrix")
            object.__setattr__(self, "frame_rotation", R)

    @property
    def internal_nodes(self) -> int:
        return 0

    def pieces(self, p_a: np.ndarray, p_b: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        planar = len(p_a) == 2
        if (self.K.shape == (6, 6)) != planar:
            raise ValueError(f"K of shape {self.K.shape} is invalid for a {'planar' if planar else 'spatial'} structure")
        rotation = self.frame_rotation
        if rotation is None:
            rotation = _planar_rotation(p_a, p_b) if planar else line_frame(p_a, p_b)
        return [(self.K, rotation)]


def _check_nodes(nodes) -> None:
    if (not isinstance(nodes, tuple) or len(nodes) != 2 or not all(isinstance(n, int) and n >= 0 for n in nodes)
            or nodes[0] == nodes[1]):
        raise ValueError(f"nodes = {nodes!r} is invalid: expected two different node indices (a, b) >= 0")
