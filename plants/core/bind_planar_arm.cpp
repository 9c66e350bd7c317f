// The planar arm's kernels in plants._core (plants/core/planar_arm.h).
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/planar_arm.h"

namespace plants::binding {

namespace {

PlanarArmModel planar_arm_model(const Matrix& links, const Vector& base, const Vector& tool, const Vector& gravity) {
    expect(links.shape(1) == sizeof(PlanarLink) / sizeof(double), "links",
           "7 columns (length, mass, rc_x, rc_y, Izz, motor_inertia, viscous)");
    expect_length(base.shape(0), 3, "base");
    expect_length(tool.shape(0), 3, "tool");
    expect_length(gravity.shape(0), 2, "gravity");
    PlanarArmModel arm{};
    arm.dof = static_cast<int>(links.shape(0));
    arm.links = reinterpret_cast<const PlanarLink*>(links.data());
    for (int i = 0; i < 3; ++i) {
        arm.base[i] = base(i);
        arm.tool[i] = tool(i);
    }
    arm.gravity[0] = gravity(0);
    arm.gravity[1] = gravity(1);
    return arm;
}

int terms(Vector q, Vector dq, Matrix links, Vector base, Vector tool, Vector gravity, MatrixOut H, VectorOut h,
          VectorOut Y, MatrixOut J, VectorOut Jdq) {
    const PlanarArmModel arm = planar_arm_model(links, base, tool, gravity);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_length(q.shape(0), n, "q");
    expect_length(dq.shape(0), n, "dq");
    expect(H.shape(0) >= n && H.shape(1) >= n, "H", "shape (n, n) or larger (its leading block is filled)");
    expect(h.shape(0) >= n, "h", "n entries or more");
    expect_length(Y.shape(0), 3, "Y");
    expect(J.shape(0) == 3 && J.shape(1) >= n, "J", "shape (3, n) or (3, more than n)");
    expect_length(Jdq.shape(0), 3, "Jdq");
    std::vector<double> work((n + 1) * PLANAR_WORK_WIDTH);
    return planar_arm_terms(arm, q.data(), dq.data(), H.data(), static_cast<int>(H.shape(1)), h.data(), Y.data(),
                            J.data(), static_cast<int>(J.shape(1)), Jdq.data(), work.data());
}

double potential(Vector q, Matrix links, Vector base, Vector gravity) {
    const double no_tool[3] = {0.0, 0.0, 0.0};
    const PlanarArmModel arm = planar_arm_model(links, base, Vector(no_tool, {3}), gravity);
    expect_length(q.shape(0), static_cast<size_t>(arm.dof), "q");
    return planar_arm_potential(arm, q.data());
}

}  // namespace

void bind_planar_arm(nb::module_& m) {
    m.def("planar_arm_terms", &terms, nb::arg("q"), nb::arg("dq"), nb::arg("links"), nb::arg("base"),
          nb::arg("tool"), nb::arg("gravity"), nb::arg("H"), nb::arg("h"), nb::arg("Y"), nb::arg("J"),
          nb::arg("Jdq"),
          "Fill H, h, Y, J and Jdq of a planar arm in place (plants/core/planar_arm.h); returns 0.");
    m.def("planar_arm_potential", &potential, nb::arg("q"), nb::arg("links"), nb::arg("base"), nb::arg("gravity"),
          "The gravitational potential energy of a planar arm [J].");
}

}  // namespace plants::binding
