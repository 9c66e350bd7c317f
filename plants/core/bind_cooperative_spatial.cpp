// The spatial cooperative plant's kernels in plants._core (plants/core/cooperative_spatial.h), on a plant's kernel
// arrays by name (plants.cooperative.plant_args.PlantArgs, CooperativePlant.plant_args). Each call reads the model
// and makes a workspace of its own (spatial_plant_reader.h): for tests and scripts; the compiled tick keeps both.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/cooperative_spatial.h"
#include "plants/core/elastic_nodes.h"
#include "plants/core/spatial_plant_reader.h"

namespace plants::binding {

namespace {

/// A new numpy array of the given shape holding a copy of n doubles from data.
nb::object numpy_copy(const double* data, size_t n, std::initializer_list<size_t> shape) {
    double* copy = new double[n];
    std::copy(data, data + n, copy);
    nb::capsule owner(copy, [](void* p) noexcept { delete[] static_cast<double*>(p); });
    return nb::cast(nb::ndarray<nb::numpy, double>(copy, shape, owner));
}

nb::object numpy_copy(const std::vector<double>& v, std::initializer_list<size_t> shape) {
    return numpy_copy(v.data(), v.size(), shape);
}

void expect_state(const Vector& x, const SpatialCooperativeModel& model) {
    expect(x.shape(0) % 2 == 0 && x.shape(0) >= 12, "x", "an even length 2 nz (z ending with the object's pose)");
    const size_t nz = x.shape(0) / 2;
    for (int i = 0; i < model.arm_count; ++i)
        expect(static_cast<size_t>(model.arms[i].q_offset + model.arms[i].dof) <= nz - 6, "P.q_off",
               "every arm's coordinates inside z before the object's pose");
}

void expect_rhs_arguments(const Vector& x, const Vector& tau, const VectorOut& dx, const SpatialCooperativeModel& model) {
    expect_state(x, model);
    expect_length(tau.shape(0), x.shape(0) / 2 - 6, "tau");
    expect_length(dx.shape(0), x.shape(0), "dx");
}

nb::tuple spatial_rhs_py(Vector x, Vector tau, nb::handle P, VectorOut dx) {
    SpatialPlant plant(P);
    expect_rhs_arguments(x, tau, dx, plant.model);
    SpatialWork work(plant.model);
    int64_t status[2] = {0, 0};
    spatial_rhs(plant.model, x.data(), static_cast<int>(x.shape(0)), tau.data(), status, work.data, dx.data());
    return nb::make_tuple(status[0], status[1]);
}

/// The status and the node state at x in w (Y, dY, the arms' H, h, J, Jdq and every node's frames), copied into a
/// new dict.
nb::dict node_state_dict(const SpatialWork& w, const int64_t* status) {
    const size_t N = w.N, m = w.m, n = w.nmax;
    nb::dict d;
    d["status"] = nb::make_tuple(status[0], status[1]);
    d["Y"] = numpy_copy(w.Y, {N, 6});
    d["dY"] = numpy_copy(w.dY, {N, 6});
    d["H"] = numpy_copy(w.H, {m, n, n});
    d["h"] = numpy_copy(w.h, {m, n});
    d["J"] = numpy_copy(w.J, {m, 6, n});
    d["Jdq"] = numpy_copy(w.Jdq, {m, 6});
    d["frames"] = numpy_copy(&w.frames[0].R[0][0], N * NODE_FRAME_BLOCKS * 9, {N, NODE_FRAME_BLOCKS, 3, 3});
    return d;
}

nb::dict spatial_control_terms_py(Vector x, nb::handle P) {
    SpatialPlant plant(P);
    expect_state(x, plant.model);
    SpatialWork w(plant.model);
    int64_t status[2] = {0, 0};
    spatial_control_terms(plant.model, x.data(), static_cast<int>(x.shape(0)), status, w.data, w.terms);
    const size_t N = w.N, m = w.m;
    nb::dict d = node_state_dict(w, status);
    d["Wr"] = numpy_copy(w.Wr, {N, 3, 3});
    d["W"] = numpy_copy(w.W, {N, 6, 6});
    d["w_free"] = numpy_copy(w.w_free, {N, 6});
    d["S"] = numpy_copy(w.S, {N, 6});
    d["Fw"] = numpy_copy(w.Fw, {m, 6});
    return d;
}

nb::dict spatial_node_state_py(Vector x, nb::handle P) {
    SpatialPlant plant(P);
    expect_state(x, plant.model);
    SpatialWork w(plant.model);
    int64_t status[2] = {0, 0};
    spatial_node_state(plant.model, x.data(), static_cast<int>(x.shape(0)), status, w.data);
    // every node's frames in its chart, as the elastic system's: an own-chart arm's chart is the one it just wrote
    node_frames_charted(w.Y.data(), w.N, plant.model.node_rows, plant.model.node_width, w.frames.data());
    return node_state_dict(w, status);
}

nb::tuple spatial_interconnection_wrenches_py(AnyArray Y, AnyArray dY, nb::handle P) {
    SpatialPlant plant(P);
    const size_t N = plant.model.arm_count + 1, m = plant.model.arm_count;
    const size_t B = node_rows_samples(Y, dY, N, 6);
    SpatialWork w(plant.model);
    std::vector<double> S(B * N * 6), Fw(B * m * 6);
    bool ok = true;
    for (size_t b = 0; b < B; ++b) {  // each sample as a call of its own: the same bits
        std::copy(Y.data() + b * N * 6, Y.data() + (b + 1) * N * 6, w.Y.begin());
        std::copy(dY.data() + b * N * 6, dY.data() + (b + 1) * N * 6, w.dY.begin());
        if (!plant.model.immobile) node_frames(w.Y.data(), w.N, w.frames.data());  // the world angles' frames
        ok = spatial_interconnection_wrenches(plant.model, w.data, w.terms, false) && ok;
        std::copy(w.S.begin(), w.S.end(), S.begin() + b * N * 6);
        std::copy(w.Fw.begin(), w.Fw.end(), Fw.begin() + b * m * 6);
    }
    if (Y.ndim() == 2) return nb::make_tuple(numpy_copy(S, {N, 6}), numpy_copy(Fw, {m, 6}), ok);
    return nb::make_tuple(numpy_copy(S, {B, N, 6}), numpy_copy(Fw, {B, m, 6}), ok);
}

nb::tuple spatial_rhs_from_terms_py(Vector x, Vector tau, nb::handle P, VectorOut dx) {
    SpatialPlant plant(P);
    expect_rhs_arguments(x, tau, dx, plant.model);
    SpatialWork work(plant.model);
    const int nx = static_cast<int>(x.shape(0));
    int64_t status[2] = {0, 0};
    spatial_control_terms(plant.model, x.data(), nx, status, work.data, work.terms);
    if (status[0] != ELASTIC_OK) return nb::make_tuple(status[0], status[1]);
    spatial_rhs_from_terms(plant.model, x.data(), nx, tau.data(), status, work.data, work.terms, dx.data());
    return nb::make_tuple(status[0], status[1]);
}

double spatial_arm_potentials_py(Vector x, nb::handle P) {
    SpatialPlant plant(P);
    expect_state(x, plant.model);
    SpatialWork work(plant.model);
    return spatial_arm_potentials(plant.model, x.data(), work.chain.data());
}

}  // namespace

void bind_cooperative_spatial(nb::module_& m) {
    m.def("spatial_rhs", &spatial_rhs_py, nb::arg("x"), nb::arg("tau"), nb::arg("P"), nb::arg("dx"),
          "dx = f(x, tau) of a spatial cooperative plant (its PlantArgs P); returns the status (code, node).");
    m.def("spatial_control_terms", &spatial_control_terms_py, nb::arg("x"), nb::arg("P"),
          "The node state, node frames and control terms of a spatial cooperative plant at x, new arrays by name.");
    m.def("spatial_node_state", &spatial_node_state_py, nb::arg("x"), nb::arg("P"),
          "The node poses and rates, the arm terms and every node's frames in its chart of a spatial cooperative "
          "plant at x, new arrays by name (status: an arm's tip at an Euler singularity).");
    m.def("spatial_interconnection_wrenches", &spatial_interconnection_wrenches_py, nb::arg("Y"), nb::arg("dY"),
          nb::arg("P"),
          "(S, Fw, ok) of a spatial plant's interconnections at node poses Y and rates dY (m + 1, 6) in the book's "
          "world angles: S (m + 1, 6) the edges' terms of w, Fw (m, 6) each contact's wrench on the object (zero "
          "where ok is false: the object's angles at the Euler singularity); for a stack of samples Y, dY "
          "(samples, m + 1, 6), S and Fw stacked the same way (ok: for every sample).");
    m.def("spatial_rhs_from_terms", &spatial_rhs_from_terms_py, nb::arg("x"), nb::arg("tau"), nb::arg("P"),
          nb::arg("dx"),
          "dx = f(x, tau) of a spatial plant finished from its control terms at x (sensed first, as a tick does); "
          "returns the status (code, node) of the terms, or else of the right-hand side.");
    m.def("spatial_arm_potentials", &spatial_arm_potentials_py, nb::arg("x"), nb::arg("P"),
          "The gravitational potential energy of a spatial plant's arms [J].");
}

}  // namespace plants::binding
