// The elastic split's QP inputs, which the tick fills (LoadDistributionProblem takes any K in Python):
// K = blockdiag_i sym(R_b K_i R_b^T), the external part K G^T (G K G^T)^{-1} w_N and P = sym(K^{-1}).
#pragma once

namespace coopctrl {

/// Result codes of fill_elastic_split.
enum ElasticSplitCode : int {
    ELASTIC_OK = 0,
    ELASTIC_DEGENERATE_GRASP = -1,  ///< G K G^T is not positive definite
    ELASTIC_SINGULAR_STIFFNESS = -3,  ///< a block of K is singular
};

/// The elastic split's arrays: the constants read and the arrays written (all row-major).
struct ElasticSplit {
    int m;                 ///< arms
    int p;                 ///< pose components per node (6 spatial, 3 planar); n = m p
    int k;                 ///< balance rows (rows of G = M[:k])
    const double* M;       ///< (>= k, ldM) the stacked rows; G = M[:k]
    int ldM;
    const double* K_obj;   ///< (m, p, p) object-frame grasp stiffnesses [N/m, N m/rad]
    const double* Y0;      ///< (p) nominal object pose [m, rad]
    const double* w;       ///< (k) the load w_N [N, N m]
    double* K;             ///< (n, n) world-frame stiffness (holds the previous call's: P is redone when K changes)
    double* P;             ///< (n, n) the cost's Hessian sym(K^{-1})
    double* external;      ///< (n) K G^T (G K G^T)^{-1} w_N [N, N m]
    double* KGt;           ///< (n, ldKGt) scratch, K G^T
    int ldKGt;
    double* A;             ///< (k, ldA) scratch, G K G^T
    int ldA;
    double* y;             ///< (k) scratch
    double* Rb;            ///< (p, p) scratch, blockdiag(R_0, R_0) spatial, the planar rotation otherwise
    double* work;          ///< (p, 2 p) scratch
};

/// Fill K, P and external at the nominal object pose. Returns the code (ElasticSplitCode); *P_changed is true
/// when K changed since the last call with these arrays (P recomputed).
int fill_elastic_split(ElasticSplit& e, bool spatial, bool* P_changed) noexcept;

}  // namespace coopctrl
