// The closed loop's tick (ported stage for stage, expression for expression from the numba tick it replaced: the
// same bits; tests/golden/tick holds that tick's records).
//
// A tick is two phases, as MuJoCo's mj_step1 and mj_step2:
//   sense:  the plant's control terms at the true state and, with noisy sensors, at the measured one; the guards;
//           the energy; the nominal motion of the nodes carried by the object (148) and the object's required wrench
//           w_N; the QP of the split (assemble_split);
//   (the split is solved between them: solve_split, or a backend in Python on the reference path)
//   act:    the split, the followers' setpoints, the leader's and the followers' laws, the saturation at tau_max,
//           the record row, the plant over the period (zero-order hold, the run's integration plan).
// Tick k is at t = (k_base + k) T [s] and is row k of the record, the trajectory table and the noise streams. The
// tick allocates nothing: its work arrays (TickWork) are made once per run.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "coopctrl/core/adaptive_plan.h"
#include "coopctrl/core/adaptive_schemes.h"
#include "coopctrl/core/control_laws.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/goldfarb_idnani.h"
#include "coopctrl/core/implicit_schemes.h"
#include "coopctrl/core/integration_plan.h"
#include "coopctrl/core/linear_algebra.h"
#include "coopctrl/core/qp_answer_check.h"
#include "coopctrl/core/qp_assembly.h"
#include "coopctrl/core/qp_contact_model.h"
#include "coopctrl/core/qp_elastic_assembly.h"
#include "coopctrl/core/squeeze.h"
#include "coopctrl/core/tick_checks.h"
#include "coopctrl/core/tick_model.h"
#include "coopctrl/core/tick_plants.h"
#include "plants/core/rigid_motion.h"

namespace coopctrl {

/// The run's integration plan: one family, its plan.
struct PeriodPlan {
    enum Family { EXPLICIT, IMPLICIT, EMBEDDED, TRBDF2 } family;
    ExplicitPlan explicit_plan;
    ImplicitPlan implicit_plan;
    EmbeddedPlan embedded_plan;
    TRBDF2Plan trbdf2_plan;
};

/// The tick's work arrays, made once per run.
struct TickWork {
    int nw;  ///< the control laws' width: max(p, the largest arm dof, the plant's arm row width)
    std::vector<double> F_cmd, F_seen, xm, Fm, F_set, wN, nrm, Jg, bias, a_cmd, err, Yn, dYn, ddYn, R3, rc, r0, Wa,
        rhs_t, qdd, inc, corr, Yv, ti, vectors, matrices, posture;
    std::vector<int64_t> piv;
    // the elastic split's
    std::vector<double> elastic_KGt, elastic_Rb, elastic_work;
    // the squeeze's (coopctrl/loop/squeeze.py's SqueezeWork)
    std::vector<double> sq_E, sq_W, sq_V, sq_sigma;
    int pairs;
    ControlWork control{};

    TickWork(const TickModel& md, int plant_nmax) {
        const int m = md.m, p = md.p, N = m + 1, n = m * p;
        nw = std::max(p, plant_nmax);
        for (int i = 0; i < m; ++i) nw = std::max(nw, static_cast<int>(md.arm_dof[i]));
        F_cmd.assign(m * p, 0.0), F_seen.assign(m * p, 0.0), xm.assign(md.nx, 0.0), Fm.assign(m * p, 0.0);
        F_set.assign(m * p, 0.0), wN.assign(p, 0.0), nrm.assign(m * md.npos, 0.0), Jg.assign(m * p * nw, 0.0);
        bias.assign(std::max(md.nu, 1), 0.0), a_cmd.assign(p, 0.0), err.assign(p, 0.0);
        Yn.assign(N * p, 0.0), dYn.assign(N * p, 0.0), ddYn.assign(N * p, 0.0), R3.assign(4 * 9, 0.0);
        rc.assign(m * md.npos, 0.0), r0.assign(md.npos, 0.0), Wa.assign(p, 0.0), rhs_t.assign(p, 0.0);
        qdd.assign(nw, 0.0), inc.assign(p, 0.0), corr.assign(p, 0.0), Yv.assign(p, 0.0), ti.assign(nw, 0.0);
        vectors.assign(WORK_VECTORS * nw, 0.0), matrices.assign(WORK_MATRICES * nw * nw, 0.0);
        posture.assign(nw, 0.0), piv.assign(nw, 0);
        elastic_KGt.assign(n * p, 0.0), elastic_Rb.assign(p * p, 0.0);
        elastic_work.assign(p * 2 * p, 0.0);
        pairs = m * (m - 1) / 2;
        const int R = m * md.npos;
        const int rows = pairs <= R ? R : pairs, cols = pairs <= R ? pairs : R;
        sq_E.assign(std::max(R * pairs, 1), 0.0), sq_W.assign(std::max(rows * cols, 1), 0.0);
        sq_V.assign(std::max(cols * cols, 1), 0.0), sq_sigma.assign(std::max(cols, 1), 0.0);
        control.nmax = nw;
        control.vectors = vectors.data();
        control.matrices = matrices.data();
        control.piv = piv.data();
        control.posture = posture.data();
    }
};

/// One run's tick on a Plant (tick_plants.h), its model, data, plan and QP workspace.
template <class Plant>
class Tick {
public:
    Tick(const TickModel& model, TickData& data, Plant& plant, PeriodPlan& plan, GIWorkspace& qp_ws)
        : md_(model), d_(data), plant_(plant), plan_(plan), ws_(qp_ws), w_(model, plant.terms(TERMS_TRUE).nmax) {}

    /// Ticks k0 .. until N are recorded, an event, or tick k_stop.
    void run(int64_t k0, int64_t k_stop) noexcept {
        StopReport& stop = *d_.stop;
        int64_t k = k0;
        stop.code = TICK_DONE;
        if (d_.flags->advance_first != 0) {  // the period a run that ended at tick k_base - 1 did not advance
            d_.flags->advance_first = 0;
            plant_.sense(d_.x, status_, TERMS_TRUE);
            int code = status_[0] == 0 ? STEP_OK : -1;
            if (code == STEP_OK) code = advance((md_.run.k_base - 1) * md_.run.T);
            if (code != STEP_OK) {
                stop.tick = 0;
                copy(d_.x, d_.x_good, md_.nx);
                step_failed(code);
                return;
            }
        }
        const bool passive = md_.switches.passive;
        while (k < md_.run.N) {
            if (k == k_stop) {
                stop.code = TICK_CHUNK_END;
                stop.tick = k;
                return;
            }
            HoldState& hold_state = *d_.hold;
            const bool hold = hold_state.mode == 1;
            bool P_changed = false;
            if (sense(k, !passive && !hold, &P_changed) != TICK_DONE) return;
            int64_t source, qs, qit, qb, qact;
            if (passive) {
                source = SPLIT_NONE, qs = 0, qit = -1, qb = 0, qact = -1;
            } else if (hold) {
                hold_state.mode = 0;
                source = SPLIT_HELD, qs = hold_state.qp_status, qit = hold_state.iterations, qb = 0, qact = -1;
            } else {
                if (!solve_split(P_changed, &qs, &qit, &qb, &qact)) return;
                source = SPLIT_SOLVED;
            }
            const int64_t code = act(k, source, qs, qit, qb, qact);
            if (code == TICK_RECORDED) break;
            if (code != TICK_DONE) return;
            k += 1;
        }
        stop.tick = k;
        stop.code = TICK_DONE;
    }

    /// The reference path's one entry per tick (its QP solved in Python between the phases): act on tick k with
    /// the backend's split (with `act_first`), then, with `sense_next`, sense tick k + 1 (its QP assembled).
    int64_t reference_step(int64_t k, bool act_first, int64_t source, int64_t qs, int64_t qit, int64_t qb,
                           bool sense_next, bool* P_changed) noexcept {
        *P_changed = false;
        if (act_first) {
            const int64_t code = act(k, source, qs, qit, qb, -1);
            if (code != TICK_DONE || !sense_next) return code;
        }
        return sense(k + 1, true, P_changed);
    }

    /// The controller's step (coopctrl.Controller): the control layer of one period from a measurement instead of
    /// the plant's state, at row k of the trajectory table: the measurement checked finite and written into the
    /// measured state; the control terms there; the nominal motion and load; the split (solved, or the last
    /// feasible one held); the laws and the saturation into tau. No guard and no plant advance: the caller owns the
    /// plant. q, dq: per arm its joints [rad, rad/s]; wrench (m, p) [N, N m]; pose, twist (p) of the object.
    /// Returns TICK_DONE, TICK_MEASUREMENT_NOT_FINITE (detail: field 0 q, 1 dq, 2 wrench, 3 pose, 4 twist; the arm;
    /// the entry; nothing changed), TICK_QP_FAILED, or a stage's event.
    int64_t controller_step(int64_t k, bool hold, const double* const* q, const double* const* dq,
                            const double* wrench, const double* pose, const double* twist) noexcept {
        const int m = md_.m, p = md_.p, nz = md_.nx / 2;
        StopReport& stop = *d_.stop;
        stop.code = TICK_DONE;
        stop.tick = k;
        auto refused = [&](int64_t field, int64_t index, int64_t entry) {
            stop.code = TICK_MEASUREMENT_NOT_FINITE;
            stop.detail[0] = field, stop.detail[1] = index, stop.detail[2] = entry;
            return TICK_MEASUREMENT_NOT_FINITE;
        };
        for (int i = 0; i < m; ++i) {
            for (int c = 0; c < md_.arm_dof[i]; ++c) {
                if (!std::isfinite(q[i][c])) return refused(0, i, c);
                if (!std::isfinite(dq[i][c])) return refused(1, i, c);
            }
            for (int a = 0; a < p; ++a)
                if (!std::isfinite(wrench[i * p + a])) return refused(2, i, a);
        }
        for (int a = 0; a < p; ++a) {
            if (!std::isfinite(pose[a])) return refused(3, 0, a);
            if (!std::isfinite(twist[a])) return refused(4, 0, a);
        }
        double* xm = w_.xm.data();
        for (int i = 0; i < m; ++i) {
            const int o = static_cast<int>(md_.q_offset[i]);
            for (int c = 0; c < md_.arm_dof[i]; ++c) {
                xm[o + c] = q[i][c];
                xm[nz + o + c] = dq[i][c];
            }
            for (int a = 0; a < p; ++a) w_.Fm[i * p + a] = wrench[i * p + a];
        }
        for (int a = 0; a < p; ++a) {
            xm[nz - p + a] = pose[a];
            xm[2 * nz - p + a] = twist[a];
        }
        plant_.sense(xm, status_, TERMS_MEASURED);
        if (status_[0] != 0) return plant_failed(xm);
        const SensedTerms tm = plant_.terms(TERMS_MEASURED);
        int64_t code = nominal_load(k);
        if (code != TICK_DONE) return code;
        int64_t source = SPLIT_HELD;
        if (!hold) {
            bool P_changed = false;
            code = assemble_split(k, tm, &P_changed);
            if (code != TICK_DONE) return code;
            int64_t qs, qit, qb, qact;
            if (!solve_split(P_changed, &qs, &qit, &qb, &qact)) return TICK_QP_FAILED;
            source = SPLIT_SOLVED;
        }
        return control_torques(k, source, tm, xm);
    }

    /// Phase 1 of tick k: sensors, guards, energy, the nominal motion and load, and with `assemble` the QP.
    int64_t sense(int64_t k, bool assemble, bool* P_changed) noexcept {
        const int m = md_.m, p = md_.p, nx = md_.nx, nz = nx / 2;
        const SensorModel& sn = md_.sensors;
        StopReport& stop = *d_.stop;
        double* x = d_.x;
        *P_changed = false;
        stop.tick = k;
        const int64_t kq = sn.rows_joints > 1 ? k : 0;  // a noise-free channel passes one row of zeros
        const int64_t ko = sn.rows_object > 1 ? k : 0;
        const int64_t kf = sn.rows_wrench > 1 ? k : 0;
        // ---- sensors (true terms: forces, guards)
        plant_.sense(x, status_, TERMS_TRUE);
        const SensedTerms tt = plant_.terms(TERMS_TRUE);
        if (status_[0] != 0) return plant_failed(x);
        if (sn.noisy_state) {
            const double* nq = sn.joints + kq * 2 * (nz - p);
            const double* no = sn.object + ko * 2 * p;
            double* xm = w_.xm.data();
            for (int c = 0; c < nz - p; ++c) {
                xm[c] = x[c] + nq[c];
                xm[nz + c] = x[nz + c] + nq[nz - p + c];
                if (sn.joint_step != 0.0) {
                    xm[c] = std::nearbyint(xm[c] / sn.joint_step) * sn.joint_step;
                    xm[nz + c] = std::nearbyint(xm[nz + c] / sn.joint_step) * sn.joint_step;
                }
            }
            for (int c = 0; c < p; ++c) {
                xm[nz - p + c] = x[nz - p + c] + no[c];
                xm[nx - p + c] = x[nx - p + c] + no[p + c];
                if (sn.object_step != 0.0) {
                    xm[nz - p + c] = std::nearbyint(xm[nz - p + c] / sn.object_step) * sn.object_step;
                    xm[nx - p + c] = std::nearbyint(xm[nx - p + c] / sn.object_step) * sn.object_step;
                }
            }
            plant_.sense(xm, status_, TERMS_MEASURED);
            if (status_[0] != 0) return plant_failed(xm);
        }
        const double* nf = sn.wrench + kf * m * p;
        for (int i = 0; i < m; ++i) {
            for (int a = 0; a < p; ++a) {
                double v = tt.Fw[i * p + a] + nf[i * p + a];
                if (sn.wrench_step != 0.0) v = std::nearbyint(v / sn.wrench_step) * sn.wrench_step;
                w_.Fm[i * p + a] = v;
            }
        }
        // ---- guards on the state we are at
        int contact = 0;
        double deformation = 0.0;
        const int gcode = guards(md_.spatial, x, nx, tt.Y, m, md_.object.rho, md_.guards.band,
                                 md_.guards.max_deformation, &contact, &deformation);
        if (gcode != GUARD_OK) {
            stop.code = gcode;
            if (gcode == GUARD_NEAR_SINGULARITY) {
                copy(d_.x_fail, x, nx);
            } else if (gcode == GUARD_DEFORMATION) {
                stop.detail[0] = contact;
                d_.stop->value[0] = deformation;
            }
            return gcode;
        }
        if (md_.switches.energy != 0) {  // the energy guard; a passive run records the energy
            const plants::PlantEnergy e = plant_.energy(x);
            if (e.status != 0) {
                stop.code = TICK_PLANT_ERROR;
                stop.detail[0] = e.status;
                stop.detail[1] = 0;
                copy(d_.x_fail, x, nx);
                return TICK_PLANT_ERROR;
            }
            if (md_.switches.energy == 2 && !(std::abs(e.total) <= md_.switches.max_energy)) {
                stop.code = TICK_ENERGY;
                d_.stop->value[0] = e.total;
                return TICK_ENERGY;
            }
            if (md_.switches.passive) {
                d_.record.energy[k] = e.total;
                d_.record.kinetic_energy[k] = e.kinetic;
            }
        }
        copy(d_.x_good, x, nx);
        stop.last_good_tick = k;
        // ---- nominal motion and load
        const int64_t code = nominal_load(k);
        if (code != TICK_DONE || !assemble) return code;
        // ---- the QP of the split, from the measured terms
        return assemble_split(k, plant_.terms(sn.noisy_state ? TERMS_MEASURED : TERMS_TRUE), P_changed);
    }

    /// The compiled solve of the split the QP arrays hold, warm started, its answer check and binding families.
    bool solve_split(bool P_changed, int64_t* qs, int64_t* qit, int64_t* qb, int64_t* qact) noexcept {
        const QPConstants& c = md_.qp;
        const QPArrays& a = d_.qp;
        const int m = md_.m, p = md_.p, n = c.n, n_in = a.n_rows - p;
        const QP qp{n, a.n_rows, p, a.H, a.g, a.M, a.lo, a.hi};
        const bool first = d_.flags->qp_solves == 0;
        int64_t iterations = 0;
        const int code = gi_solve(qp, a.x, a.z, ws_, first || P_changed, c.numbers.eps_abs,
                                  static_cast<int64_t>(c.numbers.max_iter), &iterations);
        d_.flags->qp_solves += 1;
        *qs = code;
        *qit = iterations;
        const bool ok = code == GI_SOLVED && answer_ok(a.M, n, a.n_rows, a.lo, a.hi, a.x, n, p, c.numbers.eps_abs,
                                                       c.numbers.answer_rho);
        if (!ok) {
            d_.stop->code = TICK_QP_FAILED;
            d_.stop->detail[0] = code;
            d_.stop->detail[1] = iterations;
            *qb = 0;
            *qact = -1;
            return false;
        }
        d_.flags->consecutive_failures = 0;
        const QPRows& r = c.rows;
        *qb = binding_families(a.g, a.z, p, n, n_in, m, r.min_grip, r.friction, r.facets, r.torque_limits);
        *qact = gi_active_inequalities(ws_, p);
        return true;
    }

    /// Phase 2 of tick k: the split from `source`, the controllers, the saturation, the record row k, the plant.
    int64_t act(int64_t k, int64_t source, int64_t qs, int64_t qit, int64_t qb, int64_t qact) noexcept {
        const int m = md_.m, p = md_.p, npos = md_.npos, nx = md_.nx, nu = md_.nu;
        const TickRecord& rec = d_.record;
        StopReport& stop = *d_.stop;
        const bool noisy = md_.sensors.noisy_state;
        const SensedTerms tm = plant_.terms(noisy ? TERMS_MEASURED : TERMS_TRUE);
        const double* zx = noisy ? w_.xm.data() : d_.x;
        const double* Y = plant_.terms(TERMS_TRUE).Y;
        const double* Y0N = trajectory(0, k);
        const double t = static_cast<double>(md_.run.k_base + k) * md_.run.T;
        // ---- the split, the controllers and the saturation
        const int64_t code = control_torques(k, source, tm, zx);
        if (code != TICK_DONE) return code;
        // ---- record
        rec.t[k] = t;
        copy(rec.x + k * nx, d_.x, nx);
        copy(rec.tau + k * nu, d_.tau, nu);
        copy(rec.Y0_nominal + k * p, Y0N, p);
        const double* last = d_.last_split;
        for (int i = 0; i < m; ++i) {
            for (int a = 0; a < p; ++a) {
                const int64_t at = (k * m + i) * p + a;
                rec.F_measured[at] = w_.Fm[i * p + a];
                rec.F_commanded[at] = w_.F_set[i * p + a];
                rec.F_external[at] = last[(1 * m + i) * p + a];
                rec.F_internal[at] = last[(2 * m + i) * p + a];
            }
            for (int a = 0; a < npos; ++a) rec.r_contacts[(k * m + i) * npos + a] = Y[(i + 1) * p + a];
        }
        record_squeeze(rec.r_contacts + k * m * npos, w_.Fm.data(), rec.squeeze + k * w_.pairs);
        rec.qp_status[k] = qs;
        rec.qp_binding[k] = qb;
        rec.qp_iterations[k] = qit;
        rec.qp_active_rows[k] = qact;
        stop.ticks_recorded = k + 1;
        if (k == md_.run.N - 1) return TICK_RECORDED;
        if (md_.switches.plant_outside) {  // an integrator the core lacks: the caller advances x over the period
            stop.code = TICK_PLANT_EXTERNAL;
            stop.tick = k + 1;
            return TICK_PLANT_EXTERNAL;
        }
        // ---- plant, zero-order hold over the period
        const int step_code = advance(t);
        if (step_code != STEP_OK) {
            copy(d_.x, rec.x + k * nx, nx);  // the state of the tick (as the Python loop keeps it)
            return step_failed(step_code);
        }
        return TICK_DONE;
    }

private:
    static void copy(double* dst, const double* src, int n) noexcept {
        for (int c = 0; c < n; ++c) dst[c] = src[c];
    }
    /// Row k of the nominal motion's table `which` (0 pose, 1 rate, 2 acceleration), p entries.
    const double* trajectory(int which, int64_t k) const noexcept {
        return md_.run.traj + (which * md_.run.N + k) * md_.p;
    }
    int64_t plant_failed(const double* y) noexcept {
        d_.stop->code = TICK_PLANT_ERROR;
        d_.stop->detail[0] = status_[0];
        d_.stop->detail[1] = status_[1];
        copy(d_.x_fail, y, md_.nx);
        return TICK_PLANT_ERROR;
    }
    int64_t step_failed(int step_code) noexcept {
        StopReport& stop = *d_.stop;
        if (step_code == STEP_NEWTON_FAILED) {
            stop.code = TICK_NEWTON_FAILED;
        } else if (step_code == STEP_TOO_SMALL) {
            stop.code = TICK_STEP_TOO_SMALL;
        } else {
            stop.code = TICK_PLANT_ERROR;
            stop.detail[0] = status_[0];
            stop.detail[1] = status_[1];
        }
        return stop.code;
    }

    /// The plant over the period from t [s] with the held torques, one step per entry of the run's steps.
    int advance(double t) noexcept {
        AdvanceReport report;
        report.rhs_evaluations = d_.stop->rhs_evaluations;
        int code;
        if (plan_.family == PeriodPlan::EXPLICIT) {
            code = explicit_period(plan_.explicit_plan, d_.x, md_.nx, d_.tau, plant_, status_, t, md_.run.steps,
                                   md_.run.n_steps, d_.x_fail, report);
        } else if (plan_.family == PeriodPlan::EMBEDDED || plan_.family == PeriodPlan::TRBDF2) {
            TooSmallStep too_small;
            if (plan_.family == PeriodPlan::EMBEDDED)
                code = embedded_advance(plan_.embedded_plan, d_.x, md_.nx, d_.tau, plant_, status_, t, d_.x_fail, report,
                                        too_small);
            else
                code = trbdf2_advance(plan_.trbdf2_plan, d_.x, md_.nx, d_.tau, plant_, status_, t, d_.x_fail, report,
                                      too_small);
            if (code == STEP_TOO_SMALL) {
                d_.stop->value[0] = too_small.step;
                d_.stop->value[1] = too_small.time;
            }
        } else {
            code = implicit_period(plan_.implicit_plan, d_.x, md_.nx, d_.tau, plant_, status_, t, md_.run.steps,
                                   md_.run.n_steps, d_.x_fail, report);
            if (code == STEP_NEWTON_FAILED) {
                d_.stop->detail[0] = report.failed_step;
                d_.stop->detail[1] = report.newton_iterations;
                d_.stop->value[0] = report.last_correction;
                d_.stop->value[1] = report.failed_time;
            }
        }
        d_.stop->rhs_evaluations = report.rhs_evaluations;
        return code;
    }

    /// The nominal motion of the nodes at row k (148) and the object's required wrench w_N [N, N m].
    int64_t nominal_load(int64_t k) noexcept {
        const ObjectModel& ob = md_.object;
        const double *Y0N = trajectory(0, k), *dY0N = trajectory(1, k), *ddY0N = trajectory(2, k);
        if (md_.spatial) {
            const int bad = plants::spatial_motion(Y0N, dY0N, ddY0N, ob.grasps, md_.m, w_.Yn.data(), w_.dYn.data(),
                                                   w_.ddYn.data());
            if (bad >= 0) {
                d_.stop->code = TICK_NOMINAL_SINGULAR;
                d_.stop->detail[0] = bad;
                return TICK_NOMINAL_SINGULAR;
            }
        } else {
            plants::planar_motion(Y0N, dY0N, ddY0N, ob.grasps, md_.m, w_.Yn.data(), w_.dYn.data(), w_.ddYn.data());
        }
        required_wrench(md_.spatial, ob.mass, ob.inertia, ob.gravity, Y0N, dY0N, ddY0N, w_.wN.data());
        return TICK_DONE;
    }

    /// The QP of the split into the QP arrays from the measured terms tm and the nominal motion of row k.
    int64_t assemble_split(int64_t k, const SensedTerms& tm, bool* P_changed) noexcept {
        const int m = md_.m, p = md_.p, npos = md_.npos;
        const QPConstants& c = md_.qp;
        const QPRows& r = c.rows;
        QPArrays& a = d_.qp;
        const int n = c.n;
        const double* wN = w_.wN.data();
        double* rc = w_.rc.data();
        double* r0 = w_.r0.data();
        int64_t code = 0;
        for (int e = 0; e < p; ++e) {
            a.lo[e] = wN[e];
            a.hi[e] = wN[e];
        }
        for (int i = 0; i < m; ++i)
            for (int e = 0; e < npos; ++e) rc[i * npos + e] = tm.Y[(i + 1) * p + e];
        for (int e = 0; e < npos; ++e) r0[e] = tm.Y[e];
        fill_grasp_rows(a.M, n, rc, m, npos, r0, md_.spatial);
        if (md_.switches.elastic_split) {
            ElasticSplit es{m, p, p, a.M, n, md_.K_obj, trajectory(0, k), wN, a.K, a.H, a.external,
                            w_.elastic_KGt.data(), p, a.A, p, a.y, w_.elastic_Rb.data(), w_.elastic_work.data()};
            code = fill_elastic_split(es, md_.spatial, P_changed);
            if (code != ELASTIC_OK) {
                *P_changed = false;
                return qp_assembly_failed(code);  // -1 degenerate grasp, -3 singular grasp stiffness
            }
        } else if (!pseudo_inverse_external(a.M, n, p, c.W_inv_diag, n, wN, a.external, a.A, p, a.y)) {
            return qp_assembly_failed(-1);  // degenerate grasp
        }
        if (r.has_squeeze != 0) {
            if (!fill_squeeze_basis(a.E, a.ld_E, rc, m, npos, p)) {
                *P_changed = false;
                return qp_assembly_failed(-2);
            }
            for (int row = 0; row < n; ++row) {
                double s = 0.0;
                for (int e = 0; e < c.pairs; ++e) s += a.E[row * a.ld_E + e] * c.s_des[e];
                a.F_pref[row] = a.external[row] + s;
            }
        } else {
            for (int row = 0; row < n; ++row) a.F_pref[row] = a.external[row];
        }
        if (md_.switches.elastic_split) {  // g = -P F_pref
            for (int row = 0; row < n; ++row) {
                double s = 0.0;
                for (int e = 0; e < n; ++e) s += a.H[row * n + e] * a.F_pref[e];
                a.g[row] = -s;
            }
        } else {
            for (int row = 0; row < n; ++row) a.g[row] = -c.W_diag[row] * a.F_pref[row];
        }
        if (r.min_grip >= 0 || r.friction >= 0) {
            contact_normals(tm.Y, p, md_.spatial, w_.nrm.data(), npos, m, w_.R3.data());
            if (r.min_grip >= 0) fill_grip_rows(a.M, n, p + static_cast<int>(r.min_grip), w_.nrm.data(), m, npos, p);
            if (r.friction >= 0)
                fill_friction_rows(a.M, n, p + static_cast<int>(r.friction), w_.nrm.data(), npos, m, p,
                                   static_cast<int>(r.facets), c.numbers.mu_c, c.cos_phi, c.sin_phi, md_.spatial);
        }
        if (r.torque_limits >= 0) {
            const TorqueModelInputs in{m, p, tm.nmax, tm.Y, w_.ddYn.data(), tm.W, tm.w_free, tm.H, tm.h, tm.J,
                                       tm.Jdq, md_.arm_kind, md_.arm_dof};
            TorqueModel out{w_.Jg.data(), w_.nw, w_.bias.data()};
            TorqueModelWork work{w_.Wa.data(), w_.rhs_t.data(), w_.qdd.data(), w_.piv.data(), w_.vectors.data(),
                                 w_.matrices.data(), w_.nw, w_.R3.data()};
            torque_model(md_.spatial, in, out, work);
            fill_torque_rows(a.M, a.lo, a.hi, n, p + static_cast<int>(r.torque_limits), w_.Jg.data(),
                             static_cast<long>(p) * w_.nw, w_.nw, md_.arm_dof, m, p, c.tau_qp, w_.bias.data());
        }
        return TICK_DONE;
    }
    int64_t qp_assembly_failed(int64_t detail) noexcept {
        d_.stop->code = TICK_QP_FAILED;
        d_.stop->detail[0] = detail;
        return TICK_QP_FAILED;
    }

    /// The split of tick k (source), the followers' setpoints and readings, the laws into tau, the saturation.
    int64_t control_torques(int64_t k, int64_t source, const SensedTerms& tm, const double* zx) noexcept {
        const int m = md_.m, p = md_.p, nu = md_.nu;
        const ProbeModel& pr = md_.probes;
        double* F_set = w_.F_set.data();
        double* last = d_.last_split;
        const double* xq = d_.qp.x;
        const double* external = d_.qp.external;
        // ---- the split
        if (source == SPLIT_SOLVED) {
            for (int e = 0; e < m * p; ++e) {
                F_set[e] = xq[e];
                last[e] = xq[e];
                last[m * p + e] = external[e];
                last[2 * m * p + e] = xq[e] - external[e];
            }
            d_.flags->have_last_split = 1;
        } else if (source == SPLIT_HELD) {
            for (int e = 0; e < m * p; ++e) F_set[e] = last[e];
        } else {
            for (int e = 0; e < m * p; ++e) F_set[e] = 0.0;
        }
        // the followers' setpoint and measured force (a tuning probe's F* + r + v and delayed, scaled error)
        for (int e = 0; e < m * p; ++e) {
            if (pr.followers) {
                const double fc = (F_set[e] + pr.offset[e]) + pr.pi_output[e];
                const int64_t j = std::max<int64_t>(k - pr.delay[e], 0);  // the reading of tick j
                const double seen = j == k ? w_.Fm[e] : d_.record.F_measured[j * m * p + e];
                w_.F_cmd[e] = fc;
                w_.F_seen[e] = fc - pr.gain[e] * (fc - seen);
            } else {
                w_.F_cmd[e] = F_set[e];
                w_.F_seen[e] = w_.Fm[e];
            }
        }
        // ---- controllers: the leader on its nominal deformed node
        int arm = 0;
        const int64_t ccode = control(tm, zx, trajectory(0, k), &arm);
        if (ccode != TICK_DONE) {
            d_.stop->code = ccode;
            d_.stop->detail[0] = arm;
            return ccode;
        }
        // ---- actuator saturation
        const double* tau_max = md_.qp.tau_max;
        double* tau = d_.tau;
        bool sat = false;
        for (int c = 0; c < nu; ++c)
            if (std::abs(tau[c]) > tau_max[c]) sat = true;
        if (sat) {
            LoopFlags& f = *d_.flags;
            f.saturated_ticks += 1;
            if (f.saturated_ticks == 1) f.first_saturated = md_.run.k_base + k;
            f.last_saturated = md_.run.k_base + k;
            for (int c = 0; c < nu; ++c)
                if (std::abs(tau[c]) > tau_max[c]) d_.saturated_joints[c] += 1;
            for (int c = 0; c < nu; ++c) {
                if (tau[c] < -tau_max[c])
                    tau[c] = -tau_max[c];
                else if (tau[c] > tau_max[c])
                    tau[c] = tau_max[c];
            }
        }
        return TICK_DONE;
    }

    /// The leader's and the followers' laws into tau (before saturation); a passive run keeps tau = 0.
    int64_t control(const SensedTerms& tm, const double* zx, const double* Y0N, int* arm) noexcept {
        const int m = md_.m, p = md_.p, npos = md_.npos, nz = md_.nx / 2, nmax = tm.nmax;
        const ControlModel& cm = md_.control;
        const int leader = cm.leader, kl = leader + 1;
        ControlWork& cw = w_.control;
        const double *Yn = w_.Yn.data(), *dYn = w_.dYn.data(), *ddYn = w_.ddYn.data();
        double *inc = w_.inc.data(), *Yv = w_.Yv.data(), *err = w_.err.data(), *a_cmd = w_.a_cmd.data();
        const int pp = p * p;
        if (!pose_increment(md_.spatial, cm.compliance + leader * pp, w_.F_set.data() + leader * p, Y0N, Yn + kl * p,
                            cw, inc)) {
            *arm = leader;
            return TICK_POSE_INCREMENT_SINGULAR;
        }
        for (int i = 0; i < (md_.switches.passive ? 0 : m); ++i) {
            const int ki = i + 1;
            const int ni = static_cast<int>(md_.arm_dof[i]);
            const int o = static_cast<int>(md_.q_offset[i]);
            if (i == leader) {
                leader_target(Yn + kl * p, inc, md_.probes.leader_offset, p, Yv);
                pose_error(Yv, tm.Y + kl * p, p, npos, err);
                if (!node_law(cm.leader_law, err, dYn + kl * p, tm.dY + kl * p, ddYn + kl * p, a_cmd)) {
                    *arm = i;
                    return TICK_LAW_FAILED;
                }
            } else {
                double* corr = w_.corr.data();
                follower_correction(w_.F_cmd.data() + i * p, w_.F_seen.data() + i * p, d_.integrals + i * p,
                                    md_.run.T, cm.follower_kp, cm.follower_ki, cm.integral_limit, cm.force_loop, p,
                                    corr);
                const NodeLaw& law = cm.follower_law;
                if (law.kind == LAW_COMPUTED_TORQUE) {  // target, error and law in one (the loop's own)
                    if (!follower_acceleration(md_.spatial, cm.compliance + i * pp, corr, Y0N, Yn + ki * p,
                                               tm.Y + ki * p, dYn + ki * p, tm.dY + ki * p, ddYn + ki * p,
                                               law.params[0], law.params[1], p, npos, cw, Yv, err, a_cmd)) {
                        *arm = i;
                        return TICK_POSE_INCREMENT_SINGULAR;
                    }
                } else {  // the target Y_rigid + pose_increment(corr), then the given law on the error to it
                    if (!pose_increment(md_.spatial, cm.compliance + i * pp, corr, Y0N, Yn + ki * p, cw, Yv)) {
                        *arm = i;
                        return TICK_POSE_INCREMENT_SINGULAR;
                    }
                    for (int a = 0; a < p; ++a) Yv[a] += Yn[ki * p + a];
                    pose_error(Yv, tm.Y + ki * p, p, npos, err);
                    if (!node_law(law, err, dYn + ki * p, tm.dY + ki * p, ddYn + ki * p, a_cmd)) {
                        *arm = i;
                        return TICK_LAW_FAILED;
                    }
                }
            }
            if (!arm_torque(md_.arm_kind[i] != 0, ni, p, tm.W + ki * pp, tm.w_free + ki * p, tm.S + ki * p,
                            tm.H + i * nmax * nmax, nmax, tm.h + i * nmax, tm.J + i * p * nmax, nmax, tm.Jdq + i * p,
                            a_cmd, zx + o, zx + nz + o, cm.q_rest + i * cm.ld_q_rest, cm.posture_gain, cw,
                            w_.ti.data())) {
                *arm = i;
                return TICK_SINGULAR_JACOBIAN;
            }
            for (int c = 0; c < ni; ++c) d_.tau[o + c] = w_.ti[c];
        }
        return TICK_DONE;
    }

    /// A node's commanded acceleration from its pose error by its law (coopctrl/controllers/leader_law.py's laws,
    /// or the caller's); false where a law given as a callback failed.
    bool node_law(const NodeLaw& law, const double* err, const double* dY_ref, const double* dY,
                  const double* ddY_ref, double* a_cmd) const noexcept {
        const double* params = law.params;
        if (law.kind == LAW_COMPUTED_TORQUE) {
            acceleration_from_error(err, dY_ref, dY, ddY_ref, params[0], params[1], md_.p, a_cmd);
            return true;
        }
        if (law.kind == LAW_CALLBACK)
            return law.callback.call(law.callback.context, err, dY_ref, dY, ddY_ref, md_.p, md_.npos, a_cmd);
        for (int a = 0; a < md_.p; ++a) {  // object impedance: (M, D, K) of the positions, then of the angles
            const int o = a < md_.npos ? 0 : 3;
            a_cmd[a] = ddY_ref[a] + (params[o + 1] / params[o]) * (dY_ref[a] - dY[a]) +
                       (params[o + 2] / params[o]) * err[a];
        }
        return true;
    }

    /// The virtual-linkage squeeze of the measured wrenches F (m, p) at the contacts r (m, npos) [m] into out
    /// (pairs) [N] (squeeze.h).
    void record_squeeze(const double* r, const double* F, double* out) noexcept {
        SqueezeWork work{md_.squeeze_desired, w_.sq_E.data(), w_.sq_W.data(), w_.sq_V.data(), w_.sq_sigma.data()};
        pair_squeeze(r, md_.m, md_.npos, F, md_.p, work, out);
    }

    const TickModel& md_;
    TickData& d_;
    Plant& plant_;
    PeriodPlan& plan_;
    GIWorkspace& ws_;
    TickWork w_;
    int64_t status_[2] = {0, 0};
};

}  // namespace coopctrl
