// The QP's real constants and row layout read from a Python object by name (coopctrl/loop/model.py's QPConstants):
// what the tick's binding and the answer check's binding share.
#pragma once

#include <nanobind/nanobind.h>

#include "coopctrl/core/qp_constants.h"

namespace coopctrl::binding {

namespace nb = nanobind;

/// qp.eps_abs [N], qp.mu_c, qp.max_iter, qp.min_grip [N], qp.answer_rho.
inline QPNumbers read_qp_numbers(nb::handle qp) {
    QPNumbers n{};
    n.eps_abs = nb::cast<double>(qp.attr("eps_abs"));
    n.mu_c = nb::cast<double>(qp.attr("mu_c"));
    n.max_iter = static_cast<double>(nb::cast<int64_t>(qp.attr("max_iter")));
    n.min_grip = nb::cast<double>(qp.attr("min_grip"));
    n.answer_rho = nb::cast<double>(qp.attr("answer_rho"));
    return n;
}

/// qp.has_squeeze, qp.min_grip_row, qp.friction_row, qp.torque_row (-1: the family is absent), qp.facets,
/// qp.max_consecutive_failures.
inline QPRows read_qp_rows(nb::handle qp) {
    QPRows r{};
    r.has_squeeze = nb::cast<bool>(qp.attr("has_squeeze")) ? 1 : 0;
    r.min_grip = nb::cast<int64_t>(qp.attr("min_grip_row"));
    r.friction = nb::cast<int64_t>(qp.attr("friction_row"));
    r.torque_limits = nb::cast<int64_t>(qp.attr("torque_row"));
    r.facets = nb::cast<int64_t>(qp.attr("facets"));
    r.max_consecutive_failures = nb::cast<int64_t>(qp.attr("max_consecutive_failures"));
    return r;
}

}  // namespace coopctrl::binding
