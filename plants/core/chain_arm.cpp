#include "plants/core/chain_arm.h"

#include <cmath>

#include "plants/core/frames.h"

namespace plants {

namespace {

/// Body 0's frame: the base pose.
void set_base_frame(const double* base, ChainBody& b) noexcept {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) b.R[3 * i + j] = base[4 * i + j];
        b.o[i] = base[4 * i + 3];
    }
}

bool is_prismatic(const ChainJointRow& joint) noexcept {
    return static_cast<int>(joint.type) == JOINT_PRISMATIC;
}

}  // namespace

void chain_link_frame(const ChainBody& __restrict p, const ChainJointRow& joint, double qk,
                      ChainBody& __restrict c) noexcept {
    const int kind = static_cast<int>(joint.type);
    const double* Ro = joint.rotation;
    const double o00 = Ro[0], o01 = Ro[1], o02 = Ro[2];
    const double o10 = Ro[3], o11 = Ro[4], o12 = Ro[5];
    const double o20 = Ro[6], o21 = Ro[7], o22 = Ro[8];
    // local rotation L = R_o M(q) and local joint axis a_o = R_o axis
    double l00, l01, l02, l10, l11, l12, l20, l21, l22;
    double ax_, ay_, az_;
    if (kind == JOINT_REVOLUTE_Z) {
        const auto [st, ct] = sin_cos(qk);
        l00 = ct * o00 + st * o01; l01 = ct * o01 - st * o00; l02 = o02;
        l10 = ct * o10 + st * o11; l11 = ct * o11 - st * o10; l12 = o12;
        l20 = ct * o20 + st * o21; l21 = ct * o21 - st * o20; l22 = o22;
        ax_ = o02; ay_ = o12; az_ = o22;
    } else {
        const double ax = joint.axis[0], ay = joint.axis[1], az = joint.axis[2];
        ax_ = o00 * ax + o01 * ay + o02 * az;
        ay_ = o10 * ax + o11 * ay + o12 * az;
        az_ = o20 * ax + o21 * ay + o22 * az;
        if (kind == JOINT_PRISMATIC) {
            l00 = o00; l01 = o01; l02 = o02;
            l10 = o10; l11 = o11; l12 = o12;
            l20 = o20; l21 = o21; l22 = o22;
        } else {
            // Rodrigues: Rot = c I + s [a]x + (1 - c) a a^T
            const auto [st, ct] = sin_cos(qk);
            const double vt = 1.0 - ct;
            const double m00 = ct + vt * ax * ax, m01 = vt * ax * ay - st * az, m02 = vt * ax * az + st * ay;
            const double m10 = vt * ax * ay + st * az, m11 = ct + vt * ay * ay, m12 = vt * ay * az - st * ax;
            const double m20 = vt * ax * az - st * ay, m21 = vt * ay * az + st * ax, m22 = ct + vt * az * az;
            l00 = o00 * m00 + o01 * m10 + o02 * m20;
            l01 = o00 * m01 + o01 * m11 + o02 * m21;
            l02 = o00 * m02 + o01 * m12 + o02 * m22;
            l10 = o10 * m00 + o11 * m10 + o12 * m20;
            l11 = o10 * m01 + o11 * m11 + o12 * m21;
            l12 = o10 * m02 + o11 * m12 + o12 * m22;
            l20 = o20 * m00 + o21 * m10 + o22 * m20;
            l21 = o20 * m01 + o21 * m11 + o22 * m21;
            l22 = o20 * m02 + o21 * m12 + o22 * m22;
        }
    }
    const double ox = joint.origin[0], oy = joint.origin[1], oz = joint.origin[2];
    for (int i = 0; i < 3; ++i) {
        const double r0 = p.R[3 * i], r1 = p.R[3 * i + 1], r2 = p.R[3 * i + 2];
        c.R[3 * i] = r0 * l00 + r1 * l10 + r2 * l20;
        c.R[3 * i + 1] = r0 * l01 + r1 * l11 + r2 * l21;
        c.R[3 * i + 2] = r0 * l02 + r1 * l12 + r2 * l22;
        const double u = r0 * ax_ + r1 * ay_ + r2 * az_;
        c.u[i] = u;
        double o = p.o[i] + r0 * ox + r1 * oy + r2 * oz;
        if (kind == JOINT_PRISMATIC) o += u * qk;
        c.o[i] = o;
    }
}

TipPose tip_pose(const double* Rn, const double* on, const double* tool, bool own_chart, double* Y) noexcept {
    TipPose tp;
    const double t00 = Rn[0] * tool[0] + Rn[1] * tool[4] + Rn[2] * tool[8];
    const double t10 = Rn[3] * tool[0] + Rn[4] * tool[4] + Rn[5] * tool[8];
    const double t20 = Rn[6] * tool[0] + Rn[7] * tool[4] + Rn[8] * tool[8];
    const double t01 = Rn[0] * tool[1] + Rn[1] * tool[5] + Rn[2] * tool[9];
    const double t11 = Rn[3] * tool[1] + Rn[4] * tool[5] + Rn[5] * tool[9];
    const double t21 = Rn[6] * tool[1] + Rn[7] * tool[5] + Rn[8] * tool[9];
    const double t02 = Rn[0] * tool[2] + Rn[1] * tool[6] + Rn[2] * tool[10];
    const double t12 = Rn[3] * tool[2] + Rn[4] * tool[6] + Rn[5] * tool[10];
    const double t22 = Rn[6] * tool[2] + Rn[7] * tool[6] + Rn[8] * tool[10];
    const double px = on[0] + Rn[0] * tool[3] + Rn[1] * tool[7] + Rn[2] * tool[11];
    const double py = on[1] + Rn[3] * tool[3] + Rn[4] * tool[7] + Rn[5] * tool[11];
    const double pz = on[2] + Rn[6] * tool[3] + Rn[7] * tool[7] + Rn[8] * tool[11];
    Y[0] = px;
    Y[1] = py;
    Y[2] = pz;
    double cth, sth;
    if (own_chart) {
        Y[3] = 0.0;
        Y[4] = 0.0;
        Y[5] = 0.0;
        cth = 1.0;
        sth = 0.0;
    } else {
        cth = std::sqrt(t21 * t21 + t22 * t22);
        sth = -t20;
        Y[3] = std::atan2(t10, t00);
        Y[4] = std::atan2(sth, cth);
        Y[5] = std::atan2(t21, t22);
    }
    tp.p[0] = px; tp.p[1] = py; tp.p[2] = pz;
    tp.R[0] = t00; tp.R[1] = t01; tp.R[2] = t02;
    tp.R[3] = t10; tp.R[4] = t11; tp.R[5] = t12;
    tp.R[6] = t20; tp.R[7] = t21; tp.R[8] = t22;
    tp.cos_theta = cth;
    tp.sin_theta = sth;
    return tp;
}

int chain_arm_pose(const ChainArmModel& arm, const double* q, bool own_chart, ChainBody* work, double* Y) noexcept {
    const int n = arm.dof;
    set_base_frame(arm.base, work[0]);
    for (int k = 1; k <= n; ++k) chain_link_frame(work[k - 1], arm.joints[k - 1], q[k - 1], work[k]);
    const double cth = tip_pose(work[n].R, work[n].o, arm.tool, own_chart, Y).cos_theta;
    return cth < EULER_SINGULARITY_COS ? 1 : 0;
}

int chain_arm_terms(const ChainArmModel& arm, const double* q, const double* dq, double* __restrict H,
                    double* __restrict h, double* __restrict Y, double* __restrict J, double* __restrict Jdq,
                    ChainBody* __restrict work, bool own_chart, double* __restrict chart) noexcept {
    const int n = arm.dof;
    const double gx = arm.gravity[0], gy = arm.gravity[1], gz = arm.gravity[2];
    ChainBody& b = work[0];
    set_base_frame(arm.base, b);
    for (int i = 0; i < 3; ++i) {
        b.w[i] = 0.0;
        b.alpha[i] = 0.0;
    }
    b.a[0] = -gx;
    b.a[1] = -gy;
    b.a[2] = -gz;

    // ---- forward pass: kinematics, velocities, accelerations (qdd = 0), link wrenches
    for (int k = 1; k <= n; ++k) {
        const ChainBody& p = work[k - 1];
        ChainBody& c = work[k];
        const ChainJointRow& row = arm.joints[k - 1];
        chain_link_frame(p, row, q[k - 1], c);
        const bool prismatic = is_prismatic(row);
        const double ux = c.u[0], uy = c.u[1], uz = c.u[2];
        const double qd = dq[k - 1];
        const double pwx = p.w[0], pwy = p.w[1], pwz = p.w[2];
        const double palx = p.alpha[0], paly = p.alpha[1], palz = p.alpha[2];
        // a(o_k) as a point of body k-1
        const double rx = c.o[0] - p.o[0];
        const double ry = c.o[1] - p.o[1];
        const double rz = c.o[2] - p.o[2];
        double vx = pwy * rz - pwz * ry, vy = pwz * rx - pwx * rz, vz = pwx * ry - pwy * rx;
        double aox = p.a[0] + (paly * rz - palz * ry) + (pwy * vz - pwz * vy);
        double aoy = p.a[1] + (palz * rx - palx * rz) + (pwz * vx - pwx * vz);
        double aoz = p.a[2] + (palx * ry - paly * rx) + (pwx * vy - pwy * vx);
        double wx, wy, wz, alx, aly, alz;
        if (prismatic) {
            wx = pwx; wy = pwy; wz = pwz;
            alx = palx; aly = paly; alz = palz;
            aox += 2.0 * (pwy * uz - pwz * uy) * qd;
            aoy += 2.0 * (pwz * ux - pwx * uz) * qd;
            aoz += 2.0 * (pwx * uy - pwy * ux) * qd;
        } else {
            wx = pwx + ux * qd; wy = pwy + uy * qd; wz = pwz + uz * qd;
            alx = palx + (pwy * uz - pwz * uy) * qd;
            aly = paly + (pwz * ux - pwx * uz) * qd;
            alz = palz + (pwx * uy - pwy * ux) * qd;
        }
        c.w[0] = wx; c.w[1] = wy; c.w[2] = wz;
        c.alpha[0] = alx; c.alpha[1] = aly; c.alpha[2] = alz;
        c.a[0] = aox; c.a[1] = aoy; c.a[2] = aoz;
        // COM
        const double m = row.mass;
        const double lcx = row.com[0], lcy = row.com[1], lcz = row.com[2];
        const double* Rk = c.R;
        const double sx = Rk[0] * lcx + Rk[1] * lcy + Rk[2] * lcz;
        const double sy = Rk[3] * lcx + Rk[4] * lcy + Rk[5] * lcz;
        const double sz = Rk[6] * lcx + Rk[7] * lcy + Rk[8] * lcz;
        c.com[0] = c.o[0] + sx; c.com[1] = c.o[1] + sy; c.com[2] = c.o[2] + sz;
        vx = wy * sz - wz * sy; vy = wz * sx - wx * sz; vz = wx * sy - wy * sx;
        const double acx = aox + (aly * sz - alz * sy) + (wy * vz - wz * vy);
        const double acy = aoy + (alz * sx - alx * sz) + (wz * vx - wx * vz);
        const double acz = aoz + (alx * sy - aly * sx) + (wx * vy - wy * vx);
        c.force[0] = m * acx; c.force[1] = m * acy; c.force[2] = m * acz;
        // world inertia Iw = R I R^T
        const double ixx = row.inertia[0], iyy = row.inertia[1], izz = row.inertia[2];
        const double ixy = row.inertia[3], iyz = row.inertia[4], ixz = row.inertia[5];
        const double t00 = Rk[0] * ixx + Rk[1] * ixy + Rk[2] * ixz;
        const double t01 = Rk[0] * ixy + Rk[1] * iyy + Rk[2] * iyz;
        const double t02 = Rk[0] * ixz + Rk[1] * iyz + Rk[2] * izz;
        const double t10 = Rk[3] * ixx + Rk[4] * ixy + Rk[5] * ixz;
        const double t11 = Rk[3] * ixy + Rk[4] * iyy + Rk[5] * iyz;
        const double t12 = Rk[3] * ixz + Rk[4] * iyz + Rk[5] * izz;
        const double t20 = Rk[6] * ixx + Rk[7] * ixy + Rk[8] * ixz;
        const double t21 = Rk[6] * ixy + Rk[7] * iyy + Rk[8] * iyz;
        const double t22 = Rk[6] * ixz + Rk[7] * iyz + Rk[8] * izz;
        const double wxx = t00 * Rk[0] + t01 * Rk[1] + t02 * Rk[2];
        const double wyy = t10 * Rk[3] + t11 * Rk[4] + t12 * Rk[5];
        const double wzz = t20 * Rk[6] + t21 * Rk[7] + t22 * Rk[8];
        const double wxy = t00 * Rk[3] + t01 * Rk[4] + t02 * Rk[5];
        const double wyz = t10 * Rk[6] + t11 * Rk[7] + t12 * Rk[8];
        const double wxz = t00 * Rk[6] + t01 * Rk[7] + t02 * Rk[8];
        c.inertia_world[0] = wxx; c.inertia_world[1] = wyy; c.inertia_world[2] = wzz;
        c.inertia_world[3] = wxy; c.inertia_world[4] = wyz; c.inertia_world[5] = wxz;
        // n = Iw al + w x (Iw w)
        const double Iwx = wxx * wx + wxy * wy + wxz * wz;
        const double Iwy = wxy * wx + wyy * wy + wyz * wz;
        const double Iwz = wxz * wx + wyz * wy + wzz * wz;
        c.moment[0] = wxx * alx + wxy * aly + wxz * alz + (wy * Iwz - wz * Iwy);
        c.moment[1] = wxy * alx + wyy * aly + wyz * alz + (wz * Iwx - wx * Iwz);
        c.moment[2] = wxz * alx + wyz * aly + wzz * alz + (wx * Iwy - wy * Iwx);
    }

    // ---- backward pass: h (subtree wrench about o_k)
    double Fx = 0.0, Fy = 0.0, Fz = 0.0;
    double Mx = 0.0, My = 0.0, Mz = 0.0;
    for (int k = n; k >= 1; --k) {
        const ChainBody& c = work[k];
        const ChainJointRow& row = arm.joints[k - 1];
        const double ox = c.o[0], oy = c.o[1], oz = c.o[2];
        if (k < n) {
            const ChainBody& next = work[k + 1];
            const double ex = next.o[0] - ox, ey = next.o[1] - oy, ez = next.o[2] - oz;
            Mx += ey * Fz - ez * Fy;
            My += ez * Fx - ex * Fz;
            Mz += ex * Fy - ey * Fx;
        }
        const double dx = c.com[0] - ox, dy = c.com[1] - oy, dz = c.com[2] - oz;
        const double fx = c.force[0], fy = c.force[1], fz = c.force[2];
        Mx += c.moment[0] + (dy * fz - dz * fy);
        My += c.moment[1] + (dz * fx - dx * fz);
        Mz += c.moment[2] + (dx * fy - dy * fx);
        Fx += fx;
        Fy += fy;
        Fz += fz;
        double s;
        if (is_prismatic(row)) {
            s = c.u[0] * Fx + c.u[1] * Fy + c.u[2] * Fz;
        } else {
            s = c.u[0] * Mx + c.u[1] * My + c.u[2] * Mz;
        }
        s += row.viscous * dq[k - 1];
        if (row.coulomb != 0.0) s += row.coulomb * std::tanh(dq[k - 1] / COULOMB_SMOOTHING);
        h[k - 1] = s;
    }

    // ---- composite rigid bodies: H (composite of links i..n about o_i)
    double Mc = 0.0;
    double hx = 0.0, hy = 0.0, hz = 0.0;
    double cxx = 0.0, cyy = 0.0, czz = 0.0, cxy = 0.0, cyz = 0.0, cxz = 0.0;
    for (int i = n; i >= 1; --i) {
        const ChainBody& c = work[i];
        const ChainJointRow& row = arm.joints[i - 1];
        const double ox = c.o[0], oy = c.o[1], oz = c.o[2];
        if (i < n) {
            const ChainBody& next = work[i + 1];
            const double ex = next.o[0] - ox, ey = next.o[1] - oy, ez = next.o[2] - oz;
            const double he = hx * ex + hy * ey + hz * ez;
            const double ee = ex * ex + ey * ey + ez * ez;
            cxx += 2.0 * he - 2.0 * hx * ex + Mc * (ee - ex * ex);
            cyy += 2.0 * he - 2.0 * hy * ey + Mc * (ee - ey * ey);
            czz += 2.0 * he - 2.0 * hz * ez + Mc * (ee - ez * ez);
            cxy += -(hx * ey + ex * hy) - Mc * ex * ey;
            cyz += -(hy * ez + ey * hz) - Mc * ey * ez;
            cxz += -(hx * ez + ex * hz) - Mc * ex * ez;
            hx += Mc * ex;
            hy += Mc * ey;
            hz += Mc * ez;
        }
        const double m = row.mass;
        const double dx = c.com[0] - ox, dy = c.com[1] - oy, dz = c.com[2] - oz;
        const double dd = dx * dx + dy * dy + dz * dz;
        cxx += c.inertia_world[0] + m * (dd - dx * dx);
        cyy += c.inertia_world[1] + m * (dd - dy * dy);
        czz += c.inertia_world[2] + m * (dd - dz * dz);
        cxy += c.inertia_world[3] - m * dx * dy;
        cyz += c.inertia_world[4] - m * dy * dz;
        cxz += c.inertia_world[5] - m * dx * dz;
        hx += m * dx;
        hy += m * dy;
        hz += m * dz;
        Mc += m;
        const double ux = c.u[0], uy = c.u[1], uz = c.u[2];
        double Izx, Izy, Izz;
        if (is_prismatic(row)) {
            Fx = Mc * ux; Fy = Mc * uy; Fz = Mc * uz;
            Izx = hy * uz - hz * uy; Izy = hz * ux - hx * uz; Izz = hx * uy - hy * ux;
            H[(i - 1) * n + (i - 1)] = ux * Fx + uy * Fy + uz * Fz + row.motor_inertia;
        } else {
            Izx = cxx * ux + cxy * uy + cxz * uz;
            Izy = cxy * ux + cyy * uy + cyz * uz;
            Izz = cxz * ux + cyz * uy + czz * uz;
            Fx = uy * hz - uz * hy; Fy = uz * hx - ux * hz; Fz = ux * hy - uy * hx;
            H[(i - 1) * n + (i - 1)] = ux * Izx + uy * Izy + uz * Izz + row.motor_inertia;
        }
        for (int j = i - 1; j >= 1; --j) {
            const ChainBody& pj = work[j];
            double v;
            if (is_prismatic(arm.joints[j - 1])) {
                v = pj.u[0] * Fx + pj.u[1] * Fy + pj.u[2] * Fz;
            } else {
                const double rx = ox - pj.o[0], ry = oy - pj.o[1], rz = oz - pj.o[2];
                const double mx = Izx + (ry * Fz - rz * Fy);
                const double my = Izy + (rz * Fx - rx * Fz);
                const double mz = Izz + (rx * Fy - ry * Fx);
                v = pj.u[0] * mx + pj.u[1] * my + pj.u[2] * mz;
            }
            H[(j - 1) * n + (i - 1)] = v;
            H[(i - 1) * n + (j - 1)] = v;
        }
    }

    // ---- tip pose
    const ChainBody& e = work[n];
    const TipPose tp = tip_pose(e.R, e.o, arm.tool, own_chart, Y);
    const double px = tp.p[0], py = tp.p[1], pz = tp.p[2];
    const double t00 = tp.R[0], t01 = tp.R[1], t02 = tp.R[2];
    const double t10 = tp.R[3], t11 = tp.R[4], t12 = tp.R[5];
    const double t20 = tp.R[6], t21 = tp.R[7], t22 = tp.R[8];
    const double cth = tp.cos_theta, sth = tp.sin_theta;
    if (own_chart) {
        for (int i = 0; i < 9; ++i) chart[i] = tp.R[i];
    }

    // ---- translational Jacobian rows and tip acceleration
    for (int k = 1; k <= n; ++k) {
        const ChainBody& c = work[k];
        const double ux = c.u[0], uy = c.u[1], uz = c.u[2];
        if (is_prismatic(arm.joints[k - 1])) {
            J[k - 1] = ux;
            J[n + k - 1] = uy;
            J[2 * n + k - 1] = uz;
        } else {
            const double rx = px - c.o[0], ry = py - c.o[1], rz = pz - c.o[2];
            J[k - 1] = uy * rz - uz * ry;
            J[n + k - 1] = uz * rx - ux * rz;
            J[2 * n + k - 1] = ux * ry - uy * rx;
        }
    }
    const double wx = e.w[0], wy = e.w[1], wz = e.w[2];
    const double alx = e.alpha[0], aly = e.alpha[1], alz = e.alpha[2];
    {
        const double rx = px - e.o[0], ry = py - e.o[1], rz = pz - e.o[2];
        const double vx = wy * rz - wz * ry, vy = wz * rx - wx * rz, vz = wx * ry - wy * rx;
        Jdq[0] = e.a[0] + (aly * rz - alz * ry) + (wy * vz - wz * vy) + gx;
        Jdq[1] = e.a[1] + (alz * rx - alx * rz) + (wz * vx - wx * vz) + gy;
        Jdq[2] = e.a[2] + (alx * ry - aly * rx) + (wx * vy - wy * vx) + gz;
    }

    if (cth < EULER_SINGULARITY_COS) {
        for (int k = 0; k < n; ++k) {
            J[3 * n + k] = 0.0;
            J[4 * n + k] = 0.0;
            J[5 * n + k] = 0.0;
        }
        Jdq[3] = 0.0;
        Jdq[4] = 0.0;
        Jdq[5] = 0.0;
        return 1;
    }

    // ---- angular rows: dA = L^-1 R^T omega_world
    double sph, cph;
    if (own_chart) {
        sph = 0.0;
        cph = 1.0;
    } else {
        sph = t21 / cth;
        cph = t22 / cth;
    }
    const double tth = sth / cth;
    const double l01 = sph / cth, l02 = cph / cth;
    const double l11 = cph, l12 = -sph;
    const double l21 = sph * tth, l22 = cph * tth;
    const double p00 = l01 * t01 + l02 * t02;
    const double p01 = l01 * t11 + l02 * t12;
    const double p02 = l01 * t21 + l02 * t22;
    const double p10 = l11 * t01 + l12 * t02;
    const double p11 = l11 * t11 + l12 * t12;
    const double p12 = l11 * t21 + l12 * t22;
    const double p20 = t00 + l21 * t01 + l22 * t02;
    const double p21 = t10 + l21 * t11 + l22 * t12;
    const double p22 = t20 + l21 * t21 + l22 * t22;
    for (int k = 1; k <= n; ++k) {
        if (is_prismatic(arm.joints[k - 1])) {
            J[3 * n + k - 1] = 0.0;
            J[4 * n + k - 1] = 0.0;
            J[5 * n + k - 1] = 0.0;
            continue;
        }
        const ChainBody& c = work[k];
        const double ux = c.u[0], uy = c.u[1], uz = c.u[2];
        J[3 * n + k - 1] = p00 * ux + p01 * uy + p02 * uz;
        J[4 * n + k - 1] = p10 * ux + p11 * uy + p12 * uz;
        J[5 * n + k - 1] = p20 * ux + p21 * uy + p22 * uz;
    }
    const double dA0 = p00 * wx + p01 * wy + p02 * wz;
    const double dA1 = p10 * wx + p11 * wy + p12 * wz;
    const double dA2 = p20 * wx + p21 * wy + p22 * wz;
    double bx = t00 * alx + t10 * aly + t20 * alz;
    double by = t01 * alx + t11 * aly + t21 * alz;
    double bz = t02 * alx + t12 * aly + t22 * alz;
    bx -= -cth * dA1 * dA0;
    by -= (cph * cth * dA2 - sph * sth * dA1) * dA0 - sph * dA2 * dA1;
    bz -= (-sph * cth * dA2 - cph * sth * dA1) * dA0 - cph * dA2 * dA1;
    Jdq[3] = l01 * by + l02 * bz;
    Jdq[4] = l11 * by + l12 * bz;
    Jdq[5] = bx + l21 * by + l22 * bz;
    return 0;
}

double chain_arm_potential(const ChainArmModel& arm, const double* q, ChainBody* work) noexcept {
    const int n = arm.dof;
    set_base_frame(arm.base, work[0]);
    double U = 0.0;
    for (int k = 1; k <= n; ++k) {
        const ChainJointRow& row = arm.joints[k - 1];
        ChainBody& c = work[k];
        chain_link_frame(work[k - 1], row, q[k - 1], c);
        const double m = row.mass;
        for (int i = 0; i < 3; ++i) {
            const double pc = c.o[i] + c.R[3 * i] * row.com[0] + c.R[3 * i + 1] * row.com[1] +
                              c.R[3 * i + 2] * row.com[2];
            U -= m * arm.gravity[i] * pc;
        }
    }
    return U;
}

void chain_arm_tip(const ChainArmModel& arm, const double* q, ChainBody* work, double* T, double* Jg) noexcept {
    const int n = arm.dof;
    set_base_frame(arm.base, work[0]);
    for (int k = 1; k <= n; ++k) chain_link_frame(work[k - 1], arm.joints[k - 1], q[k - 1], work[k]);
    const ChainBody& e = work[n];
    const double* tool = arm.tool;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            T[4 * i + j] = e.R[3 * i] * tool[j] + e.R[3 * i + 1] * tool[4 + j] + e.R[3 * i + 2] * tool[8 + j];
        }
        T[4 * i + 3] = e.o[i] + e.R[3 * i] * tool[3] + e.R[3 * i + 1] * tool[7] + e.R[3 * i + 2] * tool[11];
        T[12 + i] = 0.0;
    }
    T[15] = 1.0;
    for (int k = 1; k <= n; ++k) {
        const ChainBody& c = work[k];
        const double ux = c.u[0], uy = c.u[1], uz = c.u[2];
        if (is_prismatic(arm.joints[k - 1])) {
            Jg[k - 1] = ux; Jg[n + k - 1] = uy; Jg[2 * n + k - 1] = uz;
            Jg[3 * n + k - 1] = 0.0; Jg[4 * n + k - 1] = 0.0; Jg[5 * n + k - 1] = 0.0;
            continue;
        }
        const double rx = T[3] - c.o[0], ry = T[7] - c.o[1], rz = T[11] - c.o[2];
        Jg[k - 1] = uy * rz - uz * ry;
        Jg[n + k - 1] = uz * rx - ux * rz;
        Jg[2 * n + k - 1] = ux * ry - uy * rx;
        Jg[3 * n + k - 1] = ux;
        Jg[4 * n + k - 1] = uy;
        Jg[5 * n + k - 1] = uz;
    }
}

}  // namespace plants
