"""The elastic system's compiled kernels (``plants._core``, ``plants/core/elastic_*.h``) by the names
:class:`plants.elastic.ElasticSystem` and the cooperative plant call them (``elastic_edges``, ``damping_edges``,
``linear_edges``, ``elastic_accelerations``, ...; tests/test_core_elastic.py). Arrays are float64 (edge headers
int64), C-contiguous; outputs are written in place."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from plants import _core

#: 3x3 blocks per node of a ``frames`` array (``NodeFrames``: R, three dR/dA, L, the chart).
NODE_FRAME_BLOCKS = 6


def _spatial_node_frames_charted(Y, node_params):
    """Every node's world frames in its chart, a new (N, NODE_FRAME_BLOCKS, 3, 3) array."""
    frames = np.zeros((Y.shape[0], NODE_FRAME_BLOCKS, 3, 3))
    _core.spatial_node_frames(Y, node_params, frames)
    return frames


def _accelerations(core):
    def elastic_accelerations(Y, dY, Fc, node_params, edge_index, edge_params, gravity, Y_ref, immobile):
        """``(ddY, status)`` of the free elastic system (113) with ``F_0 = 0``."""
        ddY = np.empty_like(Y)
        status = core(Y, dY, Fc, node_params, edge_index, edge_params, gravity, Y_ref, immobile, ddY)
        return ddY, status

    return elastic_accelerations


#: The spatial kernels: ``elastic_edges(Y, edge_index, edge_params, F) -> (Pi, status)`` and
#: ``elastic_edges_framed(..., F, frames)``, ``damping_edges`` and ``damping_edges_framed`` (-> D),
#: ``linear_edges(Y, dY, Y_ref, edge_index, edge_params, F)`` (-> Pi), ``interconnection_terms``,
#: ``elastic_accelerations`` (-> (ddY, status)), ``node_frames_charted``, ``node_rotational_terms``.
spatial = SimpleNamespace(
    elastic_edges=lambda Y, edge_index, edge_params, F: _core.spatial_elastic_edges(Y, edge_index, edge_params, F),
    elastic_edges_framed=_core.spatial_elastic_edges,
    damping_edges=lambda Y, dY, edge_index, edge_params, F: _core.spatial_damping_edges(
        Y, dY, edge_index, edge_params, F),
    damping_edges_framed=_core.spatial_damping_edges,
    linear_edges=_core.spatial_linear_edges,
    interconnection_terms=_core.spatial_interconnection_terms,
    elastic_accelerations=_accelerations(_core.spatial_elastic_accelerations),
    node_frames_charted=_spatial_node_frames_charted,
    node_rotational_terms=_core.node_rotational_terms,
)

#: The planar kernels, as :data:`spatial` without frames.
planar = SimpleNamespace(
    elastic_edges=_core.planar_elastic_edges,
    damping_edges=_core.planar_damping_edges,
    linear_edges=_core.planar_linear_edges,
    interconnection_terms=_core.planar_interconnection_terms,
    elastic_accelerations=_accelerations(_core.planar_elastic_accelerations),
)
