// The spatial springs and dampers of one interconnection (docs/model.md s.3, 106-111, 119-121): the central
// element (the book's), the offset element (ours), the geodesic rotation form and the dampers of both, and the
// immobile model's vector springs (4.5). Each adds its generalized forces into F (N, 6) and its energy into an
// accumulator, in the order of plants/elastic/_spatial_kernels.py (elastic_edges_into, damping_edges_into,
// linear_edges), so the sums round as there.
#pragma once

#include "plants/core/elastic_model.h"

namespace plants {

/// Nodes of a central spring with positive rest length closer than this fraction of it are coincident.
constexpr double COINCIDENT_FRACTION = 1e-9;

/// The central element between nodes i and j (106-107, 119): d = r_i - r_j, s = |d|, g = 1 - l/s, beta = g^2,
/// Q = sum_k c_k d_k^2, Pi = 1/2 beta Q + its rotation spring; dPi/dr_i = g l Q d / s^3 + g^2 C d. Adds into Pi
/// [J] and F; returns ELASTIC_COINCIDENT_NODES (adding nothing more) when s < COINCIDENT_FRACTION l.
int central_spring(const SpatialSpring& s, int i, int j, const double* Y, const NodeFrames* frames, double* F,
                   double& Pi) noexcept;

/// The offset element (ours): e = R_i^T (r_j - r_i) - rho, Pi = 1/2 e^T C e + sum_k kappa_k (1 - M_kk),
/// M = R_i^T R_j R0^T (book rotation form), or the geodesic rotation spring. Adds into Pi [J] and F.
void offset_spring(const SpatialSpring& s, int i, int j, const double* Y, const NodeFrames* frames, double* F,
                   double& Pi) noexcept;

/// The geodesic rotation spring (ROTATION_GEODESIC): Delta = R_i^T R_j R0^T, e = log(Delta),
/// Pi = 1/2 e^T C_A e with C_A = diag(cA_phi, cA_theta, cA_psi); tau_j = R0^T h, tau_i = -Delta h,
/// h = J_r^-T(e) C_A e, dPi/dA_k = L_k^T tau_k. Adds into F; returns its energy [J].
double geodesic_rotation(const SpatialSpring& s, int i, int j, const NodeFrames* frames, double* F) noexcept;

/// The dampers of a central or offset element (110-111): the book's line damper (central), the offset's
/// frame-invariant e_dot damper or the book's d I, and the torsion dampers on omega_rel (frame invariant) or on
/// the Euler rates (book). Adds into D [W/2] and F.
void spring_dampers(const SpatialSpring& s, const ElasticEdge& edge, const double* Y, const double* dY,
                    const NodeFrames* frames, double* F, double& D) noexcept;

/// The immobile model's vector springs and dampers (4.5): K_ij = diag(c, cA), D_ij = diag(d I3, dA I3) on
/// y = Y - Y_ref (angles wrapped). Adds K y + D dy into F and 1/2 y^T K y into Pi.
void linear_spring(const SpatialSpring& s, int i, int j, const double* Y, const double* dY, const double* Y_ref,
                   double* F, double& Pi) noexcept;

}  // namespace plants
