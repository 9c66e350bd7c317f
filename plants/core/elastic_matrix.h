// The matrix (and beam) elements (docs/model.md s.3 [ours]): co-rotational, node i clamped in the element
// frame, spatial and planar, and their linearization in the immobile model (4.5). Ported line by line from
// plants/elastic/_spatial_kernels.py (matrix_edge, linear_matrix_edge) and _planar_kernels.py (matrix_edge).
#pragma once

#include "plants/core/elastic_model.h"

namespace plants {

/// One spatial matrix element between nodes i and j. The element frame turns with node i, R_e = R_i M; node j's
/// deformation in it is u = R_e^T (r_j - r_i) - u0, theta = log(R_e^T R_j N), Pi = 1/2 d^T K_jj d, d = (u, theta);
/// dPi/dr_j = R_e g_u = -dPi/dr_i, dPi/dA_i = L_i^T M (g_u x p - Q h), dPi/dA_j = L_j^T N h (g = K_jj d,
/// h = J_r^-T(theta) g_theta). rates: the dampers instead, d_dot = G v and g = C_jj d_dot. Adds into F (N, 6);
/// returns Pi [J] (or D [W/2]).
double spatial_matrix_element(const SpatialMatrixElement& m, int i, int j, const double* Y, const double* dY,
                              const NodeFrames* frames, double* F, bool rates) noexcept;

/// One planar matrix element: theta_e = theta_i + alpha, u = R_e^T (r_j - r_i) - u0, theta = theta_j - theta_i -
/// beta (wrapped), Pi = 1/2 d^T K_jj d; rates: the dampers. Adds into F (N, 3); returns Pi [J] (or D [W/2]).
double planar_matrix_element(const PlanarMatrixElement& m, int i, int j, const double* Y, const double* dY,
                             double* F, bool rates) noexcept;

/// A matrix element in the immobile model (4.5): y = (Y_i - Y_ref_i, Y_j - Y_ref_j) (n coordinates per node,
/// angles from coordinate angles_from on wrapped); adds K_lin y + D_lin dy into F and returns 1/2 y^T K_lin y.
/// K_lin and D_lin are 2n x 2n row-major.
double linear_matrix_element(const double* K_lin, const double* D_lin, int n, int angles_from, int i, int j,
                             const double* Y, const double* dY, const double* Y_ref, double* F) noexcept;

}  // namespace plants
