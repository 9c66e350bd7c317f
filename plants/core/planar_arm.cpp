#include "plants/core/planar_arm.h"

#include <cmath>
#include "plants/core/frames.h"

namespace plants {

namespace {
// Columns of one row k of the work array (row n holds the end of the last link).
constexpr int O = 0;   // 2: joint k position (row n: end of the last link)
constexpr int TH = 2;  // 1: absolute angle of link k
constexpr int W = 3;   // 1: angular velocity of link k
constexpr int A = 4;   // 2: acceleration of o_k (with -g), as a point of link k (qdd = 0)
constexpr int C = 6;   // 2: centre of mass of link k
constexpr int F = 8;   // 2: inertial force of link k
}  // namespace

int planar_arm_terms(const PlanarArmModel& arm, const double* q, const double* dq, double* H, int ldH, double* h,
                     double* Y, double* J, int ldJ, double* Jdq, double* work) noexcept {
    const int n = arm.dof;
    const double gx = arm.gravity[0], gz = arm.gravity[1];
    double ox = arm.base[0], oz = arm.base[1];
    double th = arm.base[2];
    double w = 0.0;
    double ax = -gx, az = -gz;
    for (int k = 0; k < n; ++k) {
        double* r = work + k * PLANAR_WORK_WIDTH;
        const PlanarLink& link = arm.links[k];
        th += q[k];
        w += dq[k];
        r[O] = ox; r[O + 1] = oz; r[TH] = th; r[W] = w;
        r[A] = ax; r[A + 1] = az;
        const auto [st, ct] = sin_cos(th);
        // the centre of mass and its acceleration (alpha = 0 with qdd = 0): a_c = a_o - w^2 d
        const double sx = ct * link.rc_x - st * link.rc_y;
        const double sz = st * link.rc_x + ct * link.rc_y;
        r[C] = ox + sx; r[C + 1] = oz + sz;
        const double w2 = w * w;
        r[F] = link.mass * (ax - w2 * sx);
        r[F + 1] = link.mass * (az - w2 * sz);
        // the next joint
        const double lx = link.length * ct, lz = link.length * st;
        ox += lx;
        oz += lz;
        ax -= w2 * lx;
        az -= w2 * lz;
    }
    double* e = work + n * PLANAR_WORK_WIDTH;
    e[O] = ox; e[O + 1] = oz; e[TH] = th; e[W] = w; e[A] = ax; e[A + 1] = az;

    // backward pass: moments about o_k (the inertial moments Izz * alpha vanish with qdd = 0)
    double Fx = 0.0, Fz = 0.0, M = 0.0;
    for (int k = n - 1; k >= 0; --k) {
        const double* r = work + k * PLANAR_WORK_WIDTH;
        const double* next = r + PLANAR_WORK_WIDTH;
        const double px = r[O], pz = r[O + 1];
        const double dx = r[C] - px, dz = r[C + 1] - pz;
        const double ex = next[O] - px, ez = next[O + 1] - pz;
        const double fx = r[F], fz = r[F + 1];
        M = (dx * fz - dz * fx) + M + (ex * Fz - ez * Fx);
        Fx += fx;
        Fz += fz;
        h[k] = M + arm.links[k].viscous * dq[k];
    }

    // composite rigid bodies about o_i: mass Mc, first moment (hx, hz), inertia Ic
    double Mc = 0.0, hx = 0.0, hz = 0.0, Ic = 0.0;
    for (int i = n - 1; i >= 0; --i) {
        const double* r = work + i * PLANAR_WORK_WIDTH;
        const double* next = r + PLANAR_WORK_WIDTH;
        const PlanarLink& link = arm.links[i];
        const double px = r[O], pz = r[O + 1];
        const double ex = next[O] - px, ez = next[O + 1] - pz;
        Ic += 2.0 * (hx * ex + hz * ez) + Mc * (ex * ex + ez * ez);
        hx += Mc * ex;
        hz += Mc * ez;
        const double m = link.mass;
        const double dx = r[C] - px, dz = r[C + 1] - pz;
        Ic += link.Izz + m * (dx * dx + dz * dz);
        hx += m * dx;
        hz += m * dz;
        Mc += m;
        // a unit acceleration of joint i: the force 1 x h = (-hz, hx)
        const double fx = -hz, fz = hx;
        H[i * ldH + i] = Ic + link.motor_inertia;
        for (int j = i - 1; j >= 0; --j) {
            const double* rj = work + j * PLANAR_WORK_WIDTH;
            const double rx = px - rj[O], rz = pz - rj[O + 1];
            const double v = Ic + (rx * fz - rz * fx);
            H[j * ldH + i] = v;
            H[i * ldH + j] = v;
        }
    }

    // the tip
    const auto [st, ct] = sin_cos(th);
    const double tx = ox + ct * arm.tool[0] - st * arm.tool[1];
    const double tz = oz + st * arm.tool[0] + ct * arm.tool[1];
    Y[0] = tx; Y[1] = tz; Y[2] = th + arm.tool[2];
    for (int k = 0; k < n; ++k) {
        const double* r = work + k * PLANAR_WORK_WIDTH;
        J[k] = -(tz - r[O + 1]);
        J[ldJ + k] = tx - r[O];
        J[2 * ldJ + k] = 1.0;
    }
    const double w2 = w * w;
    Jdq[0] = ax - w2 * (tx - ox) + gx;
    Jdq[1] = az - w2 * (tz - oz) + gz;
    Jdq[2] = 0.0;
    return 0;
}

double planar_arm_potential(const PlanarArmModel& arm, const double* q) noexcept {
    double ox = arm.base[0], oz = arm.base[1], th = arm.base[2];
    double U = 0.0;
    for (int k = 0; k < arm.dof; ++k) {
        const PlanarLink& link = arm.links[k];
        th += q[k];
        const auto [st, ct] = sin_cos(th);
        const double cx = ox + ct * link.rc_x - st * link.rc_y;
        const double cz = oz + st * link.rc_x + ct * link.rc_y;
        U -= link.mass * (arm.gravity[0] * cx + arm.gravity[1] * cz);
        ox += link.length * ct;
        oz += link.length * st;
    }
    return U;
}

}  // namespace plants
