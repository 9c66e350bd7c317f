// The planar elastic system (docs/model.md s.2-3, planar reduction): poses (x, z, theta) in the vertical x-z
// plane, L = 1, W = diag(m, m, I) constant, no gyroscopic term. Every interconnection's forces summed onto the
// nodes and the free system's accelerations, ported line by line from plants/elastic/_planar_kernels.py.
#pragma once

#include "plants/core/elastic_model.h"

namespace plants {

/// The constants of a planar elastic system.
struct PlanarElasticModel {
    int node_count;                     ///< N = m + 1 (node 0 the object)
    const PlanarNode* nodes;            ///< N nodes
    Interconnections interconnections;  ///< the edges, rows of PLANAR_EDGE_WIDTH doubles
    const double* gravity;              ///< (g_x, g_z) [m/s^2]
    const double* Y_ref;                ///< (N, 3) reference poses [m, rad]
    bool immobile;                      ///< the immobile model (4.5)
};

/// Add dPi/dY of every interconnection into F (N, 3); Pi [J] into *Pi. Central: Pi = 1/2 beta (c_x d_x^2 +
/// c_z d_z^2) + 1/2 cA delta^2, d = r_i - r_j, beta = (1 - l/|d|)^2, delta = theta_i - theta_j - A0; offset:
/// e = R(theta_i)^T (r_j - r_i) - rho, Pi = 1/2 e^T C e + 1/2 cA delta^2. Returns a status.
int planar_elastic_edges(const Interconnections& ic, const double* Y, double* F, double* Pi) noexcept;

/// Add dD/d(dY) (110-111) into F (N, 3); returns the Rayleigh function D [W/2].
double planar_damping_edges(const Interconnections& ic, const double* Y, const double* dY, double* F) noexcept;

/// The immobile model (4.5): add K y + D dy into F (N, 3); returns Pi [J].
double planar_linear_edges(const Interconnections& ic, const double* Y, const double* dY, const double* Y_ref,
                           double* F) noexcept;

/// Add every interconnection's part of w into w (N, 3); returns a status.
int planar_interconnection_terms(const Interconnections& ic, const double* Y, const double* dY,
                                 const double* Y_ref, bool immobile, double* w) noexcept;

/// ddY (N, 3) of the free planar system W ddY + w = F, F_0 = 0 (Fc row 0 ignored); w (N, 3) is overwritten.
/// Returns a status (ddY zero when it is not ELASTIC_OK).
int planar_elastic_accelerations(const PlanarElasticModel& model, const double* Y, const double* dY,
                                 const double* Fc, double* ddY, double* w) noexcept;

}  // namespace plants
