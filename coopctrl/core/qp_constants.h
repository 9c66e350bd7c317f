// The load-distribution QP's constants of a run, by name: the loop's QPConstants (coopctrl/loop/model.py), read
// field by field (qp_constants_reader.h).
#pragma once

#include <cstdint>

#include "coopctrl/core/goldfarb_idnani.h"

namespace coopctrl {

/// The QP's real constants.
struct QPNumbers {
    double eps_abs;     ///< [N] the solver's primal feasibility tolerance (violation / row norm)
    double mu_c;        ///< [-] friction coefficient of the inscribed pyramid, mu cos(pi / facets) (planar: mu)
    double max_iter;    ///< [-] the solver's iteration limit (a whole number)
    double min_grip;    ///< [N] the least normal force of the min_grip rows (0 when the family is off)
    double answer_rho;  ///< [-] the fraction of the load an answer may miss (ANSWER_TOLERANCE_OF_LOAD)
};

/// The QP's row layout: a family's first row, -1 where it is absent. Rows count from the first inequality row
/// (after the k balance rows).
struct QPRows {
    int64_t has_squeeze;               ///< 1 if the preferred split has a desired squeeze
    int64_t min_grip;                  ///< first min_grip row (m rows)
    int64_t friction;                  ///< first friction row (facets rows per contact)
    int64_t torque_limits;             ///< first torque_limits row (one per joint)
    int64_t facets;                    ///< friction rows per contact (2 planar)
    int64_t max_consecutive_failures;  ///< failed solves in a row before the run stops
};

/// The QP's constants of a run (QPConstants), by name.
struct QPConstants {
    int n;                     ///< contact wrench entries (k m)
    int nu;                    ///< joints of all arms
    int pairs;                 ///< squeeze pairs
    const double* W_diag;      ///< (n) weights of the contact wrenches
    const double* W_inv_diag;  ///< (n) their inverses
    const double* s_des;       ///< (pairs) desired squeeze [N]
    const double* tau_qp;      ///< (nu) joint torque limits of the torque_limits rows [N m]
    const double* tau_max;     ///< (nu) saturation limits [N m]
    const double* cos_phi;     ///< (facets) the friction pyramid's facet directions (spatial; one zero planar)
    const double* sin_phi;     ///< (facets)
    QPNumbers numbers;         ///< the real constants
    QPRows rows;               ///< the row layout
};

/// The check of a solved QP (tick.h's solve_split after the solve): whether the answer
/// x (qp.n) passes answer_ok with the constants' eps_abs and answer_rho, and if so *families, the mask of the
/// binding families of the multipliers z (qp.n_rows, the solver's: balance rows first) on the m contacts.
bool qp_answer_check(const QPConstants& c, const QP& qp, const double* x, const double* z, int m,
                     int64_t* families) noexcept;

}  // namespace coopctrl
