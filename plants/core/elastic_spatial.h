// The spatial elastic system (docs/model.md s.3, 104-121, 4.5-4.6): every interconnection's forces summed onto
// the nodes, and the free system's accelerations W(Y) Y'' + w(Y, Y') = F (113). Ported line by line from
// plants/elastic/_spatial_kernels.py: the same expressions in the same order, so the same bits.
#pragma once

#include "plants/core/elastic_model.h"

namespace plants {

/// The constants of a spatial elastic system: N nodes, their interconnections, gravity and the reference poses.
struct SpatialElasticModel {
    int node_count;                     ///< N = m + 1 (node 0 the object)
    const double* node_rows;            ///< N rows of node_width doubles: SpatialNode, or ChartedSpatialNode
    int node_width;                     ///< SPATIAL_NODE_WIDTH or SPATIAL_NODE_WIDTH_CHARTED
    Interconnections interconnections;  ///< the edges, rows of SPATIAL_EDGE_WIDTH doubles
    const double* gravity;              ///< (3) [m/s^2]
    const double* Y_ref;                ///< (N, 6) reference poses (r [m], A [rad]) of the unloaded state
    bool immobile;                      ///< the immobile model (4.5): linear about Y_ref
};

/// What elastic accelerations overwrite: node_count NodeFrames, Wr (N, 3, 3), w (N, 6).
struct SpatialElasticWork {
    NodeFrames* frames;
    double* Wr;
    double* w;
};

/// Add dPi/dY (120-121) of every interconnection into F (N, 6) on the nodes' world frames (NodeFrames, their
/// charts applied); Pi [J] into *Pi. Returns ELASTIC_OK or ELASTIC_COINCIDENT_NODES (then F and *Pi are partial).
int spatial_elastic_edges(const Interconnections& ic, const double* Y, const NodeFrames* frames, double* F,
                          double* Pi) noexcept;

/// Add dD/d(dY) of the dampers (110-111) into F (N, 6); returns the Rayleigh function D [W/2].
double spatial_damping_edges(const Interconnections& ic, const double* Y, const double* dY,
                             const NodeFrames* frames, double* F) noexcept;

/// The immobile model (4.5): add K y + D dy of every interconnection into F (N, 6), y = Y - Y_ref; returns Pi [J].
double spatial_linear_edges(const Interconnections& ic, const double* Y, const double* dY, const double* Y_ref,
                            double* F) noexcept;

/// Add every interconnection's part of w (113) into w (N, 6): dPi/dY + dD/d(dY) on the book's world frames of
/// the N nodes (written into frames), or the immobile model's K y + D dy. Returns a status.
int spatial_interconnection_terms(const Interconnections& ic, int N, const double* Y, const double* dY,
                                  const double* Y_ref, bool immobile, double* w, NodeFrames* frames) noexcept;

/// ddY (N, 6) of the free elastic system W(Y) ddY + w(Y, dY) = F (113), F_0 = 0: Fc (N, 6) the generalized
/// contact forces on the nodes (row 0 ignored); Y in the nodes' charts. Returns a status (ddY is zero, or
/// partial at an Euler singularity, when it is not ELASTIC_OK).
int spatial_elastic_accelerations(const SpatialElasticModel& model, const double* Y, const double* dY,
                                  const double* Fc, double* ddY, const SpatialElasticWork& work) noexcept;

}  // namespace plants
