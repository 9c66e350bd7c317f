// The nominal motion of the loaded state in plants._core (plants/core/rigid_motion.h).
#include "plants/core/binding_checks.h"
#include "plants/core/rigid_motion.h"

namespace plants::binding {

namespace {

/// (Y, dY, ddY) of the object and the nodes it carries rigidly into the (m + 1, p) outputs; returns the first
/// node at the Euler singularity (spatial) or -1.
int nominal_node_motion(Vector Y0, Vector dY0, Vector ddY0, Matrix G, MatrixOut Y, MatrixOut dY, MatrixOut ddY) {
    const size_t p = Y0.shape(0);
    expect(p == 6 || p == 3, "Y0", "6 (spatial) or 3 (planar) entries");
    expect_length(dY0.shape(0), p, "dY0");
    expect_length(ddY0.shape(0), p, "ddY0");
    expect(G.shape(1) == p, "G", "p columns (the grasps' offsets and angles)");
    const size_t m = G.shape(0);
    for (const MatrixOut* out : {&Y, &dY, &ddY})
        expect(out->shape(0) == m + 1 && out->shape(1) == p, "Y, dY, ddY", "shape (m + 1, p) each");
    if (p == 3) {
        planar_motion(Y0.data(), dY0.data(), ddY0.data(), G.data(), static_cast<int>(m), Y.data(), dY.data(),
                      ddY.data());
        return -1;
    }
    return spatial_motion(Y0.data(), dY0.data(), ddY0.data(), G.data(), static_cast<int>(m), Y.data(), dY.data(),
                          ddY.data());
}

}  // namespace

void bind_rigid_motion(nb::module_& m) {
    m.def("nominal_node_motion", &nominal_node_motion, nb::arg("Y0"), nb::arg("dY0"), nb::arg("ddY0"), nb::arg("G"),
          nb::arg("Y"), nb::arg("dY"), nb::arg("ddY"),
          "(Y, dY, ddY) of the object and the contact nodes it carries rigidly (148), into the outputs; returns "
          "the first node at the Euler singularity, or -1.");
}

}  // namespace plants::binding
