// The node poses of recorded states in coopctrl._core (coopctrl/core/node_poses.h), on a plant read from its
// PlantArgs (plants/core's plant readers) with a workspace of its own.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <string>
#include <vector>

#include "coopctrl/core/node_poses.h"
#include "plants/core/binding_checks.h"
#include "plants/core/planar_plant_reader.h"
#include "plants/core/spatial_plant_reader.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using plants::binding::expect;
using plants::binding::Matrix;
using PosesOut = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using StatusOut = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

/// nz = the arms' coordinates and the object's pose: the half of the state.
template <class Model>
size_t half_state(const Model& model, size_t p) {
    size_t nz = p;
    for (int i = 0; i < model.arm_count; ++i) nz += static_cast<size_t>(model.arms[i].dof);
    return nz;
}

NodePoseRecord record_of(Matrix X, PosesOut out, StatusOut status, size_t m, size_t p, size_t nz) {
    expect(X.shape(1) == 2 * nz, "X", "rows of the plant's state size " + std::to_string(2 * nz));
    expect(out.shape(0) == X.shape(0) && out.shape(1) == m && out.shape(2) == p, "out",
           "shape (rows of X, m, " + std::to_string(p) + ")");
    expect(status.shape(0) >= 2, "status", "at least 2 entries");
    return NodePoseRecord{X.data(), static_cast<int>(X.shape(0)), static_cast<int>(X.shape(1)), out.data()};
}

int64_t spatial_poses(Matrix X, nb::handle P, StatusOut status, PosesOut out) {
    plants::binding::SpatialPlant plant(P);
    const auto& model = plant.model;
    const NodePoseRecord record = record_of(X, out, status, model.arm_count, 6, half_state(model, 6));
    std::vector<double> Y((model.arm_count + 1) * 6);
    std::vector<plants::ChainBody> chain(model.nmax + 1);
    return spatial_node_poses(model, record, Y.data(), chain.data(), status.data());
}

int64_t planar_poses(Matrix X, nb::handle P, StatusOut status, PosesOut out) {
    plants::binding::PlanarPlant plant(P);
    const auto& model = plant.model;
    const NodePoseRecord record = record_of(X, out, status, model.arm_count, 3, half_state(model, 3));
    plants::PlanarWork work(model);
    return planar_node_poses(model, record, work.data, status.data());
}

}  // namespace

void bind_node_poses(nb::module_& m) {
    m.def("spatial_node_poses", &spatial_poses, nb::arg("X"), nb::arg("P"), nb::arg("status").noconvert(),
          nb::arg("out").noconvert(),
          "The node poses out[k] (m, 6) [m, rad] of each finite state row X[k] of the spatial plant P (its\n"
          "PlantArgs); returns the first row whose kinematics failed (status[0], status[1] the node), or -1.");
    m.def("planar_node_poses", &planar_poses, nb::arg("X"), nb::arg("P"), nb::arg("status").noconvert(),
          nb::arg("out").noconvert(), "spatial_node_poses of a planar plant: out[k] (m, 3).");
}

}  // namespace coopctrl::binding
