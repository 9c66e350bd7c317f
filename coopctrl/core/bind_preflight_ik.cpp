// Pre-flight's inverse kinematics in coopctrl._core (coopctrl/core/preflight_ik.h), with the numba kernels'
// arguments (coopctrl/analysis/preflight_ik.py) and the settings of plants.arms.spatial_ik passed by the caller.
// The posture refinement's LAPACK and BLAS routines are scipy's (scipy.linalg.cython_lapack, cython_blas), the
// ones numba's np.linalg.pinv and matrix products call, looked up once.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <string>

#include "coopctrl/core/preflight_ik.h"
#include "plants/core/binding_checks.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using plants::binding::expect;
using plants::binding::expect_length;
using plants::binding::Matrix;
using plants::binding::MatrixOut;
using plants::binding::Vector;
using plants::binding::VectorOut;
using Tensor = nb::ndarray<const double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using IntVector = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

/// The function a Cython module exports under name (its __pyx_capi__ capsule), as numba looks it up.
void* cython_function(const char* module, const char* name) {
    nb::object capi = nb::module_::import_(module).attr("__pyx_capi__");
    nb::object capsule = capi[name];
    PyObject* c = capsule.ptr();
    void* f = PyCapsule_GetPointer(c, PyCapsule_GetName(c));
    if (f == nullptr) throw nb::python_error();
    return f;
}

const DenseRoutines& dense_routines() {
    static const DenseRoutines routines{
        reinterpret_cast<DgesddRoutine*>(cython_function("scipy.linalg.cython_lapack", "dgesdd")),
        reinterpret_cast<DgemmRoutine*>(cython_function("scipy.linalg.cython_blas", "dgemm")),
        reinterpret_cast<DgemvRoutine*>(cython_function("scipy.linalg.cython_blas", "dgemv"))};
    return routines;
}

void copy_pose(const Matrix& T, const char* name, double* out) {
    expect(T.shape(0) == 4 && T.shape(1) == 4, name, "shape (4, 4)");
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j) out[4 * i + j] = T(i, j);
}

/// The arm of the numba kernels' (kind, table, base, tool, lower, upper), checked against q.
SpatialIKArm spatial_arm(int kind, const Matrix& table, const Matrix& base, const Matrix& tool, const Vector& lower,
                         const Vector& upper, const VectorOut& q) {
    expect(kind == IK_KIND_DH || kind == IK_KIND_CHAIN, "kind", "0 (a DH table) or 1 (a chain table)");
    const size_t n = table.shape(0);
    SpatialIKArm arm{};
    arm.kind = static_cast<SpatialIKKind>(kind);
    if (kind == IK_KIND_DH) {
        expect(table.shape(1) == sizeof(plants::DHLink) / sizeof(double), "table", "16 columns (a DH table)");
        arm.dh.dof = static_cast<int>(n);
        arm.dh.links = reinterpret_cast<const plants::DHLink*>(table.data());
        copy_pose(base, "base", arm.dh.base);
        copy_pose(tool, "tool", arm.dh.tool);
    } else {
        expect(table.shape(1) == sizeof(plants::ChainJointRow) / sizeof(double), "table", "32 columns (a chain table)");
        arm.chain.dof = static_cast<int>(n);
        arm.chain.joints = reinterpret_cast<const plants::ChainJointRow*>(table.data());
        copy_pose(base, "base", arm.chain.base);
        copy_pose(tool, "tool", arm.chain.tool);
    }
    expect(n >= 1, "table", "at least one joint");
    expect_length(lower.shape(0), n, "lower");
    expect_length(upper.shape(0), n, "upper");
    expect_length(q.shape(0), n, "q");
    arm.lower = lower.data();
    arm.upper = upper.data();
    return arm;
}

bool spatial_ik_py(int kind, Matrix table, Matrix base, Matrix tool, Vector lower, Vector upper, Vector target,
                   VectorOut q, double tolerance) {
    const SpatialIKArm arm = spatial_arm(kind, table, base, tool, lower, upper, q);
    expect_length(target.shape(0), 6, "target");
    return spatial_ik(arm, IKSettings{tolerance, 0, 0.0}, target.data(), q.data());
}

void refine_posture_py(int kind, Matrix table, Matrix base, Matrix tool, Vector lower, Vector upper, Vector posture,
                       Vector target, VectorOut q, double tolerance, int posture_iterations, double posture_step) {
    const SpatialIKArm arm = spatial_arm(kind, table, base, tool, lower, upper, q);
    expect_length(posture.shape(0), q.shape(0), "posture");
    expect_length(target.shape(0), 6, "target");
    const PostureStatus status =
        spatial_refine_posture(arm, IKSettings{tolerance, posture_iterations, posture_step}, dense_routines(),
                               posture.data(), target.data(), q.data());
    if (status == POSTURE_NOT_FINITE) {
        nb::object error = nb::module_::import_("numpy.linalg").attr("LinAlgError");
        PyErr_SetString(error.ptr(), "Array must not contain infs or NaNs.");
        throw nb::python_error();
    }
    if (status == POSTURE_SVD_FAILED) throw nb::value_error("Internal algorithm failed to converge");
}

bool planar_ik_py(Matrix links, Vector base, Vector tool, Vector gravity, Vector lower, Vector upper, Vector target,
                  VectorOut q, double tolerance) {
    const size_t n = links.shape(0);
    expect(n >= 1 && links.shape(1) == sizeof(plants::PlanarLink) / sizeof(double), "links",
           "at least one row of 7 columns (a planar link table)");
    expect_length(base.shape(0), 3, "base");
    expect_length(tool.shape(0), 3, "tool");
    expect_length(gravity.shape(0), 2, "gravity");
    expect_length(lower.shape(0), n, "lower");
    expect_length(upper.shape(0), n, "upper");
    expect_length(target.shape(0), 3, "target");
    expect_length(q.shape(0), n, "q");
    PlanarIKArm arm{};
    arm.arm.dof = static_cast<int>(n);
    arm.arm.links = reinterpret_cast<const plants::PlanarLink*>(links.data());
    for (int c = 0; c < 3; ++c) {
        arm.arm.base[c] = base(c);
        arm.arm.tool[c] = tool(c);
    }
    arm.arm.gravity[0] = gravity(0);
    arm.arm.gravity[1] = gravity(1);
    arm.lower = lower.data();
    arm.upper = upper.data();
    return planar_ik(arm, IKSettings{tolerance, 0, 0.0}, target.data(), q.data());
}

bool square_rates_py(Tensor J, Matrix dY, IntVector dofs, MatrixOut out) {
    const size_t m = dofs.shape(0), p = J.shape(1);
    expect(J.shape(0) == m && p >= 1 && p <= 6 && J.shape(2) >= p, "J", "shape (m, p <= 6, >= p), m = len(dofs)");
    expect(dY.shape(0) == m + 1 && dY.shape(1) >= p, "dY", "shape (m + 1, >= p)");
    expect(out.shape(0) == m && out.shape(1) >= p, "out", "shape (m, >= p)");
    return square_joint_rates(J.data(), static_cast<int>(m), static_cast<int>(p), static_cast<int>(J.shape(2)),
                              dY.data(), static_cast<int>(dY.shape(1)), dofs.data(), out.data(),
                              static_cast<int>(out.shape(1)));
}

}  // namespace

void bind_preflight_ik(nb::module_& m) {
    m.def("spatial_ik", &spatial_ik_py, nb::arg("kind"), nb::arg("table"), nb::arg("base"), nb::arg("tool"),
          nb::arg("lower"), nb::arg("upper"), nb::arg("target"), nb::arg("q").noconvert(), nb::arg("tolerance"),
          "Damped least squares from q toward the node pose target (position [m], ZYX Euler angles [rad]) of a DH\n"
          "(kind 0) or chain (kind 1) arm; q gets the answer. Returns whether it converged\n"
          "(coopctrl/core/preflight_ik.h).");
    m.def("refine_posture", &refine_posture_py, nb::arg("kind"), nb::arg("table"), nb::arg("base"), nb::arg("tool"),
          nb::arg("lower"), nb::arg("upper"), nb::arg("posture"), nb::arg("target"), nb::arg("q").noconvert(),
          nb::arg("tolerance"), nb::arg("posture_iterations"), nb::arg("posture_step"),
          "Move spatial_ik's answer q of a redundant arm along its self-motion manifold toward posture.");
    m.def("planar_ik", &planar_ik_py, nb::arg("links"), nb::arg("base"), nb::arg("tool"), nb::arg("gravity"),
          nb::arg("lower"), nb::arg("upper"), nb::arg("target"), nb::arg("q").noconvert(), nb::arg("tolerance"),
          "spatial_ik of a planar arm toward target = (x, z, theta); q gets the answer.");
    m.def("square_joint_rates_into", &square_rates_py, nb::arg("J"), nb::arg("dY"), nb::arg("dofs"),
          nb::arg("out").noconvert(),
          "Each arm's joint rates out[i, :p] solving J[i, :, :p] dq_i = dY[i + 1] where every arm's Jacobian is\n"
          "square and regular; False (out undefined) if one is not.");
}

}  // namespace coopctrl::binding
