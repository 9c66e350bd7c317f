#include "plants/core/dh_arm.h"

#include <cmath>

#include "plants/core/chain_arm.h"
#include "plants/core/frames.h"

namespace plants {

int dh_arm_terms(const DHArmModel& arm, const double* q, const double* dq, double* H, double* h, double* Y,
                 double* J, double* Jdq, DHFrame* work) noexcept {
    const int n = arm.dof;
    const double gx = arm.gravity[0], gy = arm.gravity[1], gz = arm.gravity[2];
    DHFrame& b = work[0];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) b.R[3 * i + j] = arm.base[4 * i + j];
        b.o[i] = arm.base[4 * i + 3];
        b.w[i] = 0.0;
        b.alpha[i] = 0.0;
    }
    b.a[0] = -gx;
    b.a[1] = -gy;
    b.a[2] = -gz;

    // ---- forward pass: kinematics, velocities, accelerations (qdd = 0), link wrenches
    for (int k = 1; k <= n; ++k) {
        const DHFrame& p = work[k - 1];
        DHFrame& c = work[k];
        const DHLink& row = arm.links[k - 1];
        const double th = q[k - 1] + row.offset;
        const auto [st, ct] = sin_cos(th);
        const auto [sa, ca] = sin_cos(row.alpha);
        const double la = row.a, ld = row.d;
        // local DH rotation Rz(th) Rx(alpha)
        const double a00 = ct, a01 = -st * ca, a02 = st * sa;
        const double a10 = st, a11 = ct * ca, a12 = -ct * sa;
        const double a20 = 0.0, a21 = sa, a22 = ca;
        for (int i = 0; i < 3; ++i) {
            const double r0 = p.R[3 * i], r1 = p.R[3 * i + 1], r2 = p.R[3 * i + 2];
            c.R[3 * i] = r0 * a00 + r1 * a10 + r2 * a20;
            c.R[3 * i + 1] = r0 * a01 + r1 * a11 + r2 * a21;
            c.R[3 * i + 2] = r0 * a02 + r1 * a12 + r2 * a22;
            c.o[i] = p.o[i] + r0 * (la * ct) + r1 * (la * st) + r2 * ld;
        }
        // joint axis z_{k-1} (world)
        const double zx = p.R[2], zy = p.R[5], zz = p.R[8];
        const double qd = dq[k - 1];
        const double pwx = p.w[0], pwy = p.w[1], pwz = p.w[2];
        const double wx = pwx + zx * qd, wy = pwy + zy * qd, wz = pwz + zz * qd;
        c.w[0] = wx; c.w[1] = wy; c.w[2] = wz;
        // alpha_k = alpha_{k-1} + w_{k-1} x z qd
        const double alx = p.alpha[0] + (pwy * zz - pwz * zy) * qd;
        const double aly = p.alpha[1] + (pwz * zx - pwx * zz) * qd;
        const double alz = p.alpha[2] + (pwx * zy - pwy * zx) * qd;
        c.alpha[0] = alx; c.alpha[1] = aly; c.alpha[2] = alz;
        // a(o_k) = a(o_{k-1}) + al x r + w x (w x r)
        const double rx = c.o[0] - p.o[0];
        const double ry = c.o[1] - p.o[1];
        const double rz = c.o[2] - p.o[2];
        double vx = wy * rz - wz * ry, vy = wz * rx - wx * rz, vz = wx * ry - wy * rx;
        const double aox = p.a[0] + (aly * rz - alz * ry) + (wy * vz - wz * vy);
        const double aoy = p.a[1] + (alz * rx - alx * rz) + (wz * vx - wx * vz);
        const double aoz = p.a[2] + (alx * ry - aly * rx) + (wx * vy - wy * vx);
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
        // world inertia Iw = R I R^T; T = R I (rows of R times I)
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

    // ---- backward pass: h (moments about o_{k-1})
    double Fx = 0.0, Fy = 0.0, Fz = 0.0;
    double Mx = 0.0, My = 0.0, Mz = 0.0;
    for (int k = n; k >= 1; --k) {
        const DHFrame& p = work[k - 1];
        const DHFrame& c = work[k];
        const double ox = p.o[0], oy = p.o[1], oz = p.o[2];
        const double dx = c.com[0] - ox, dy = c.com[1] - oy, dz = c.com[2] - oz;
        const double ex = c.o[0] - ox, ey = c.o[1] - oy, ez = c.o[2] - oz;
        const double fx = c.force[0], fy = c.force[1], fz = c.force[2];
        Mx = c.moment[0] + (dy * fz - dz * fy) + Mx + (ey * Fz - ez * Fy);
        My = c.moment[1] + (dz * fx - dx * fz) + My + (ez * Fx - ex * Fz);
        Mz = c.moment[2] + (dx * fy - dy * fx) + Mz + (ex * Fy - ey * Fx);
        Fx += fx;
        Fy += fy;
        Fz += fz;
        h[k - 1] = p.R[2] * Mx + p.R[5] * My + p.R[8] * Mz + arm.links[k - 1].viscous * dq[k - 1];
    }

    // ---- composite rigid bodies: H
    double Mc = 0.0;
    double hx = 0.0, hy = 0.0, hz = 0.0;
    double cxx = 0.0, cyy = 0.0, czz = 0.0, cxy = 0.0, cyz = 0.0, cxz = 0.0;
    for (int i = n; i >= 1; --i) {
        const DHFrame& p = work[i - 1];
        const DHFrame& c = work[i];
        const double ox = p.o[0], oy = p.o[1], oz = p.o[2];
        // shift the composite of links i+1..n from o_i to o_{i-1}: e = o_i - o_{i-1}
        const double ex = c.o[0] - ox, ey = c.o[1] - oy, ez = c.o[2] - oz;
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
        // add link i about o_{i-1}
        const double m = arm.links[i - 1].mass;
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
        // unit acceleration of joint i: moment I_o z about o_{i-1}, force z x hc
        const double zx = p.R[2], zy = p.R[5], zz = p.R[8];
        const double Izx = cxx * zx + cxy * zy + cxz * zz;
        const double Izy = cxy * zx + cyy * zy + cyz * zz;
        const double Izz = cxz * zx + cyz * zy + czz * zz;
        Fx = zy * hz - zz * hy;
        Fy = zz * hx - zx * hz;
        Fz = zx * hy - zy * hx;
        H[(i - 1) * n + (i - 1)] = zx * Izx + zy * Izy + zz * Izz + arm.links[i - 1].motor_inertia;
        for (int j = i - 1; j >= 1; --j) {
            const DHFrame& pj = work[j - 1];
            const double rx = ox - pj.o[0], ry = oy - pj.o[1], rz = oz - pj.o[2];
            const double mx = Izx + (ry * Fz - rz * Fy);
            const double my = Izy + (rz * Fx - rx * Fz);
            const double mz = Izz + (rx * Fy - ry * Fx);
            const double v = pj.R[2] * mx + pj.R[5] * my + pj.R[8] * mz;
            H[(j - 1) * n + (i - 1)] = v;
            H[(i - 1) * n + (j - 1)] = v;
        }
    }

    // ---- tip pose (the chain kernel's)
    const DHFrame& e = work[n];
    const TipPose tp = tip_pose(e.R, e.o, arm.tool, false, Y);
    const double px = tp.p[0], py = tp.p[1], pz = tp.p[2];
    const double t00 = tp.R[0], t01 = tp.R[1], t02 = tp.R[2];
    const double t10 = tp.R[3], t11 = tp.R[4], t12 = tp.R[5];
    const double t20 = tp.R[6], t21 = tp.R[7], t22 = tp.R[8];
    const double cth = tp.cos_theta, sth = tp.sin_theta;

    // ---- translational Jacobian rows and tip acceleration
    for (int k = 1; k <= n; ++k) {
        const DHFrame& p = work[k - 1];
        const double zx = p.R[2], zy = p.R[5], zz = p.R[8];
        const double rx = px - p.o[0], ry = py - p.o[1], rz = pz - p.o[2];
        J[k - 1] = zy * rz - zz * ry;
        J[n + k - 1] = zz * rx - zx * rz;
        J[2 * n + k - 1] = zx * ry - zy * rx;
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
    const double sph = t21 / cth, cph = t22 / cth;
    const double tth = sth / cth;
    // Linv rows
    const double l01 = sph / cth, l02 = cph / cth;
    const double l11 = cph, l12 = -sph;
    const double l21 = sph * tth, l22 = cph * tth;
    // P = L^-1 R^T (R^T row i = column i of R)
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
        const DHFrame& pk = work[k - 1];
        const double zx = pk.R[2], zy = pk.R[5], zz = pk.R[8];
        J[3 * n + k - 1] = p00 * zx + p01 * zy + p02 * zz;
        J[4 * n + k - 1] = p10 * zx + p11 * zy + p12 * zz;
        J[5 * n + k - 1] = p20 * zx + p21 * zy + p22 * zz;
    }
    // dA, then ddA = L^-1 (R^T alpha - Ldot dA)
    const double dA0 = p00 * wx + p01 * wy + p02 * wz;
    const double dA1 = p10 * wx + p11 * wy + p12 * wz;
    const double dA2 = p20 * wx + p21 * wy + p22 * wz;
    double bx = t00 * alx + t10 * aly + t20 * alz;
    double by = t01 * alx + t11 * aly + t21 * alz;
    double bz = t02 * alx + t12 * aly + t22 * alz;
    // Ldot dA (frames.h body_rate_map_dot)
    bx -= -cth * dA1 * dA0;
    by -= (cph * cth * dA2 - sph * sth * dA1) * dA0 - sph * dA2 * dA1;
    bz -= (-sph * cth * dA2 - cph * sth * dA1) * dA0 - cph * dA2 * dA1;
    Jdq[3] = l01 * by + l02 * bz;
    Jdq[4] = l11 * by + l12 * bz;
    Jdq[5] = bx + l21 * by + l22 * bz;
    return 0;
}

namespace {

/// Frame k from frame k-1 in place: o += R (a cos th, a sin th, d), R = R Rz(th) Rx(alpha).
void advance_dh_frame(const DHLink& row, double qk, double* R, double* o) noexcept {
    const double th = qk + row.offset;
    const auto [st, ct] = sin_cos(th);
    const auto [sa, ca] = sin_cos(row.alpha);
    const double la = row.a, ld = row.d;
    for (int i = 0; i < 3; ++i) {
        const double r0 = R[3 * i], r1 = R[3 * i + 1], r2 = R[3 * i + 2];
        o[i] += r0 * (la * ct) + r1 * (la * st) + r2 * ld;
        R[3 * i] = r0 * ct + r1 * st;
        R[3 * i + 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa;
        R[3 * i + 2] = r0 * st * sa - r1 * ct * sa + r2 * ca;
    }
}

}  // namespace

double dh_arm_potential(const DHArmModel& arm, const double* q) noexcept {
    double R[9], o[3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) R[3 * i + j] = arm.base[4 * i + j];
        o[i] = arm.base[4 * i + 3];
    }
    double U = 0.0;
    for (int k = 0; k < arm.dof; ++k) {
        const DHLink& row = arm.links[k];
        advance_dh_frame(row, q[k], R, o);
        const double m = row.mass;
        for (int i = 0; i < 3; ++i) {
            const double pc = o[i] + R[3 * i] * row.com[0] + R[3 * i + 1] * row.com[1] + R[3 * i + 2] * row.com[2];
            U -= m * arm.gravity[i] * pc;
        }
    }
    return U;
}

void dh_arm_tip(const DHArmModel& arm, const double* q, double* axes, double* points, double* T,
                double* Jg) noexcept {
    const int n = arm.dof;
    double R[9], o[3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) R[3 * i + j] = arm.base[4 * i + j];
        o[i] = arm.base[4 * i + 3];
    }
    for (int k = 0; k < n; ++k) {
        for (int i = 0; i < 3; ++i) {
            axes[3 * k + i] = R[3 * i + 2];
            points[3 * k + i] = o[i];
        }
        advance_dh_frame(arm.links[k], q[k], R, o);
    }
    const double* tool = arm.tool;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            T[4 * i + j] = R[3 * i] * tool[j] + R[3 * i + 1] * tool[4 + j] + R[3 * i + 2] * tool[8 + j];
        }
        T[4 * i + 3] = o[i] + R[3 * i] * tool[3] + R[3 * i + 1] * tool[7] + R[3 * i + 2] * tool[11];
        T[12 + i] = 0.0;
    }
    T[15] = 1.0;
    for (int k = 0; k < n; ++k) {
        const double zx = axes[3 * k], zy = axes[3 * k + 1], zz = axes[3 * k + 2];
        const double rx = T[3] - points[3 * k], ry = T[7] - points[3 * k + 1], rz = T[11] - points[3 * k + 2];
        Jg[k] = zy * rz - zz * ry;
        Jg[n + k] = zz * rx - zx * rz;
        Jg[2 * n + k] = zx * ry - zy * rx;
        Jg[3 * n + k] = zx;
        Jg[4 * n + k] = zy;
        Jg[5 * n + k] = zz;
    }
}

}  // namespace plants
