// The integration plan of a run (the fixed-step schemes' configuration and work arrays) and what an advance
// reports, by name. The schemes themselves: explicit_schemes.h, implicit_schemes.h.
#pragma once

#include <cstdint>

namespace coopctrl {

/// Results of an advance over one control period.
enum StepCode : int {
    STEP_OK = 0,             ///< the period is integrated
    STEP_PLANT_ERROR = 1,    ///< the right-hand side failed (AdvanceReport::plant_status, x_fail)
    STEP_NEWTON_FAILED = 2,  ///< an implicit stage did not converge (AdvanceReport's Newton fields)
    STEP_TOO_SMALL = 3,      ///< an error-controlled step fell below its minimum
};

/// The explicit schemes' run-time codes (coopctrl/integrators/methods.py has the same numbers).
enum ExplicitMethod : int64_t {
    METHOD_EULER = 0,
    METHOD_SYMPLECTIC_EULER = 1,
    METHOD_RK4 = 2,
};

/// Euler, symplectic Euler and RK4: the scheme and its work arrays (nx doubles each).
struct ExplicitPlan {
    int64_t method;  ///< ExplicitMethod
    double* k1;      ///< the slopes of the stages [units of x / s]
    double* k2;
    double* k3;
    double* k4;
    double* y;       ///< the stage state
};

/// A singly diagonally implicit Runge-Kutta scheme (implicit midpoint, implicit Euler) and its simplified Newton
/// iteration's state, kept from step to step: the stages G(k_i) = k_i - f(S_i + gamma h k_i) = 0 with
/// M = (I - gamma h J)^-1 and J the forward-difference Jacobian.
struct ImplicitPlan {
    double rtol;            ///< [-] Newton's relative tolerance
    double atol;            ///< [units of x] Newton's absolute tolerance
    int64_t max_iterations; ///< Newton iterations a stage may take
    double reuse_rate;      ///< [-] a contraction rate above which the Jacobian is evaluated again
    int stages;             ///< s
    const double* tableau;  ///< (s, s) row-major, lower triangular, diagonal gamma
    const double* weights;  ///< (s,) b
    const double* nodes;    ///< (s,) c
    double* M;              ///< (nx, nx) the iteration matrix (I - gamma h J)^-1
    double* A;              ///< (nx, nx) work: J, then I - gamma h J
    double* LU;             ///< (nx, nx) work: the LU factors of A
    double* slopes;         ///< (s, nx) the stage slopes of the last step
    double* predictors;     ///< (s, nx) the next step's starting slopes
    double* known;          ///< (nx,) work: S_i
    double* k;              ///< (nx,) work: the iterate
    double* xs;             ///< (nx,) work: the stage state
    double* fs;             ///< (nx,) work: f at the stage state
    double* dk;             ///< (nx,) work: the Newton correction
    double* xp;             ///< (nx,) work: the Jacobian's perturbed state
    double* fp;             ///< (nx,) work: f at xp
    double* memo;           ///< (3,) (M is kept: 1 / 0, the step h [s] M was made for, Jacobian evaluations)
    double* pinv_work;      ///< (2 nx^2 + nx,) work of the pseudo-inverse, the fallback for a singular I - gamma h J
};

/// What an advance reports besides its StepCode.
struct AdvanceReport {
    int64_t rhs_evaluations = 0;   ///< right-hand-side evaluations so far (counted on, not reset)
    int64_t plant_status[2] = {0, 0};  ///< the plant's status at a STEP_PLANT_ERROR
    int64_t failed_step = 0;       ///< STEP_NEWTON_FAILED: the index of the failed step in the period's steps
    int64_t newton_iterations = 0; ///< STEP_NEWTON_FAILED: the failed stage's iterations
    double last_correction = 0.0;  ///< STEP_NEWTON_FAILED: its last correction h max|dk| [units of x]
    double failed_time = 0.0;      ///< STEP_NEWTON_FAILED: the time at the start of the failed step [s]
};

}  // namespace coopctrl
