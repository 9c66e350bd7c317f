// The error-controlled schemes' plans (rk23, rk45: EmbeddedPlan; trbdf2: TRBDF2Plan) by name: their tableau,
// tolerances and step controller, their work arrays, and the state kept from step to step and tick to tick (the
// step carried over, the Newton matrix, the statistics rows). The Python plans of
// coopctrl/integrators/adaptive_plans.py hold the same arrays; the schemes: adaptive_schemes.h.
#pragma once

#include <cstdint>

namespace coopctrl {

/// How an accepted step's successor is chosen (adaptive_plans.CONTROLLER_*).
enum StepController : int {
    CONTROLLER_PI = 0,          ///< Gustafsson's PI controller
    CONTROLLER_ELEMENTARY = 1,  ///< safety |e|^(-1/k) (scipy's RK23, RK45)
    CONTROLLER_FIXED = 2,       ///< every step AdaptiveMemo::fixed_step, no control (the order tests)
};

/// The entries of a Python plan's settings array (adaptive_plans.S_*): read once into the plan's fields.
enum AdaptiveSetting : int {
    SETTING_RTOL = 0,
    SETTING_MIN_STEP = 1,
    SETTING_SAFETY = 2,
    SETTING_MIN_FACTOR = 3,
    SETTING_MAX_FACTOR = 4,
    SETTING_ERROR_ORDER = 5,
    SETTING_CONTROLLER = 6,
    SETTING_PERIOD = 7,
    SETTING_NEWTON_TOL = 8,
    SETTING_MAX_ITERATIONS = 9,
    SETTING_COUNT = 10,
};

/// The state a plan keeps from step to step and tick to tick: the Python plan's memo array (float64 (8,)), field
/// for field (adaptive_plans.M_*), so that it is written in place.
struct AdaptiveMemo {
    double carry;          ///< [s] the step carried to the next period (0: none yet)
    double error_prev;     ///< [-] the last accepted error norm (the PI controller's memory)
    double fixed_step;     ///< [s] CONTROLLER_FIXED's step
    double parts;          ///< TR-BDF2's steps in the last period
    double gh;             ///< [s] the d h the iteration matrix M was made for (0: no M)
    double have_jacobian;  ///< 1.0: J is current, 0.0: evaluate it before the next step
    double jacobians;      ///< Jacobian evaluations so far
    double fresh;          ///< 1.0: J was evaluated at the state of the step being tried
};
static_assert(sizeof(AdaptiveMemo) == 8 * sizeof(double), "AdaptiveMemo overlays the memo array");

/// One tick's row of a plan's statistics (float64 (ticks, 4)), field for field (adaptive_plans.STAT_*).
struct StepStatistics {
    double accepted;         ///< accepted steps
    double rejected;         ///< rejected steps (and TR-BDF2's steps whose Newton iteration did not converge)
    double rhs_evaluations;  ///< right-hand-side evaluations
    double min_step;         ///< [s] the smallest accepted step (inf: none; NaN: the tick did not advance)
};
static_assert(sizeof(StepStatistics) == 4 * sizeof(double), "StepStatistics overlays a row of stats");

/// What both families share: the period, the tolerances and the step controller, and where they keep their state.
struct StepControl {
    double period;            ///< [s] the control period T: an advance integrates [t, t + T]
    const double* atol;       ///< (nx,) absolute tolerances [units of x]
    double rtol;              ///< [-] relative tolerance
    double min_step;          ///< [s] a step below it stops the run (STEP_TOO_SMALL)
    double safety;            ///< [-] the factor on the controller's step
    double min_factor;        ///< [-] the smallest step factor
    double max_factor;        ///< [-] the largest step factor
    double error_order;       ///< q, the order of the error estimate (the controller's exponent is 1 / (q + 1))
    StepController controller;
    AdaptiveMemo* memo;       ///< the state kept from step to step
    StepStatistics* stats;    ///< (ticks,) a row per tick k = round(t / T)
    int64_t ticks;
};

/// The explicit embedded pairs (Bogacki-Shampine 3(2), Dormand-Prince 5(4), first-same-as-last) with s stages.
struct EmbeddedPlan {
    StepControl control;
    int stages;       ///< s
    const double* A;  ///< (s, s) row-major, strictly lower triangular
    const double* B;  ///< (s,) the weights of the step (the higher order)
    const double* C;  ///< (s,) the nodes
    const double* E;  ///< (s + 1,) the error weights, the last on the first-same-as-last slope
    double* K;        ///< (s + 1, nx) the slopes; row s is f at the step's end
    double* y;        ///< (nx,) work: the stage state
    double* ynew;     ///< (nx,) work: the step's end
};

/// TR-BDF2 and its simplified Newton iteration's state (J, M kept from step to step and tick to tick).
struct TRBDF2Plan {
    StepControl control;
    double newton_tol;       ///< [-] a stage converges when its scaled correction is below this
    int64_t max_iterations;  ///< Newton iterations a stage may take
    double* J;          ///< (nx, nx) the forward-difference Jacobian
    double* Ah;         ///< (nx, nx) work: I - d h J
    double* LU;         ///< (nx, nx) work: its LU factors
    double* M;          ///< (nx, nx) the iteration matrix (I - d h J)^-1
    double* k1;         ///< (nx,) the stage slopes
    double* k2;
    double* k3;
    double* known;      ///< (nx,) work: the stage's known part
    double* xs;         ///< (nx,) work: the stage state
    double* fs;         ///< (nx,) work: f at xs
    double* dk;         ///< (nx,) work: the Newton correction, then the filtered error M e
    double* e;          ///< (nx,) work: the error estimate
    double* y;          ///< (nx,) work: the step's end
    double* xp;         ///< (nx,) work: the Jacobian's perturbed state
    double* fp;         ///< (nx,) work: f at xp
    double* pinv_work;  ///< (2 nx^2 + nx,) work of the pseudo-inverse, the fallback for a singular I - d h J
};

/// Where and why a step fell below min_step (STEP_TOO_SMALL; a StopReport's value).
struct TooSmallStep {
    double step = 0.0;  ///< [s] the step the controller asked for
    double time = 0.0;  ///< [s] the time it would have started at
};

}  // namespace coopctrl
