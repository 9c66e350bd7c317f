// plants._core: the Python bindings of the plant's compiled kernels (plants/core). Each function checks its
// arguments' shapes once and calls the core, which checks nothing; arrays pass without copies.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <string>
#include <vector>

#include "plants/core/planar_arm.h"

namespace nb = nanobind;

namespace {

using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

void expect(bool ok, const char* name, const std::string& what) {
    if (!ok) throw nb::value_error((std::string(name) + ": expected " + what).c_str());
}

void expect_length(size_t got, size_t want, const char* name) {
    expect(got == want, name, "length " + std::to_string(want) + ", got " + std::to_string(got));
}

plants::PlanarArmModel planar_arm_model(const Matrix& links, const Vector& base, const Vector& tool,
                                        const Vector& gravity) {
    expect(links.shape(1) == sizeof(plants::PlanarLink) / sizeof(double), "links",
           "7 columns (length, mass, rc_x, rc_y, Izz, motor_inertia, viscous)");
    expect_length(base.shape(0), 3, "base");
    expect_length(tool.shape(0), 3, "tool");
    expect_length(gravity.shape(0), 2, "gravity");
    plants::PlanarArmModel arm{};
    arm.dof = static_cast<int>(links.shape(0));
    arm.links = reinterpret_cast<const plants::PlanarLink*>(links.data());
    for (int i = 0; i < 3; ++i) {
        arm.base[i] = base(i);
        arm.tool[i] = tool(i);
    }
    arm.gravity[0] = gravity(0);
    arm.gravity[1] = gravity(1);
    return arm;
}

int planar_arm_terms(Vector q, Vector dq, Matrix links, Vector base, Vector tool, Vector gravity, MatrixOut H,
                     VectorOut h, VectorOut Y, MatrixOut J, VectorOut Jdq) {
    const plants::PlanarArmModel arm = planar_arm_model(links, base, tool, gravity);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_length(q.shape(0), n, "q");
    expect_length(dq.shape(0), n, "dq");
    expect(H.shape(0) == n && H.shape(1) == n, "H", "shape (n, n)");
    expect_length(h.shape(0), n, "h");
    expect_length(Y.shape(0), 3, "Y");
    expect(J.shape(0) == 3 && J.shape(1) == n, "J", "shape (3, n)");
    expect_length(Jdq.shape(0), 3, "Jdq");
    std::vector<double> work((n + 1) * plants::PLANAR_WORK_WIDTH);
    return plants::planar_arm_terms(arm, q.data(), dq.data(), H.data(), h.data(), Y.data(), J.data(), Jdq.data(),
                                    work.data());
}

double planar_arm_potential(Vector q, Matrix links, Vector base, Vector gravity) {
    const double no_tool[3] = {0.0, 0.0, 0.0};
    const plants::PlanarArmModel arm =
        planar_arm_model(links, base, Vector(no_tool, {3}), gravity);
    expect_length(q.shape(0), static_cast<size_t>(arm.dof), "q");
    return plants::planar_arm_potential(arm, q.data());
}

}  // namespace

NB_MODULE(_core, m) {
    m.doc() = "The plant's compiled kernels (C++, built at install; plants/core).";
    m.def("planar_arm_terms", &planar_arm_terms, nb::arg("q"), nb::arg("dq"), nb::arg("links"), nb::arg("base"),
          nb::arg("tool"), nb::arg("gravity"), nb::arg("H"), nb::arg("h"), nb::arg("Y"), nb::arg("J"),
          nb::arg("Jdq"),
          "Fill H, h, Y, J and Jdq of a planar arm in place (plants/core/planar_arm.h); returns 0.");
    m.def("planar_arm_potential", &planar_arm_potential, nb::arg("q"), nb::arg("links"), nb::arg("base"),
          nb::arg("gravity"), "The gravitational potential energy of a planar arm [J].");
}
