#include "coopctrl/core/qp_constants.h"

#include "coopctrl/core/qp_answer_check.h"

namespace coopctrl {

bool qp_answer_check(const QPConstants& c, const QP& qp, const double* x, const double* z, int m,
                     int64_t* families) noexcept {
    *families = 0;
    if (!answer_ok(qp.M, qp.n, qp.n_rows, qp.lo, qp.hi, x, qp.n, qp.n_eq, c.numbers.eps_abs, c.numbers.answer_rho))
        return false;
    const QPRows& rows = c.rows;
    *families = binding_families(qp.g, z, qp.n_eq, qp.n, qp.n_rows - qp.n_eq, m, rows.min_grip, rows.friction,
                                 rows.facets, rows.torque_limits);
    return true;
}

}  // namespace coopctrl
