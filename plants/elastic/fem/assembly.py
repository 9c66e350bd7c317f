"""The stiffness of an elastic structure assembled as the book writes it (47)-(59).

For elements ``i`` with own-frame stiffness ``K_e^i`` (47) and displacements ``Delta_e^i``:

    K_e     = diag(K_e^1, K_e^2, ...)                                  (48)
    Delta_e = a_0 Delta + a_1 k                                        (49), (50)
    k       = -(a_1^T K_e a_1)^-1 a_1^T K_e a_0 Delta                  (53)
    a       = a_0 - a_1 (a_1^T K_e a_1)^-1 a_1^T K_e a_0               (54)
    K       = a^T K_e a                                                (56)-(59)

``Delta`` stacks the structure nodes' world displacements (``d`` per node: 6 spatial, 3 planar,
see :mod:`plants.elastic.fem.elements`), ``k`` those of the elements' massless internal nodes:
the kinematically indeterminate quantities, chosen by virtual work (52) so that no force acts on
them. ``a_0`` and ``a_1`` hold, per element piece, the rotation of its two end points'
displacements into the piece's frame. With no internal node, ``a = a_0`` (a statically
determinate connection, (49)).

:func:`direct_stiffness` is the independent check: the classical direct-stiffness method, which
adds ``T_i^T K_e^i T_i`` into the global matrix at the pieces' nodes, with the internal nodes kept
as nodes of their own (their elimination is then a linear solve of the whole system).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plants.elastic.fem.elements import world_to_local


@dataclass(frozen=True)
class StiffnessAssembly:
    """The book's matrices for one structure of ``n`` nodes, ``d`` displacements per node
    (``K`` is ``n d`` x ``n d`` [N/m, N, N m])."""

    K_e: np.ndarray
    a_0: np.ndarray
    a_1: np.ndarray
    a: np.ndarray
    K: np.ndarray

    def __repr__(self) -> str:
        return (f"StiffnessAssembly(K {self.K.shape[0]}x{self.K.shape[1]}, K_e {self.K_e.shape[0]}x{self.K_e.shape[1]}, "
                f"{self.a_1.shape[1]} kinematically indeterminate quantities)")


def _points(element, rest_positions: np.ndarray) -> list[tuple[str, int, np.ndarray]]:
    """The element's end and internal points in order: ('node', index, position) or
    ('internal', j, position) with j counted within the element."""
    a, b = element.nodes
    p_a, p_b = rest_positions[a], rest_positions[b]
    n = element.internal_nodes
    inner = [("internal", j, p_a + (p_b - p_a) * (j + 1) / (n + 1)) for j in range(n)]
    return [("node", a, p_a), *inner, ("node", b, p_b)]


def _check(elements, rest_positions) -> tuple[np.ndarray, int]:
    P = np.asarray(rest_positions, dtype=float)
    if P.ndim != 2 or P.shape[1] not in (2, 3) or not np.all(np.isfinite(P)):
        raise ValueError(f"rest_positions of shape {P.shape} is invalid: expected finite (n, 3) spatial or (n, 2) "
                         "planar (x, z) positions [m]")
    for e in elements:
        if max(e.nodes) >= len(P):
            raise ValueError(f"nodes = {e.nodes!r} is invalid: the structure has {len(P)} nodes (0 to {len(P) - 1})")
    return P, 6 if P.shape[1] == 3 else 3


def stiffness_assembly(elements, rest_positions, node_maps=None) -> StiffnessAssembly:
    """``K_e``, ``a_0``, ``a_1``, ``a`` and ``K = a^T K_e a`` (48)-(59) of the structure whose nodes
    rest at ``rest_positions`` [m] ((n, 3); planar (n, 2) as (x, z)) joined by ``elements``.

    ``node_maps`` (optional, one d x d matrix per node) takes ``Delta`` from other coordinates of
    the nodes to their world displacements (the plant's Euler-angle coordinates: ``blockdiag(I,
    R(A) L(A))``), so that ``K`` is in those coordinates."""
    P, d = _check(elements, rest_positions)
    maps = [np.eye(d)] * len(P) if node_maps is None else [np.asarray(T, dtype=float) for T in node_maps]
    blocks, rows_0, rows_1 = [], [], []
    n_internal = 0
    for element in elements:
        points = _points(element, P)
        for (K_i, rotation), start, end in zip(element.pieces(P[element.nodes[0]], P[element.nodes[1]]),
                                               points[:-1], points[1:]):
            T = world_to_local(rotation, planar=d == 3)
            blocks.append(K_i)
            r0 = np.zeros((2 * d, len(P) * d))
            r1 = np.zeros((2 * d, max(element.internal_nodes, 0) * d))
            for half, (kind, index, _) in enumerate((start, end)):
                if kind == "node":
                    r0[half * d:(half + 1) * d, index * d:(index + 1) * d] = T @ maps[index]
                else:
                    r1[half * d:(half + 1) * d, index * d:(index + 1) * d] = T
            rows_0.append(r0)
            rows_1.append((n_internal, r1))
        n_internal += element.internal_nodes
    K_e = _block_diagonal(blocks)
    a_0 = np.vstack(rows_0) if rows_0 else np.zeros((0, len(P) * d))
    a_1 = np.zeros((a_0.shape[0], n_internal * d))
    row = 0
    for offset, r1 in rows_1:
        a_1[row:row + r1.shape[0], offset * d:offset * d + r1.shape[1]] = r1
        row += r1.shape[0]
    if n_internal:
        # (53)-(54): the internal nodes carry no force, a_1^T K_e (a_0 Delta + a_1 k) = 0
        k_of_delta = -np.linalg.solve(a_1.T @ K_e @ a_1, a_1.T @ K_e @ a_0)
        a = a_0 + a_1 @ k_of_delta
    else:
        a = a_0.copy()
    K = a.T @ K_e @ a
    return StiffnessAssembly(K_e=K_e, a_0=a_0, a_1=a_1, a=a, K=0.5 * (K + K.T))


def direct_stiffness(elements, rest_positions) -> tuple[np.ndarray, int]:
    """The direct-stiffness matrix over the structure nodes followed by every internal node (in
    the order of ``elements``), and the number of structure-node displacements it begins with."""
    P, d = _check(elements, rest_positions)
    n_internal = sum(e.internal_nodes for e in elements)
    size = (len(P) + n_internal) * d
    K = np.zeros((size, size))
    offset = len(P)
    for element in elements:
        points = _points(element, P)
        slots = [index if kind == "node" else offset + index for kind, index, _ in points]
        for (K_i, rotation), s, t in zip(element.pieces(P[element.nodes[0]], P[element.nodes[1]]), slots[:-1], slots[1:]):
            T = world_to_local(rotation, planar=d == 3)
            dofs = np.r_[s * d:(s + 1) * d, t * d:(t + 1) * d]
            T2 = np.zeros((2 * d, 2 * d))
            T2[:d, :d] = T2[d:, d:] = T
            K[np.ix_(dofs, dofs)] += T2.T @ K_i @ T2
        offset += element.internal_nodes
    return K, len(P) * d


def _block_diagonal(blocks: list[np.ndarray]) -> np.ndarray:
    size = sum(b.shape[0] for b in blocks)
    out = np.zeros((size, size))
    i = 0
    for b in blocks:
        out[i:i + b.shape[0], i:i + b.shape[0]] = b
        i += b.shape[0]
    return out
