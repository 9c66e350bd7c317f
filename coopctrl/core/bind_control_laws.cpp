// The control laws in coopctrl._core (coopctrl/core/control_laws.h), for Python callers and the tests.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "plants/core/binding_checks.h"
#include "coopctrl/core/control_laws.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using plants::binding::expect;
using plants::binding::Matrix;
using plants::binding::Vector;
using plants::binding::VectorOut;

/// The laws' work arrays for arms of up to nmax joints.
struct OwnedWork {
    std::vector<double> vectors, matrices, posture;
    std::vector<int64_t> piv;
    ControlWork work{};
    explicit OwnedWork(int nmax)
        : vectors(WORK_VECTORS * nmax), matrices(WORK_MATRICES * nmax * nmax), posture(nmax),
          piv(nmax) {
        work.nmax = nmax;
        work.vectors = vectors.data();
        work.matrices = matrices.data();
        work.piv = piv.data();
        work.posture = posture.data();
    }
};

bool arm_torque_py(bool contact, int n, Matrix W, Vector w_free, Vector S, Matrix H, Vector h, Matrix J, Vector Jdq,
                   Vector a_cmd, Vector q, Vector dq, Vector q_rest, Vector posture_gain, VectorOut tau) {
    const int p = static_cast<int>(a_cmd.shape(0));
    expect(W.shape(0) == static_cast<size_t>(p) && W.shape(1) == static_cast<size_t>(p), "W", "shape (p, p)");
    expect(w_free.shape(0) == static_cast<size_t>(p) && S.shape(0) == static_cast<size_t>(p) &&
               Jdq.shape(0) == static_cast<size_t>(p), "w_free, S, Jdq", "length p");
    expect(J.shape(0) == static_cast<size_t>(p), "J", "p rows");
    const int cols = contact ? p : n;
    expect(n >= 1 && static_cast<int>(J.shape(1)) >= (contact ? 0 : n) && static_cast<int>(H.shape(0)) >= (contact ? 0 : n) &&
               static_cast<int>(H.shape(1)) >= (contact ? 0 : n) && static_cast<int>(h.shape(0)) >= (contact ? 0 : n),
           "H, h, J", "at least n joints");
    expect(static_cast<int>(tau.shape(0)) >= cols, "tau", "at least n (p for a contact point) entries");
    if (!contact && n > p)
        expect(static_cast<int>(q.shape(0)) >= n && static_cast<int>(dq.shape(0)) >= n &&
                   static_cast<int>(q_rest.shape(0)) >= n && posture_gain.shape(0) == 2,
               "q, dq, q_rest, posture_gain", "n joints each and (Kp, Kd)");
    OwnedWork owned(std::max(n, p));
    return arm_torque(contact, n, p, W.data(), w_free.data(), S.data(), H.data(), static_cast<int>(H.shape(1)),
                      h.data(), J.data(), static_cast<int>(J.shape(1)), Jdq.data(), a_cmd.data(), q.data(), dq.data(),
                      q_rest.data(), posture_gain.data(), owned.work, tau.data());
}

bool pose_increment_py(bool spatial, Matrix C, Vector F, Vector Y0, Vector Yi, VectorOut out) {
    const size_t p = spatial ? 6 : 3;
    expect(C.shape(0) == p && C.shape(1) == p, "C", "shape (p, p)");
    expect(F.shape(0) == p && Y0.shape(0) == p && Yi.shape(0) == p && out.shape(0) == p, "F, Y0, Yi, out",
           "length p");
    OwnedWork owned(static_cast<int>(p));
    return pose_increment(spatial, C.data(), F.data(), Y0.data(), Yi.data(), owned.work, out.data());
}

void follower_correction_py(Vector F_cmd, Vector F_seen, VectorOut integral, double T, double kp, double ki,
                            double integral_limit, bool force_loop, VectorOut corr) {
    const size_t p = corr.shape(0);
    expect(F_cmd.shape(0) == p && F_seen.shape(0) == p && integral.shape(0) == p, "F_cmd, F_seen, integral",
           "the length of corr");
    follower_correction(F_cmd.data(), F_seen.data(), integral.data(), T, kp, ki, integral_limit, force_loop,
                        static_cast<int>(p), corr.data());
}

void tracking_acceleration_py(Vector target, Vector Y, Vector dY_ref, Vector dY, Vector ddY_ref, double Kp,
                              double Kd, int npos, VectorOut err, VectorOut a_cmd) {
    const size_t p = a_cmd.shape(0);
    expect(target.shape(0) == p && Y.shape(0) == p && dY_ref.shape(0) == p && dY.shape(0) == p &&
               ddY_ref.shape(0) == p && err.shape(0) == p, "target, Y, dY_ref, dY, ddY_ref, err",
           "the length of a_cmd");
    tracking_acceleration(target.data(), Y.data(), dY_ref.data(), dY.data(), ddY_ref.data(), Kp, Kd,
                          static_cast<int>(p), npos, err.data(), a_cmd.data());
}

bool node_torque_py(bool contact, Matrix W, Vector w_free, Vector S, Matrix H, Vector h, Matrix J, Vector Jdq,
                    Vector a_cmd, std::optional<Vector> tau_posture, VectorOut tau) {
    const size_t p = a_cmd.shape(0);
    const size_t n = contact ? p : H.shape(0);
    expect(W.shape(0) == p && W.shape(1) == p, "W", "shape (p, p)");
    expect(w_free.shape(0) == p && S.shape(0) == p && Jdq.shape(0) == p, "w_free, S, Jdq", "length p");
    if (!contact)
        expect(H.shape(1) == n && h.shape(0) >= n && J.shape(0) == p && J.shape(1) >= n, "H, h, J",
               "H (n, n), h (n,), J (p, >= n)");
    expect(tau.shape(0) >= n, "tau", "at least n (p for a contact point) entries");
    const bool redundant = !contact && n > p;
    if (redundant && tau_posture) expect(tau_posture->shape(0) >= n, "tau_posture", "n entries");
    OwnedWork owned(static_cast<int>(std::max(n, p)));
    const int ldH = contact ? 0 : static_cast<int>(H.shape(1)), ldJ = contact ? 0 : static_cast<int>(J.shape(1));
    if (redundant) {
        std::vector<double> zero(n, 0.0);
        const double* t0 = tau_posture ? tau_posture->data() : zero.data();
        return node_torque_redundant(W.data(), w_free.data(), S.data(), H.data(), ldH, h.data(), J.data(), ldJ,
                                     Jdq.data(), a_cmd.data(), t0, static_cast<int>(n), static_cast<int>(p),
                                     owned.work, tau.data());
    }
    return node_torque(W.data(), w_free.data(), S.data(), H.data(), ldH, h.data(), J.data(), ldJ, Jdq.data(),
                       a_cmd.data(), contact, static_cast<int>(n), static_cast<int>(p), owned.work, tau.data());
}

void pose_error_py(Vector target, Vector Y, int npos, VectorOut out) {
    const size_t p = target.shape(0);
    expect(Y.shape(0) == p && out.shape(0) == p, "Y, out", "the length of target");
    pose_error(target.data(), Y.data(), static_cast<int>(p), npos, out.data());
}

void posture_torque_py(Matrix H, Vector q, Vector dq, Vector q_rest, int n, double Kp, double Kd, VectorOut out) {
    expect(n >= 1 && H.shape(0) >= static_cast<size_t>(n) && H.shape(1) >= static_cast<size_t>(n), "H, n",
           "n >= 1 and H at least (n, n)");
    expect(q.shape(0) >= static_cast<size_t>(n) && dq.shape(0) >= static_cast<size_t>(n) &&
               q_rest.shape(0) >= static_cast<size_t>(n) && out.shape(0) >= static_cast<size_t>(n),
           "q, dq, q_rest, out", "at least n entries each");
    posture_torque(H.data(), static_cast<int>(H.shape(1)), q.data(), dq.data(), q_rest.data(), n, Kp, Kd, out.data());
}

}  // namespace

void bind_control_laws(nb::module_& m) {
    m.def("arm_torque", &arm_torque_py, nb::arg("contact"), nb::arg("n"), nb::arg("W"), nb::arg("w_free"),
          nb::arg("S"), nb::arg("H"), nb::arg("h"), nb::arg("J"), nb::arg("Jdq"), nb::arg("a_cmd"), nb::arg("q"),
          nb::arg("dq"), nb::arg("q_rest"), nb::arg("posture_gain"), nb::arg("tau"),
          "The joint torques [N m] that give the node a_cmd (coopctrl/core/control_laws.h); returns ok.");
    m.def("pose_increment", &pose_increment_py, nb::arg("spatial"), nb::arg("C"), nb::arg("F"), nb::arg("Y0"),
          nb::arg("Yi"), nb::arg("out"), "The node pose increment [m, rad] through the grasp compliance C.");
    m.def("follower_correction", &follower_correction_py, nb::arg("F_cmd"), nb::arg("F_seen"), nb::arg("integral"),
          nb::arg("T"), nb::arg("kp"), nb::arg("ki"), nb::arg("integral_limit"), nb::arg("force_loop"),
          nb::arg("corr"), "The followers' force PI in wrench units (integral updated in place).");
    m.def("tracking_acceleration", &tracking_acceleration_py, nb::arg("target"), nb::arg("Y"), nb::arg("dY_ref"),
          nb::arg("dY"), nb::arg("ddY_ref"), nb::arg("Kp"), nb::arg("Kd"), nb::arg("npos"), nb::arg("err"),
          nb::arg("a_cmd"), "The computed-torque motion loop's commanded node acceleration.");
    m.def("node_torque", &node_torque_py, nb::arg("contact"), nb::arg("W"), nb::arg("w_free"), nb::arg("S"),
          nb::arg("H"), nb::arg("h"), nb::arg("J"), nb::arg("Jdq"), nb::arg("a_cmd"), nb::arg("tau_posture").none(),
          nb::arg("tau").noconvert(),
          "The computed torque tau[:n] [N m] of an arm of n = H.shape[0] joints (a contact point: tau[:p], the node\n"
          "wrench); a redundant arm (n > p) adds the null-space torque of tau_posture (None: zero). Returns ok.");
    m.def("pose_error", &pose_error_py, nb::arg("target"), nb::arg("Y"), nb::arg("npos"), nb::arg("out").noconvert(),
          "out = target - Y with the angles (a >= npos) wrapped into [-pi, pi) [m, rad].");
    m.def("posture_torque", &posture_torque_py, nb::arg("H"), nb::arg("q"), nb::arg("dq"), nb::arg("q_rest"),
          nb::arg("n"), nb::arg("Kp"), nb::arg("Kd"), nb::arg("out").noconvert(),
          "The null-space posture torque tau_0 = m_bar (Kp (q_rest - q) - Kd dq), m_bar = tr(H) / n [N m].");
}

}  // namespace coopctrl::binding
