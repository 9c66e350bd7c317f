// The spatial elastic system's nodes (docs/model.md s.2-3): their frames in their charts, their inertia and
// gyroscopic terms (105, 113-114), and the solve of one node's rotational block. Ported line by line from
// plants/elastic/_spatial_kernels.py (same expressions, same order: the same bits).
#pragma once

#include "plants/core/elastic_model.h"

namespace plants {

/// Every node k's R(A_k), dR/dA and L(A_k) into frames[k] (N nodes; Y (N, 6) row-major poses (r [m], A [rad])).
void node_frames(const double* Y, int N, NodeFrames* frames) noexcept;

/// Turn every charted node's frames into its world frames, R = C R(A), dR/dA = C dR(A)/dA: rows of
/// SPATIAL_NODE_WIDTH_CHARTED doubles (ChartedSpatialNode); CHART_STORED copies C into frames[k].chart,
/// CHART_OWN reads it from there, CHART_WORLD is left alone.
void apply_charts(const ChartedSpatialNode* nodes, int N, NodeFrames* frames) noexcept;

/// node_frames, then apply_charts when the node rows are charted (node_width == SPATIAL_NODE_WIDTH_CHARTED).
void node_frames_charted(const double* Y, int N, const double* node_rows, int node_width,
                         NodeFrames* frames) noexcept;

/// The rotational inertia Wr = L^T I L (3x3 row-major) [kg m^2] and gyroscopic term
/// g = L^T (I Ldot dA + omega x I omega) [N m] of one node at angles A [rad], rates dA [rad/s], with
/// principal inertia I (3) [kg m^2] (105, 114).
void node_rotational_terms(const double* A, const double* dA, const double* I, double* Wr, double* g) noexcept;

/// Per-node inertia and the non-interconnection part of w (113): Wr (N, 3, 3) and w (N, 6) = (-m g, gyroscopic);
/// the immobile model uses W(Y_ref) and no gyroscopic term. Node rows of node_width doubles (SpatialNode first).
/// Returns ELASTIC_OK.
int node_terms(const double* Y, const double* dY, int N, const double* node_rows, int node_width,
               const double* gravity, const double* Y_ref, bool immobile, double* Wr, double* w) noexcept;

/// node_frames_charted and node_terms of the mobile model in one pass (one evaluation of each node's six sines
/// and cosines); the same bits.
void node_frames_terms(const double* Y, const double* dY, int N, const double* node_rows, int node_width,
                       const double* gravity, NodeFrames* frames, double* Wr, double* w) noexcept;

/// Solve (L^T I L) out = b for one node as out = L^-1 I^-1 L^-T b; false at the Euler singularity
/// (|cos theta| < EULER_SINGULARITY_COS, elastic_rotation.h).
bool solve_node_rotation(const double* A, const double* I, const double* b, double* out) noexcept;

}  // namespace plants
