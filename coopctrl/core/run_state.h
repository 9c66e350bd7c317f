// What a run carries from tick to tick and how a run (or one integrator call) stopped, by name: the loop state's
// tallies and hold, and the stop report (coopctrl._core.LoopFlags, HoldState and StopReport, bind_loop_state.cpp).
// Plain data, written in place by the tick (tick.h) and the integrators' bindings.
#pragma once

#include <cstdint>

namespace coopctrl {

/// The loop state's tallies (LoopState.flags, a coopctrl._core.LoopFlags: these fields by name).
struct LoopFlags {
    int64_t have_last_split = 0;       ///< a feasible split has been solved
    int64_t consecutive_failures = 0;  ///< failed QP solves in a row
    int64_t saturated_ticks = 0;       ///< ticks with a saturated joint
    int64_t qp_solves = 0;             ///< solves so far (the first solve starts cold)
    int64_t first_saturated = -1;      ///< the first saturated tick (-1: none)
    int64_t last_saturated = -1;       ///< the last saturated tick (-1: none)
    int64_t advance_first = 0;         ///< advance the period a run ending at tick k_base - 1 did not, then clear
};

/// The next tick's hold (LoopState.hold, a coopctrl._core.HoldState).
struct HoldState {
    int64_t mode = 0;        ///< 1: take the last feasible split (the caller applied the failure policy)
    int64_t qp_status = 0;   ///< the failed solve's status, recorded
    int64_t iterations = 0;  ///< its iterations, recorded
    int64_t binding = 0;     ///< its binding families mask
};

/// How a run stopped (LoopData.stop, a coopctrl._core.StopReport): the code, where, and the code's details.
struct StopReport {
    int64_t code = 0;             ///< TickCode
    int64_t tick = 0;             ///< the tick it stopped at, or where to resume
    int64_t detail[3] = {0, 0, 0};  ///< the code's integer details (TickCode's comments)
    int64_t ticks_recorded = 0;   ///< rows of the record written
    int64_t last_good_tick = -1;  ///< the last tick whose state passed the guards (-1: none)
    int64_t rhs_evaluations = 0;  ///< right-hand-side evaluations (the integrators' count)
    double value[2] = {0.0, 0.0};  ///< the code's real details (TickCode's comments)
};

}  // namespace coopctrl
