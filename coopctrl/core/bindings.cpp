// coopctrl._core: the Python bindings of the control layer's compiled core (coopctrl/core). Each concern registers
// its functions from its own bind_<concern>.cpp; a function checks its arguments' shapes once and calls the core,
// which checks nothing; arrays pass without copies.
#include <nanobind/nanobind.h>

namespace nb = nanobind;

namespace coopctrl::binding {
void bind_adaptive(nb::module_& m);
void bind_control_laws(nb::module_& m);
void bind_integrators(nb::module_& m);
void bind_loop_state(nb::module_& m);
void bind_node_poses(nb::module_& m);
void bind_preflight_ik(nb::module_& m);
void bind_qp(nb::module_& m);
void bind_squeeze(nb::module_& m);
void bind_tick_checks(nb::module_& m);
void bind_tick(nb::module_& m);
void bind_plant_advance(nb::module_& m);
void bind_qp_replay(nb::module_& m);
}  // namespace coopctrl::binding

NB_MODULE(_core, m) {
    m.doc() = "The control layer's compiled core (C++, built at install; coopctrl/core).";
    coopctrl::binding::bind_adaptive(m);
    coopctrl::binding::bind_control_laws(m);
    coopctrl::binding::bind_integrators(m);
    coopctrl::binding::bind_loop_state(m);
    coopctrl::binding::bind_node_poses(m);
    coopctrl::binding::bind_preflight_ik(m);
    coopctrl::binding::bind_qp(m);
    coopctrl::binding::bind_squeeze(m);
    coopctrl::binding::bind_tick_checks(m);
    coopctrl::binding::bind_tick(m);
    coopctrl::binding::bind_plant_advance(m);
    coopctrl::binding::bind_qp_replay(m);
}
