// The frames' kernels in plants._core (plants/core/frames.h): each fills its output arrays in place.
#include "plants/core/binding_checks.h"
#include "plants/core/frames.h"

namespace plants::binding {

namespace {

using Tensor3Out = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

void expect_matrix(const MatrixOut& M, size_t rows, size_t cols, const char* name) {
    expect(M.shape(0) == rows && M.shape(1) == cols, name,
           "shape (" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
}

void expect_rotation(const Matrix& M, const char* name) {
    expect(M.shape(0) == 3 && M.shape(1) == 3, name, "shape (3, 3)");
}

void rotation_zyx_into(Vector A, MatrixOut R) {
    expect_length(A.shape(0), 3, "A");
    expect_matrix(R, 3, 3, "R");
    rotation_zyx(A.data(), R.data());
}

void rotation_zyx_partials_into(Vector A, MatrixOut dpsi, MatrixOut dth, MatrixOut dph) {
    expect_length(A.shape(0), 3, "A");
    expect_matrix(dpsi, 3, 3, "dpsi");
    expect_matrix(dth, 3, 3, "dth");
    expect_matrix(dph, 3, 3, "dph");
    rotation_zyx_partials(A.data(), dpsi.data(), dth.data(), dph.data());
}

void rotation_zyx_and_partials_into(Vector A, MatrixOut R, Tensor3Out dR) {
    expect_length(A.shape(0), 3, "A");
    expect_matrix(R, 3, 3, "R");
    expect(dR.shape(0) == 3 && dR.shape(1) == 3 && dR.shape(2) == 3, "dR", "shape (3, 3, 3)");
    rotation_zyx_and_partials(A.data(), R.data(), dR.data());
}

void euler_zyx_from_rotation_into(Matrix R, VectorOut A) {
    expect_rotation(R, "R");
    expect_length(A.shape(0), 3, "A");
    euler_zyx_from_rotation(R.data(), A.data());
}

void rotation_vector_into(Matrix M, VectorOut out) {
    expect_rotation(M, "M");
    expect_length(out.shape(0), 3, "out");
    rotation_vector(M.data(), out.data());
}

void body_rate_map_into(Vector A, MatrixOut L) {
    expect_length(A.shape(0), 3, "A");
    expect_matrix(L, 3, 3, "L");
    body_rate_map(A.data(), L.data());
}

void body_rate_map_dot_into(Vector A, Vector dA, MatrixOut Ld) {
    expect_length(A.shape(0), 3, "A");
    expect_length(dA.shape(0), 3, "dA");
    expect_matrix(Ld, 3, 3, "Ld");
    body_rate_map_dot(A.data(), dA.data(), Ld.data());
}

bool body_rate_map_inverse_into(Vector A, MatrixOut Linv) {
    expect_length(A.shape(0), 3, "A");
    expect_matrix(Linv, 3, 3, "Linv");
    return body_rate_map_inverse(A.data(), Linv.data());
}

void rotation_planar_into(double theta, MatrixOut R) {
    expect_matrix(R, 2, 2, "R");
    rotation_planar(theta, R.data());
}

}  // namespace

void bind_frames(nb::module_& m) {
    m.attr("EULER_SINGULARITY_COS") = EULER_SINGULARITY_COS;
    m.def("rotation_zyx_into", &rotation_zyx_into, nb::arg("A"), nb::arg("R"),
          "R (3x3) = R(A) = Rz(psi) Ry(theta) Rx(phi) for A = (psi, theta, phi) [rad] (plants/core/frames.h).");
    m.def("rotation_zyx_partials_into", &rotation_zyx_partials_into, nb::arg("A"), nb::arg("dpsi"), nb::arg("dth"),
          nb::arg("dph"), "The partials dR/dpsi, dR/dtheta, dR/dphi of R(A), each 3x3, in place.");
    m.def("rotation_zyx_and_partials_into", &rotation_zyx_and_partials_into, nb::arg("A"), nb::arg("R"),
          nb::arg("dR"), "R(A) (3x3) and its partials dR (3, 3, 3: psi, theta, phi) in place.");
    m.def("euler_zyx_from_rotation_into", &euler_zyx_from_rotation_into, nb::arg("R"), nb::arg("A"),
          "The ZYX Euler angles A (3) [rad] of the rotation matrix R (3x3), theta in [-pi/2, pi/2].");
    m.def("rotation_vector_into", &rotation_vector_into, nb::arg("M"), nb::arg("out"),
          "The rotation vector [rad] of the rotation matrix M (3x3) into out (3).");
    m.def("body_rate_map_into", &body_rate_map_into, nb::arg("A"), nb::arg("L"),
          "L (3x3) = L(A), omega_body = L(A) dA/dt (105).");
    m.def("body_rate_map_dot_into", &body_rate_map_dot_into, nb::arg("A"), nb::arg("dA"), nb::arg("Ld"),
          "Ld (3x3) = dL/dt at the angles A [rad] and the Euler rates dA [rad/s].");
    m.def("body_rate_map_inverse_into", &body_rate_map_inverse_into, nb::arg("A"), nb::arg("Linv"),
          "Linv (3x3) = L(A)^-1; False (Linv untouched) where |cos(theta)| < EULER_SINGULARITY_COS.");
    m.def("rotation_planar_into", &rotation_planar_into, nb::arg("theta"), nb::arg("R"),
          "R (2x2) = the rotation by theta [rad] in the (x, z) plane, from +x towards +z.");
}

}  // namespace plants::binding
