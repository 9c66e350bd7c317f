// plants._core: the Python bindings of the plant's compiled kernels (plants/core). Each concern registers its
// functions from its own bind_<concern>.cpp; a function checks its arguments' shapes once and calls the core,
// which checks nothing; arrays pass without copies.
#include <nanobind/nanobind.h>

namespace nb = nanobind;

namespace plants::binding {
void bind_planar_arm(nb::module_& m);
void bind_frames(nb::module_& m);
void bind_rigid_motion(nb::module_& m);
void bind_cooperative(nb::module_& m);
void bind_cooperative_spatial(nb::module_& m);
void bind_cooperative_energy(nb::module_& m);
void bind_elastic(nb::module_& m);
void bind_arms(nb::module_& m);
}  // namespace plants::binding

NB_MODULE(_core, m) {
    m.doc() = "The plant's compiled kernels (C++, built at install; plants/core).";
    plants::binding::bind_planar_arm(m);
    plants::binding::bind_frames(m);
    plants::binding::bind_rigid_motion(m);
    plants::binding::bind_cooperative(m);
    plants::binding::bind_cooperative_spatial(m);
    plants::binding::bind_cooperative_energy(m);
    plants::binding::bind_elastic(m);
    plants::binding::bind_arms(m);
}
