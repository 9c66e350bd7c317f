// A fixed-step integration plan (coopctrl.integrators.compiled.make_plan's ExplicitPlan or ImplicitPlan namedtuple)
// read by its field names into the core's plan (integration_plan.h), its arrays shared, not copied.
#pragma once

#include <string>
#include <vector>

#include "coopctrl/core/array_reader.h"
#include "coopctrl/core/integration_plan.h"

namespace coopctrl::binding {

/// The ExplicitPlan `plan` for a state of nx entries.
inline ExplicitPlan read_explicit_plan(nb::handle plan, int64_t nx) {
    ExplicitPlan p{};
    p.method = nb::cast<int64_t>(plan.attr("method"));
    p.k1 = doubles(plan, "plan", "k1", {nx});
    p.k2 = doubles(plan, "plan", "k2", {nx});
    p.k3 = doubles(plan, "plan", "k3", {nx});
    p.k4 = doubles(plan, "plan", "k4", {nx});
    p.y = doubles(plan, "plan", "y", {nx});
    return p;
}

/// The ImplicitPlan `plan` for a state of nx entries; pinv_work is sized for its pseudo-inverse fallback.
inline ImplicitPlan read_implicit_plan(nb::handle plan, int64_t nx, std::vector<double>& pinv_work) {
    ImplicitPlan p{};
    const double* settings = doubles(plan, "plan", "settings", {4});  // (rtol, atol, max_iterations, reuse_rate)
    p.rtol = settings[0];
    p.atol = settings[1];
    p.max_iterations = static_cast<int64_t>(settings[2]);
    p.reuse_rate = settings[3];
    const int64_t s = extent(plan, "tableau", 0);
    p.stages = static_cast<int>(s);
    p.tableau = doubles(plan, "plan", "tableau", {s, s});
    p.weights = doubles(plan, "plan", "weights", {s});
    p.nodes = doubles(plan, "plan", "nodes", {s});
    p.M = doubles(plan, "plan", "M", {nx, nx});
    p.A = doubles(plan, "plan", "A", {nx, nx});
    p.LU = doubles(plan, "plan", "LU", {nx, nx});
    p.slopes = doubles(plan, "plan", "slopes", {s, nx});
    p.predictors = doubles(plan, "plan", "predictors", {s, nx});
    p.known = doubles(plan, "plan", "known", {nx});
    p.k = doubles(plan, "plan", "k", {nx});
    p.xs = doubles(plan, "plan", "xs", {nx});
    p.fs = doubles(plan, "plan", "fs", {nx});
    p.dk = doubles(plan, "plan", "dk", {nx});
    p.xp = doubles(plan, "plan", "xp", {nx});
    p.fp = doubles(plan, "plan", "fp", {nx});
    p.memo = doubles(plan, "plan", "memo", {3});
    pinv_work.assign(2 * nx * nx + nx, 0.0);
    p.pinv_work = pinv_work.data();
    return p;
}

/// The plan's family name (its namedtuple's class name).
inline std::string plan_kind(nb::handle plan) { return nb::cast<std::string>(plan.type().attr("__name__")); }

}  // namespace coopctrl::binding
