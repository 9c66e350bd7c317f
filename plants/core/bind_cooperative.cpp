// The cooperative plant's kernels in plants._core (plants/core/cooperative_planar.h), on a plant's kernel arrays by
// name (plants.cooperative.plant_args.PlantArgs, CooperativePlant.plant_args).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/cooperative_planar.h"
#include "plants/core/planar_plant_reader.h"

namespace plants::binding {

namespace {

nb::object numpy_copy(const std::vector<double>& v, std::initializer_list<size_t> shape) {
    double* copy = new double[v.size()];
    std::copy(v.begin(), v.end(), copy);
    nb::capsule owner(copy, [](void* p) noexcept { delete[] static_cast<double*>(p); });
    return nb::cast(nb::ndarray<nb::numpy, double>(copy, shape, owner));
}

nb::tuple planar_rhs_py(Vector x, Vector tau, nb::handle P, VectorOut dx) {
    PlanarPlant plant(P);
    PlanarWork work(plant.model);
    expect(x.shape(0) % 2 == 0 && dx.shape(0) == x.shape(0), "x, dx", "the same even length 2 nz");
    int64_t status[2] = {0, 0};
    planar_rhs(plant.model, x.data(), static_cast<int>(x.shape(0)), tau.data(), status, work.data, dx.data());
    return nb::make_tuple(status[0], status[1]);
}

/// The status and the node state at x in w (Y, dY and the arms' H, h, J, Jdq), copied into a new dict.
nb::dict node_state_dict(const PlanarWork& w, const int64_t* status) {
    const size_t N = w.N, m = w.m, n = w.nmax;
    nb::dict d;
    d["status"] = nb::make_tuple(status[0], status[1]);
    d["Y"] = numpy_copy(w.Y, {N, 3});
    d["dY"] = numpy_copy(w.dY, {N, 3});
    d["H"] = numpy_copy(w.H, {m, n, n});
    d["h"] = numpy_copy(w.h, {m, n});
    d["J"] = numpy_copy(w.J, {m, 3, n});
    d["Jdq"] = numpy_copy(w.Jdq, {m, 3});
    return d;
}

nb::dict planar_node_state_py(Vector x, nb::handle P) {
    PlanarPlant plant(P);
    PlanarWork w(plant.model);
    expect(x.shape(0) % 2 == 0, "x", "an even length 2 nz");
    int64_t status[2] = {0, 0};
    planar_node_state(plant.model, x.data(), static_cast<int>(x.shape(0)), status, w.data);
    nb::dict d = node_state_dict(w, status);
    return d;
}

nb::tuple planar_interconnection_wrenches_py(AnyArray Y, AnyArray dY, nb::handle P) {
    PlanarPlant plant(P);
    const size_t N = plant.model.arm_count + 1, m = plant.model.arm_count;
    const size_t B = node_rows_samples(Y, dY, N, 3);
    PlanarWork w(plant.model);
    std::vector<double> S(B * N * 3), Fw(B * m * 3);
    for (size_t b = 0; b < B; ++b) {  // each sample as a call of its own: the same bits
        std::copy(Y.data() + b * N * 3, Y.data() + (b + 1) * N * 3, w.Y.begin());
        std::copy(dY.data() + b * N * 3, dY.data() + (b + 1) * N * 3, w.dY.begin());
        planar_interconnection_wrenches(plant.model, w.data, w.terms);
        std::copy(w.S.begin(), w.S.end(), S.begin() + b * N * 3);
        std::copy(w.Fw.begin(), w.Fw.end(), Fw.begin() + b * m * 3);
    }
    if (Y.ndim() == 2) return nb::make_tuple(numpy_copy(S, {N, 3}), numpy_copy(Fw, {m, 3}), true);
    return nb::make_tuple(numpy_copy(S, {B, N, 3}), numpy_copy(Fw, {B, m, 3}), true);
}

nb::dict planar_control_terms_py(Vector x, nb::handle P) {
    PlanarPlant plant(P);
    PlanarWork w(plant.model);
    int64_t status[2] = {0, 0};
    planar_control_terms(plant.model, x.data(), static_cast<int>(x.shape(0)), status, w.data, w.terms);
    const size_t N = w.N, m = w.m;
    nb::dict d = node_state_dict(w, status);
    d["W"] = numpy_copy(w.W, {N, 3, 3});
    d["w_free"] = numpy_copy(w.w_free, {N, 3});
    d["S"] = numpy_copy(w.S, {N, 3});
    d["Fw"] = numpy_copy(w.Fw, {m, 3});
    return d;
}

double planar_arm_potentials_py(Vector x, nb::handle P) {
    PlanarPlant plant(P);
    return planar_arm_potentials(plant.model, x.data());
}

}  // namespace

void bind_cooperative(nb::module_& m) {
    m.def("planar_rhs", &planar_rhs_py, nb::arg("x"), nb::arg("tau"), nb::arg("P"), nb::arg("dx"),
          "dx = f(x, tau) of a planar cooperative plant (its PlantArgs P); returns the status (code, node).");
    m.def("planar_node_state", &planar_node_state_py, nb::arg("x"), nb::arg("P"),
          "The node poses and rates and the arm terms of a planar cooperative plant at x, new arrays by name.");
    m.def("planar_interconnection_wrenches", &planar_interconnection_wrenches_py, nb::arg("Y"), nb::arg("dY"),
          nb::arg("P"),
          "(S, Fw, True) of a planar plant's interconnections at node poses Y and rates dY (m + 1, 3): S (m + 1, 3) "
          "the edges' terms of w, Fw (m, 3) each contact's wrench on the object; for a stack of samples Y, dY "
          "(samples, m + 1, 3), S and Fw stacked the same way.");
    m.def("planar_control_terms", &planar_control_terms_py, nb::arg("x"), nb::arg("P"),
          "The node state and the control terms of a planar cooperative plant at x, as new arrays by name.");
    m.def("planar_arm_potentials", &planar_arm_potentials_py, nb::arg("x"), nb::arg("P"),
          "The gravitational potential energy of a planar plant's arms [J].");
}

}  // namespace plants::binding
