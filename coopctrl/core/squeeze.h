// The virtual-linkage squeeze of one tick (coopctrl/loop/squeeze.py's pair_squeeze_into, line by line: the same
// bits): the pair tensions [N] of the contact wrenches' internal part on the squeeze basis,
//     s = s_des + E^+ (F - E s_des)
// (qp_tensions.h's pair_tensions on the columns of qp_assembly.h's fill_squeeze_basis; docs/model.md section 6).
#pragma once

namespace coopctrl {

/// The squeeze's per-run arrays (squeeze.py's SqueezeWork, field for field), for m contacts of npos coordinates,
/// R = m npos force rows and P = m (m - 1) / 2 pairs.
struct SqueezeWork {
    const double* desired;  ///< (P,) the desired squeeze per pair [N]
    double* E;              ///< (R, P) the pair columns' force rows
    double* W;              ///< (R, P), or (P, R) when P > R: the rotated columns
    double* V;              ///< (min(R, P), min(R, P)) the rotations
    double* sigma;          ///< (min(R, P),) the singular values [-]
};

/// The squeeze s (P,) [N] of the wrenches F (m, p) [N, N m] (p >= npos: the force entries first) at the contacts
/// r (m, npos) [m] into out. NaN where F or r is not finite, two contacts coincide or the pairs are
/// ill-conditioned; nothing for fewer than two contacts.
void pair_squeeze(const double* r, int m, int npos, const double* F, int p, SqueezeWork& work,
                  double* out) noexcept;

}  // namespace coopctrl
