#include "plants/core/elastic_planar.h"

#include <cmath>

#include "plants/core/elastic_matrix.h"
#include "plants/core/elastic_rotation.h"
#include "plants/core/elastic_springs.h"

namespace plants {

using elastic_detail::wrap_angle;

int planar_elastic_edges(const Interconnections& ic, const double* Y, double* F, double* Pi) noexcept {
    double sum = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
        if (edge.kind == ELEMENT_MATRIX) {
            sum += planar_matrix_element(ic.element<PlanarMatrixElement>(e), i, j, Y, Y, F, false);
            continue;
        }
        const PlanarSpring& s = ic.element<PlanarSpring>(e);
        const double* Yi = Y + 3 * i;
        const double* Yj = Y + 3 * j;
        double* Fi = F + 3 * i;
        double* Fj = F + 3 * j;
        if (edge.kind == ELEMENT_CENTRAL) {
            const double d0 = Yi[0] - Yj[0];
            const double d1 = Yi[1] - Yj[1];
            const double Q = s.stiffness[0] * d0 * d0 + s.stiffness[1] * d1 * d1;
            const double l = s.rest_length;
            double a, g2;
            if (l > 0.0) {
                const double dist = std::sqrt(d0 * d0 + d1 * d1);
                if (dist < COINCIDENT_FRACTION * l) {
                    *Pi = sum;
                    return ELASTIC_COINCIDENT_NODES;
                }
                const double g = 1.0 - l / dist;
                a = g * l * Q / (dist * dist * dist);
                g2 = g * g;
            } else {
                a = 0.0;
                g2 = 1.0;
            }
            sum += 0.5 * g2 * Q;
            const double f0 = a * d0 + g2 * s.stiffness[0] * d0;
            const double f1 = a * d1 + g2 * s.stiffness[1] * d1;
            Fi[0] += f0;
            Fi[1] += f1;
            Fj[0] -= f0;
            Fj[1] -= f1;
        } else {
            const auto [sn, c] = sin_cos(Yi[2]);
            const double d0 = Yj[0] - Yi[0];
            const double d1 = Yj[1] - Yi[1];
            const double e0 = c * d0 + sn * d1 - s.rest_offset[0];
            const double e1 = -sn * d0 + c * d1 - s.rest_offset[1];
            sum += 0.5 * (s.stiffness[0] * e0 * e0 + s.stiffness[1] * e1 * e1);
            const double C0 = s.stiffness[0] * e0;
            const double C1 = s.stiffness[1] * e1;
            const double f0 = c * C0 - sn * C1;
            const double f1 = sn * C0 + c * C1;
            Fj[0] += f0;
            Fj[1] += f1;
            Fi[0] -= f0;
            Fi[1] -= f1;
            // de/dtheta_i = dR^T d, dR = [[-s, -c], [c, -s]]
            Fi[2] += C0 * (-sn * d0 + c * d1) + C1 * (-c * d0 - sn * d1);
        }
        const double cA = s.torsion;
        if (cA != 0.0) {
            const double dl = wrap_angle(Yi[2] - Yj[2] - s.rest_angle);
            sum += 0.5 * cA * dl * dl;
            Fi[2] += cA * dl;
            Fj[2] -= cA * dl;
        }
    }
    *Pi = sum;
    return ELASTIC_OK;
}

double planar_damping_edges(const Interconnections& ic, const double* Y, const double* dY, double* F) noexcept {
    double D = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
        if (edge.kind == ELEMENT_MATRIX) {
            D += planar_matrix_element(ic.element<PlanarMatrixElement>(e), i, j, Y, dY, F, true);
            continue;
        }
        const PlanarSpring& s = ic.element<PlanarSpring>(e);
        double* Fi = F + 3 * i;
        double* Fj = F + 3 * j;
        const double dd = s.damping;
        if (dd != 0.0) {
            const double v0 = dY[3 * i] - dY[3 * j];
            const double v1 = dY[3 * i + 1] - dY[3 * j + 1];
            const double d0 = Y[3 * i] - Y[3 * j];
            const double d1 = Y[3 * i + 1] - Y[3 * j + 1];
            const double dist = std::sqrt(d0 * d0 + d1 * d1);
            double f0, f1;
            if (edge.kind == ELEMENT_CENTRAL && dist > 1e-12) {
                const double vu = (v0 * d0 + v1 * d1) / dist;
                D += 0.5 * dd * vu * vu;
                f0 = dd * vu * d0 / dist;
                f1 = dd * vu * d1 / dist;
            } else if (edge.kind == ELEMENT_CENTRAL || edge.damping_form == DAMPING_BOOK) {
                D += 0.5 * dd * (v0 * v0 + v1 * v1);
                f0 = dd * v0;
                f1 = dd * v1;
            } else {
                const auto [sn, c] = sin_cos(Y[3 * i + 2]);
                // rho = R_i^T (r_j - r_i); r_j - r_i = -(d0, d1); dr_j - dr_i = -(v0, v1)
                const double rho0 = -(c * d0 + sn * d1);
                const double rho1 = -(-sn * d0 + c * d1);
                const double w = dY[3 * i + 2];
                const double ed0 = -(c * v0 + sn * v1) + w * rho1;
                const double ed1 = -(-sn * v0 + c * v1) - w * rho0;
                D += 0.5 * dd * (ed0 * ed0 + ed1 * ed1);
                const double g0 = dd * ed0;
                const double g1 = dd * ed1;
                f0 = -(c * g0 - sn * g1);  // force on node i (node j gets its opposite below)
                f1 = -(sn * g0 + c * g1);
                Fi[2] += g0 * rho1 - g1 * rho0;
            }
            Fi[0] += f0;
            Fi[1] += f1;
            Fj[0] -= f0;
            Fj[1] -= f1;
        }
        const double dA = s.torsion_damping;
        if (dA != 0.0) {
            const double v = dY[3 * i + 2] - dY[3 * j + 2];
            D += 0.5 * dA * v * v;
            Fi[2] += dA * v;
            Fj[2] -= dA * v;
        }
    }
    return D;
}

double planar_linear_edges(const Interconnections& ic, const double* Y, const double* dY, const double* Y_ref,
                           double* F) noexcept {
    double Pi = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
        if (edge.kind == ELEMENT_MATRIX) {
            const PlanarMatrixElement& m = ic.element<PlanarMatrixElement>(e);
            Pi += linear_matrix_element(m.stiffness_linear, m.damping_linear, 3, 2, i, j, Y, dY, Y_ref, F);
            continue;
        }
        const PlanarSpring& s = ic.element<PlanarSpring>(e);
        for (int k = 0; k < 3; ++k) {
            double diff = (Y[3 * i + k] - Y_ref[3 * i + k]) - (Y[3 * j + k] - Y_ref[3 * j + k]);
            double dk, kk;
            if (k == 2) {
                diff = wrap_angle(diff);  // a common rotation is a zero mode, also across +-pi
                dk = s.torsion_damping;
                kk = s.torsion;
            } else {
                dk = s.damping;
                kk = s.stiffness[k];
            }
            Pi += 0.5 * kk * diff * diff;
            const double f = kk * diff + dk * (dY[3 * i + k] - dY[3 * j + k]);
            F[3 * i + k] += f;
            F[3 * j + k] -= f;
        }
    }
    return Pi;
}

int planar_interconnection_terms(const Interconnections& ic, const double* Y, const double* dY,
                                 const double* Y_ref, bool immobile, double* w) noexcept {
    if (immobile) {
        planar_linear_edges(ic, Y, dY, Y_ref, w);
        return ELASTIC_OK;
    }
    double Pi;
    const int status = planar_elastic_edges(ic, Y, w, &Pi);
    if (status != ELASTIC_OK) return status;
    planar_damping_edges(ic, Y, dY, w);
    return ELASTIC_OK;
}

int planar_elastic_accelerations(const PlanarElasticModel& model, const double* Y, const double* dY,
                                 const double* Fc, double* ddY, double* w) noexcept {
    const int N = model.node_count;
    for (int k = 0; k < 3 * N; ++k) w[k] = 0.0;
    for (int k = 0; k < N; ++k) {
        w[3 * k] = -model.nodes[k].mass * model.gravity[0];
        w[3 * k + 1] = -model.nodes[k].mass * model.gravity[1];
    }
    const int status = planar_interconnection_terms(model.interconnections, Y, dY, model.Y_ref, model.immobile, w);
    if (status != ELASTIC_OK) {
        for (int k = 0; k < 3 * N; ++k) ddY[k] = 0.0;
        return status;
    }
    for (int k = 0; k < N; ++k)
        for (int a = 0; a < 3; ++a) {
            const double f = (k > 0 ? Fc[3 * k + a] : 0.0) - w[3 * k + a];
            ddY[3 * k + a] = f / (a < 2 ? model.nodes[k].mass : model.nodes[k].inertia);
        }
    return ELASTIC_OK;
}

}  // namespace plants
