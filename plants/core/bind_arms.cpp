// The spatial arms' kernels in plants._core: the general serial chain (plants/core/chain_arm.h, URDF and DH arms
// alike) and the DH arm (plants/core/dh_arm.h). Each checks its arguments' shapes once, reads the joint table's
// rows as the core's structs (no copy), and fills its output arrays in place.
#include <string>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/chain_arm.h"
#include "plants/core/dh_arm.h"

namespace plants::binding {

namespace {

void expect_shape(size_t rows, size_t cols, size_t want_rows, size_t want_cols, const char* name,
                  const char* what) {
    expect(rows == want_rows && cols == want_cols, name,
           std::string("shape ") + what + " = (" + std::to_string(want_rows) + ", " + std::to_string(want_cols) +
               "), got (" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
}

void copy_pose(const Matrix& T, const char* name, double* out) {
    expect_shape(T.shape(0), T.shape(1), 4, 4, name, "(4, 4)");
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j) out[4 * i + j] = T(i, j);
}

void copy_gravity(const Vector& gravity, double* out) {
    expect_length(gravity.shape(0), 3, "gravity");
    for (size_t i = 0; i < 3; ++i) out[i] = gravity(i);
}

/// The outputs of a terms kernel: H (n, n), h (n), Y (6), J (6, n), Jdq (6).
void expect_terms_outputs(size_t n, const MatrixOut& H, const VectorOut& h, const VectorOut& Y, const MatrixOut& J,
                          const VectorOut& Jdq) {
    expect_shape(H.shape(0), H.shape(1), n, n, "H", "(n, n)");
    expect_length(h.shape(0), n, "h");
    expect_length(Y.shape(0), 6, "Y");
    expect_shape(J.shape(0), J.shape(1), 6, n, "J", "(6, n)");
    expect_length(Jdq.shape(0), 6, "Jdq");
}

void expect_joint_vector(const Vector& v, size_t n, const char* name) { expect_length(v.shape(0), n, name); }

// ---- chain arm ---------------------------------------------------------------------------------------------

ChainArmModel chain_arm_model(const Matrix& table, const Matrix& base, const Matrix* tool, const Vector* gravity) {
    expect(table.shape(1) == sizeof(ChainJointRow) / sizeof(double) && table.shape(0) >= 1, "table",
           "at least one row of 32 columns (type, origin(3), rotation(9), axis(3), mass, com(3), inertia(6), "
           "motor_inertia, viscous, coulomb, 3 unused)");
    ChainArmModel arm{};
    arm.dof = static_cast<int>(table.shape(0));
    arm.joints = reinterpret_cast<const ChainJointRow*>(table.data());
    copy_pose(base, "base", arm.base);
    if (tool) copy_pose(*tool, "tool", arm.tool);
    if (gravity) copy_gravity(*gravity, arm.gravity);
    return arm;
}

int chain_terms(Vector q, Vector dq, Matrix table, Matrix base, Matrix tool, Vector gravity, MatrixOut H,
                VectorOut h, VectorOut Y, MatrixOut J, VectorOut Jdq, bool own_chart, double* chart) {
    const ChainArmModel arm = chain_arm_model(table, base, &tool, &gravity);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    expect_joint_vector(dq, n, "dq");
    expect_terms_outputs(n, H, h, Y, J, Jdq);
    std::vector<ChainBody> work(n + 1);
    return chain_arm_terms(arm, q.data(), dq.data(), H.data(), h.data(), Y.data(), J.data(), Jdq.data(),
                           work.data(), own_chart, chart);
}

int chain_terms_world(Vector q, Vector dq, Matrix table, Matrix base, Matrix tool, Vector gravity, MatrixOut H,
                      VectorOut h, VectorOut Y, MatrixOut J, VectorOut Jdq) {
    return chain_terms(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, false, nullptr);
}

int chain_terms_own_chart(Vector q, Vector dq, Matrix table, Matrix base, Matrix tool, Vector gravity, MatrixOut H,
                          VectorOut h, VectorOut Y, MatrixOut J, VectorOut Jdq, MatrixOut chart) {
    expect_shape(chart.shape(0), chart.shape(1), 3, 3, "chart", "(3, 3)");
    return chain_terms(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, true, chart.data());
}

int chain_pose(Vector q, Matrix table, Matrix base, Matrix tool, bool own_chart, VectorOut Y) {
    const ChainArmModel arm = chain_arm_model(table, base, &tool, nullptr);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    expect_length(Y.shape(0), 6, "Y");
    std::vector<ChainBody> work(n + 1);
    return chain_arm_pose(arm, q.data(), own_chart, work.data(), Y.data());
}

double chain_potential(Vector q, Matrix table, Matrix base, Vector gravity) {
    const ChainArmModel arm = chain_arm_model(table, base, nullptr, &gravity);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    std::vector<ChainBody> work(n + 1);
    return chain_arm_potential(arm, q.data(), work.data());
}

void chain_tip(Vector q, Matrix table, Matrix base, Matrix tool, MatrixOut T, MatrixOut Jg) {
    const ChainArmModel arm = chain_arm_model(table, base, &tool, nullptr);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    expect_shape(T.shape(0), T.shape(1), 4, 4, "T", "(4, 4)");
    expect_shape(Jg.shape(0), Jg.shape(1), 6, n, "Jg", "(6, n)");
    std::vector<ChainBody> work(n + 1);
    chain_arm_tip(arm, q.data(), work.data(), T.data(), Jg.data());
}

// ---- DH arm ------------------------------------------------------------------------------------------------

DHArmModel dh_arm_model(const Matrix& dh, const Matrix& base, const Matrix* tool, const Vector* gravity) {
    expect(dh.shape(1) == sizeof(DHLink) / sizeof(double) && dh.shape(0) >= 1, "dh",
           "at least one row of 16 columns (a, alpha, d, offset, mass, com(3), inertia(6), motor_inertia, "
           "viscous)");
    DHArmModel arm{};
    arm.dof = static_cast<int>(dh.shape(0));
    arm.links = reinterpret_cast<const DHLink*>(dh.data());
    copy_pose(base, "base", arm.base);
    if (tool) copy_pose(*tool, "tool", arm.tool);
    if (gravity) copy_gravity(*gravity, arm.gravity);
    return arm;
}

int dh_terms(Vector q, Vector dq, Matrix dh, Matrix base, Matrix tool, Vector gravity, MatrixOut H, VectorOut h,
             VectorOut Y, MatrixOut J, VectorOut Jdq) {
    const DHArmModel arm = dh_arm_model(dh, base, &tool, &gravity);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    expect_joint_vector(dq, n, "dq");
    expect_terms_outputs(n, H, h, Y, J, Jdq);
    std::vector<DHFrame> work(n + 1);
    return dh_arm_terms(arm, q.data(), dq.data(), H.data(), h.data(), Y.data(), J.data(), Jdq.data(),
                        work.data());
}

double dh_potential(Vector q, Matrix dh, Matrix base, Vector gravity) {
    const DHArmModel arm = dh_arm_model(dh, base, nullptr, &gravity);
    expect_joint_vector(q, static_cast<size_t>(arm.dof), "q");
    return dh_arm_potential(arm, q.data());
}

void dh_tip(Vector q, Matrix dh, Matrix base, Matrix tool, MatrixOut T, MatrixOut Jg) {
    const DHArmModel arm = dh_arm_model(dh, base, &tool, nullptr);
    const size_t n = static_cast<size_t>(arm.dof);
    expect_joint_vector(q, n, "q");
    expect_shape(T.shape(0), T.shape(1), 4, 4, "T", "(4, 4)");
    expect_shape(Jg.shape(0), Jg.shape(1), 6, n, "Jg", "(6, n)");
    std::vector<double> axes(3 * n), points(3 * n);
    dh_arm_tip(arm, q.data(), axes.data(), points.data(), T.data(), Jg.data());
}

}  // namespace

void bind_arms(nb::module_& m) {
    m.attr("COULOMB_SMOOTHING") = COULOMB_SMOOTHING;
    m.attr("JOINT_REVOLUTE_Z") = static_cast<int>(JOINT_REVOLUTE_Z);
    m.attr("JOINT_REVOLUTE") = static_cast<int>(JOINT_REVOLUTE);
    m.attr("JOINT_PRISMATIC") = static_cast<int>(JOINT_PRISMATIC);
    m.def("chain_arm_terms", &chain_terms_world, nb::arg("q"), nb::arg("dq"), nb::arg("table"), nb::arg("base"),
          nb::arg("tool"), nb::arg("gravity"), nb::arg("H"), nb::arg("h"), nb::arg("Y"), nb::arg("J"),
          nb::arg("Jdq"),
          "Fill H, h, Y, J and Jdq of a serial chain in place (plants/core/chain_arm.h); returns 0, or 1 at the "
          "singularity of the tip's Euler angles (angular rows of J and Jdq zero).");
    m.def("chain_arm_terms_own_chart", &chain_terms_own_chart, nb::arg("q"), nb::arg("dq"), nb::arg("table"),
          nb::arg("base"), nb::arg("tool"), nb::arg("gravity"), nb::arg("H"), nb::arg("h"), nb::arg("Y"),
          nb::arg("J"), nb::arg("Jdq"), nb::arg("chart"),
          "chain_arm_terms with the node's angles in its own chart (Y[3:6] = 0); chart (3x3) receives R_tip(q).");
    m.def("chain_arm_pose", &chain_pose, nb::arg("q"), nb::arg("table"), nb::arg("base"), nb::arg("tool"),
          nb::arg("own_chart"), nb::arg("Y"),
          "The node pose Y (6) of chain_arm_terms alone (forward kinematics), bit for bit; the same return value.");
    m.def("chain_arm_potential", &chain_potential, nb::arg("q"), nb::arg("table"), nb::arg("base"),
          nb::arg("gravity"), "The gravitational potential energy of a serial chain's links [J].");
    m.def("chain_arm_tip", &chain_tip, nb::arg("q"), nb::arg("table"), nb::arg("base"), nb::arg("tool"),
          nb::arg("T"), nb::arg("Jg"),
          "The node frame's world pose T (4x4) and geometric Jacobian Jg (6 x n: v; omega) in place.");
    m.def("dh_arm_terms", &dh_terms, nb::arg("q"), nb::arg("dq"), nb::arg("dh"), nb::arg("base"), nb::arg("tool"),
          nb::arg("gravity"), nb::arg("H"), nb::arg("h"), nb::arg("Y"), nb::arg("J"), nb::arg("Jdq"),
          "Fill H, h, Y, J and Jdq of a DH arm in place (plants/core/dh_arm.h); returns 0, or 1 at the "
          "singularity of the tip's Euler angles (angular rows of J and Jdq zero).");
    m.def("dh_arm_potential", &dh_potential, nb::arg("q"), nb::arg("dh"), nb::arg("base"), nb::arg("gravity"),
          "The gravitational potential energy of a DH arm's links [J].");
    m.def("dh_arm_tip", &dh_tip, nb::arg("q"), nb::arg("dh"), nb::arg("base"), nb::arg("tool"), nb::arg("T"),
          nb::arg("Jg"),
          "The node frame's world pose T (4x4) and geometric Jacobian Jg (6 x n: v; omega) of a DH arm in place.");
}

}  // namespace plants::binding
