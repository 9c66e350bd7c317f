// The closed loop's tick in coopctrl._core (coopctrl/core/tick.h): `Tick(model, data)` reads a run's model and data
// by name once (coopctrl/loop/model.py's LoopModel with its ControlModel, data.py's LoopData with its integration
// plan), then `run_ticks(k0, k_stop)` runs ticks, `reference_step(...)` serves the reference path and
// `controller_step(...)` the Controller.
// The arrays are the run's own: what the tick writes is in them.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "coopctrl/core/adaptive_plan_reader.h"
#include "coopctrl/core/array_reader.h"
#include "coopctrl/core/goldfarb_idnani.h"
#include "coopctrl/core/plan_reader.h"
#include "coopctrl/core/qp_constants_reader.h"
#include "coopctrl/core/tick.h"
#include "coopctrl/core/tick_model.h"
#include "coopctrl/core/tick_plants.h"
#include "plants/core/planar_plant_reader.h"
#include "plants/core/spatial_plant_reader.h"

namespace coopctrl::binding {

namespace {

using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;


template <class T>
T attr(nb::handle owner, const char* name) {
    return nb::cast<T>(owner.attr(name));
}

/// data.<name>, one of the run-state classes (bind_loop_state.cpp), the object itself: the tick writes into it.
template <class T>
T& run_state(nb::handle data, const char* name, const char* type_name) {
    T* value = nullptr;
    if (!nb::try_cast<T*>(data.attr(name), value) || value == nullptr)
        throw nb::type_error((std::string("data.") + name + ": expected a " + type_name).c_str());
    return *value;
}

/// A node law written in Python, f(err, dY_ref, dY, ddY_ref, npos, params, a_cmd) writing a_cmd in place, called
/// by the tick through LawCallback (the documented slower path: the GIL is taken for each call).
struct PythonLaw {
    nb::callable f;
    nb::object params;                       // the law's constants, a float64 array
    nb::object err, dY_ref, dY, ddY_ref, a_cmd;  // float64 (p,) arrays the tick's values are copied into
    double *err_, *dY_ref_, *dY_, *ddY_ref_, *a_cmd_;
    nb::object raised;                       // what f raised, raised again when the tick returns
    std::string refused;                     // why its answer was refused

    PythonLaw(nb::callable function, nb::object constants, int p) : f(std::move(function)), params(constants) {
        auto make = [p](double*& data) {
            double* values = new double[p]();
            nb::capsule owner(values, [](void* v) noexcept { delete[] static_cast<double*>(v); });
            data = values;
            return nb::cast(nb::ndarray<nb::numpy, double, nb::ndim<1>>(values, {static_cast<size_t>(p)}, owner));
        };
        err = make(err_), dY_ref = make(dY_ref_), dY = make(dY_), ddY_ref = make(ddY_ref_), a_cmd = make(a_cmd_);
    }

    static bool call(void* context, const double* e, const double* dyr, const double* dy, const double* ddyr, int p,
                     int npos, double* out) noexcept {
        auto* self = static_cast<PythonLaw*>(context);
        nb::gil_scoped_acquire gil;
        for (int a = 0; a < p; ++a) {
            self->err_[a] = e[a], self->dY_ref_[a] = dyr[a], self->dY_[a] = dy[a], self->ddY_ref_[a] = ddyr[a];
            self->a_cmd_[a] = std::nan("");
        }
        try {
            self->f(self->err, self->dY_ref, self->dY, self->ddY_ref, npos, self->params, self->a_cmd);
        } catch (nb::python_error& error) {
            self->raised = nb::borrow(error.value());
            return false;
        }
        for (int a = 0; a < p; ++a) {
            if (!std::isfinite(self->a_cmd_[a])) {
                self->refused = "a_cmd[" + std::to_string(a) + "] = " + std::to_string(self->a_cmd_[a]) +
                                ": expected the law to write a finite acceleration into every entry of a_cmd";
                return false;
            }
            out[a] = self->a_cmd_[a];
        }
        return true;
    }

    /// Raise what the law raised or why its answer was refused, if it did.
    void raise_if_failed(const char* which) {
        if (raised.is_valid()) {
            nb::object exc = raised;
            raised = nb::object();
            PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(exc.ptr())), exc.ptr());
            throw nb::python_error();
        }
        if (!refused.empty()) {
            const std::string why = std::string(which) + ": " + refused;
            refused.clear();
            throw nb::value_error(why.c_str());
        }
    }
};

/// control.<name>: a built-in law's name (with control.<name>_params) or a Python function (then `python` holds it).
NodeLaw read_law(nb::handle control, const char* name, std::unique_ptr<PythonLaw>& python, int p) {
    const std::string params_name = std::string(name) + "_params";
    NodeLaw law{};
    law.n_params = static_cast<int>(extent(control, params_name.c_str(), 0));
    law.params = doubles(control, "control", params_name.c_str(), {law.n_params});
    nb::object given = control.attr(name);
    if (nb::isinstance<nb::str>(given)) {
        const std::string kind = nb::cast<std::string>(given);
        if (kind == "computed_torque" && law.n_params == 2)
            law.kind = LAW_COMPUTED_TORQUE;
        else if (kind == "object_impedance" && law.n_params == 6)
            law.kind = LAW_OBJECT_IMPEDANCE;
        else
            throw nb::value_error(("control." + std::string(name) + " = '" + kind + "' with " +
                                   std::to_string(law.n_params) + " constants: expected 'computed_torque' (2) or "
                                   "'object_impedance' (6), or a Python function").c_str());
        return law;
    }
    if (!PyCallable_Check(given.ptr()))
        throw nb::type_error(("control." + std::string(name) + ": expected a law's name or a Python function").c_str());
    python = std::make_unique<PythonLaw>(nb::borrow<nb::callable>(given), control.attr(params_name.c_str()), p);
    law.kind = LAW_CALLBACK;
    law.callback = LawCallback{&PythonLaw::call, python.get()};
    return law;
}

/// One run's tick: the model and data read by name, the plant, the plan and the QP workspace.
class TickRun {
public:
    TickRun(nb::object model, nb::object data)
        : model_obj_(model), data_obj_(data), plan_obj_(data.attr("plan")), control_obj_(model.attr("control")) {
        read_model(model, control_obj_);
        read_data(data);
        read_plan(plan_obj_);
        if (md_.spatial) {
            spatial_ = std::make_unique<plants::binding::SpatialPlant>(model.attr("P"));
            spatial_plant_ = std::make_unique<SpatialTickPlant>(spatial_->model, md_.nx);
            spatial_tick_ = std::make_unique<Tick<SpatialTickPlant>>(md_, d_, *spatial_plant_, plan_, ws_);
        } else {
            planar_ = std::make_unique<plants::binding::PlanarPlant>(model.attr("P"));
            planar_plant_ = std::make_unique<PlanarTickPlant>(planar_->model, md_.nx);
            planar_tick_ = std::make_unique<Tick<PlanarTickPlant>>(md_, d_, *planar_plant_, plan_, ws_);
        }
    }

    void run_ticks(int64_t k0, int64_t k_stop) {
        {
            nb::gil_scoped_release release;
            if (md_.spatial)
                spatial_tick_->run(k0, k_stop);
            else
                planar_tick_->run(k0, k_stop);
        }
        raise_law_errors();
    }

    /// The controller's step (tick.h's controller_step) from a measurement: q, dq tuples of per-arm arrays.
    int64_t controller_step(int64_t k, bool hold, nb::tuple q, nb::tuple dq, Matrix wrench, Vector pose,
                            Vector twist) {
        const size_t m = static_cast<size_t>(md_.m), p = static_cast<size_t>(md_.p);
        if (q.size() != m || dq.size() != m) throw nb::value_error("q, dq: expected one array per arm");
        if (wrench.shape(0) != m || wrench.shape(1) != p || pose.shape(0) != p || twist.shape(0) != p)
            throw nb::value_error("wrench, pose, twist: expected shapes (m, p), (p,), (p,)");
        const double* qs[64];
        const double* dqs[64];
        if (m > 64) throw nb::value_error("q: at most 64 arms");
        for (size_t i = 0; i < m; ++i) {
            Vector a = nb::cast<Vector>(q[i]), b = nb::cast<Vector>(dq[i]);
            if (a.shape(0) != static_cast<size_t>(md_.arm_dof[i]) || b.shape(0) != a.shape(0))
                throw nb::value_error(("q[" + std::to_string(i) + "], dq[" + std::to_string(i) +
                                       "]: expected the arm's joint count each").c_str());
            qs[i] = a.data();
            dqs[i] = b.data();
        }
        int64_t code = md_.spatial ? spatial_tick_->controller_step(k, hold, qs, dqs, wrench.data(), pose.data(),
                                                                      twist.data())
                                   : planar_tick_->controller_step(k, hold, qs, dqs, wrench.data(), pose.data(),
                                                                     twist.data());
        raise_law_errors();
        return code;
    }

    /// The plant's world turned in place (a chart re-centred, coopctrl.loop.charts): its bases and gravity read
    /// again.
    void world_moved() {
        if (spatial_) spatial_->read_world();
    }

    nb::tuple reference_step(int64_t k, bool act, int64_t source, int64_t qs, int64_t qit, int64_t qb,
                             bool sense_next) {
        bool P_changed = false;
        int64_t code;
        {
            nb::gil_scoped_release release;
            code = md_.spatial ? spatial_tick_->reference_step(k, act, source, qs, qit, qb, sense_next, &P_changed)
                               : planar_tick_->reference_step(k, act, source, qs, qit, qb, sense_next, &P_changed);
        }
        raise_law_errors();
        return nb::make_tuple(code, P_changed);
    }

private:
    void raise_law_errors() {
        if (leader_callback_) leader_callback_->raise_if_failed("the leader's law");
        if (follower_callback_) follower_callback_->raise_if_failed("the followers' law");
    }

    void read_model(nb::handle model, nb::handle control) {
        const char* M = "model";
        md_.spatial = attr<bool>(model, "spatial");
        nb::handle P = model.attr("P");
        const int64_t m = extent(P, "arm_kind", 0);
        md_.m = static_cast<int>(m);
        md_.p = md_.spatial ? 6 : 3;
        md_.npos = md_.spatial ? 3 : 2;
        const int64_t p = md_.p, npos = md_.npos;
        md_.arm_kind = ints(P, "P", "arm_kind", {m});
        md_.arm_dof = ints(P, "P", "arm_dof", {m});
        md_.q_offset = ints(P, "P", "q_off", {m});
        int64_t nu = 0;
        for (int64_t i = 0; i < m; ++i) nu += md_.arm_dof[i];
        md_.nu = static_cast<int>(nu);
        nb::handle data = data_obj_;
        md_.nx = static_cast<int>(extent(data, "x", 0));
        const int64_t nx = md_.nx, nz = nx / 2;
        // the run
        RunModel& run = md_.run;
        run.N = attr<int64_t>(model, "N");
        run.k_base = attr<int64_t>(model, "k_base");
        run.T = attr<double>(model, "T");
        run.n_steps = static_cast<int>(extent(model, "steps", 0));
        run.steps = doubles(model, M, "steps", {run.n_steps});
        run.traj = doubles(model, M, "traj", {3, run.N, p});
        // the object
        ObjectModel& ob = md_.object;
        ob.mass = attr<double>(model, "object_mass");
        const double* inertia = doubles(model, M, "object_inertia", {md_.spatial ? 3 : 1});
        for (int a = 0; a < (md_.spatial ? 3 : 1); ++a) ob.inertia[a] = inertia[a];
        ob.grasps = doubles(model, M, "grasps", {m, p});
        ob.rho = doubles(model, M, "rho", {m, npos});
        ob.gravity = doubles(P, "P", "gravity", {npos});
        md_.guards.max_deformation = attr<double>(model, "max_deformation");
        md_.guards.band = attr<double>(model, "band");
        // the sensors
        SensorModel& sn = md_.sensors;
        nb::handle sensors = model.attr("sensors");
        const char* S = "sensors";
        sn.rows_joints = extent(sensors, "joints", 0);
        sn.joints = doubles(sensors, S, "joints", {sn.rows_joints, 2 * (nz - p)});
        sn.rows_object = extent(sensors, "object", 0);
        sn.object = doubles(sensors, S, "object", {sn.rows_object, 2 * p});
        sn.rows_wrench = extent(sensors, "wrench", 0);
        sn.wrench = doubles(sensors, S, "wrench", {sn.rows_wrench, m * p});
        sn.noisy_state = attr<bool>(sensors, "noisy_state");
        sn.joint_step = attr<double>(sensors, "joint_step");
        sn.object_step = attr<double>(sensors, "object_step");
        sn.wrench_step = attr<double>(sensors, "wrench_step");
        // the control model, by name (coopctrl/loop/model.py's ControlModel)
        ControlModel& cm = md_.control;
        const char* C = "control";
        cm.leader = attr<int>(control, "leader");
        cm.leader_Kp = attr<double>(control, "leader_Kp");
        cm.leader_Kd = attr<double>(control, "leader_Kd");
        cm.follower_kp = attr<double>(control, "follower_kp");
        cm.follower_ki = attr<double>(control, "follower_ki");
        cm.follower_Kp = attr<double>(control, "follower_Kp");
        cm.follower_Kd = attr<double>(control, "follower_Kd");
        cm.force_loop = attr<bool>(control, "force_loop");
        cm.integral_limit = attr<double>(control, "integral_limit");
        const double* gain = doubles(control, C, "posture_gain", {2});
        cm.posture_gain[0] = gain[0];
        cm.posture_gain[1] = gain[1];
        cm.ld_q_rest = static_cast<int>(extent(control, "q_rest", 1));
        cm.q_rest = doubles(control, C, "q_rest", {m, cm.ld_q_rest});
        cm.compliance = doubles(control, C, "compliance", {m, p, p});
        cm.leader_law = read_law(control, "leader_law", leader_callback_, md_.p);
        cm.follower_law = read_law(control, "follower_law", follower_callback_, md_.p);
        if (cm.leader < 0 || cm.leader >= m) throw nb::value_error("control.leader: expected an arm index");
        // the QP's constants (QPConstants, by name)
        nb::handle qp = model.attr("qp");
        QPConstants& c = md_.qp;
        c.n = static_cast<int>(m * p);
        c.nu = md_.nu;
        c.pairs = static_cast<int>(extent(qp, "s_des", 0));
        c.W_diag = doubles(qp, "qp", "W_diag", {c.n});
        c.W_inv_diag = doubles(qp, "qp", "W_inv_diag", {c.n});
        c.s_des = doubles(qp, "qp", "s_des", {c.pairs});
        c.tau_qp = doubles(qp, "qp", "tau_qp", {nu});
        c.tau_max = doubles(qp, "qp", "tau_max", {nu});
        c.cos_phi = doubles(qp, "qp", "cos_phi", {ANY});
        c.sin_phi = doubles(qp, "qp", "sin_phi", {ANY});
        c.numbers = read_qp_numbers(qp);
        c.rows = read_qp_rows(qp);
        // the switches and the probes (RunOptions, by name)
        nb::handle opts = model.attr("opts");
        RunSwitches& sw = md_.switches;
        sw.passive = attr<bool>(opts, "passive");
        sw.energy = attr<int>(opts, "energy");
        sw.max_energy = attr<double>(opts, "max_energy");
        sw.elastic_split = attr<bool>(opts, "elastic_split");
        sw.plant_outside = attr<bool>(opts, "plant_outside");
        md_.probes.followers = attr<bool>(opts, "probes");
        if (sw.energy < 0 || sw.energy > 2) throw nb::value_error("opts.energy: expected 0, 1 or 2");
        md_.K_obj = doubles(opts, "opts", "K_obj", {m, p, p});
        ProbeModel& pr = md_.probes;
        pr.leader_offset = doubles(opts, "opts", "leader_offset", {p});
        pr.offset = doubles(opts, "opts", "probe_offset", {m, p});
        pr.pi_output = doubles(opts, "opts", "probe_pi", {m, p});
        pr.gain = doubles(opts, "opts", "probe_gain", {m, p});
        pr.delay = ints(opts, "opts", "probe_delay", {m, p});
    }

    void read_data(nb::handle data) {
        const char* D = "data";
        const int64_t m = md_.m, p = md_.p, nx = md_.nx, nu = md_.nu, N = md_.run.N, npos = md_.npos;
        d_.x = doubles(data, D, "x", {nx});
        d_.tau = doubles(data, D, "tau", {nu});
        d_.integrals = doubles(data, D, "integrals", {m, p});
        d_.last_split = doubles(data, D, "last_split", {3, m, p});
        d_.flags = &run_state<LoopFlags>(data, "flags", "coopctrl._core.LoopFlags");
        d_.saturated_joints = ints(data, D, "saturated_joints", {nu});
        d_.hold = &run_state<HoldState>(data, "hold", "coopctrl._core.HoldState");
        d_.x_good = doubles(data, D, "x_good", {nx});
        d_.x_fail = doubles(data, D, "x_fail", {nx});
        d_.stop = &run_state<StopReport>(data, "stop", "coopctrl._core.StopReport");
        // the QP arrays (QPArrays, by name)
        nb::handle qa = data.attr("qp_arrays");
        const int64_t n = m * p;
        QPArrays& a = d_.qp;
        a.n_rows = static_cast<int>(extent(qa, "M", 0));
        a.M = doubles(qa, "qp_arrays", "M", {a.n_rows, n});
        a.lo = doubles(qa, "qp_arrays", "lo", {a.n_rows});
        a.hi = doubles(qa, "qp_arrays", "hi", {a.n_rows});
        a.H = doubles(qa, "qp_arrays", "H", {n, n});
        a.g = doubles(qa, "qp_arrays", "g", {n});
        a.x = doubles(qa, "qp_arrays", "x", {n});
        a.z = doubles(qa, "qp_arrays", "z", {a.n_rows});
        a.external = doubles(qa, "qp_arrays", "external", {n});
        a.F_pref = doubles(qa, "qp_arrays", "F_pref", {n});
        a.ld_E = static_cast<int>(extent(qa, "E", 1));
        a.E = doubles(qa, "qp_arrays", "E", {n, a.ld_E});
        a.A = doubles(qa, "qp_arrays", "A", {p, p});
        a.y = doubles(qa, "qp_arrays", "y", {p});
        a.K = doubles(qa, "qp_arrays", "K", {n, n});
        // the compiled QP's workspace (its warm start): the tuple (mats, vecs, rowv, ints) of gi_workspace
        nb::tuple ws = nb::cast<nb::tuple>(data.attr("ws"));
        if (ws.size() != 4) throw nb::value_error("data.ws: expected the tuple (mats, vecs, rowv, ints) of gi_workspace");
        using F3 = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
        using F2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
        using I1 = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
        F3 mats;
        F2 vecs, rowv;
        I1 wints;
        if (!nb::try_cast(ws[0], mats, false) || !nb::try_cast(ws[1], vecs, false) || !nb::try_cast(ws[2], rowv, false) ||
            !nb::try_cast(ws[3], wints, false) || mats.shape(1) != static_cast<size_t>(n) ||
            rowv.shape(1) != static_cast<size_t>(a.n_rows) ||
            wints.shape(0) != static_cast<size_t>(gi_ints_length(static_cast<int>(n), a.n_rows)))
            throw nb::value_error("data.ws: expected gi_workspace(n, n_rows) of this run's QP");
        ws_ = gi_workspace_view(static_cast<int>(n), a.n_rows, mats.data(), vecs.data(), rowv.data(), wints.data());
        // the record's rows (TickRecord, by name)
        nb::handle r = data.attr("record");
        md_.squeeze_desired = doubles(data.attr("sq"), "data.sq", "desired", {m * (m - 1) / 2});
        if (r.is_none()) return;  // a controller's step records nothing
        const char* R = "record";
        TickRecord& rec = d_.record;
        const int64_t pairs = extent(r, "squeeze", 1);
        rec.t = doubles(r, R, "t", {ANY});
        rec.x = doubles(r, R, "x", {ANY, nx});
        rec.tau = doubles(r, R, "tau", {ANY, nu});
        rec.Y0_nominal = doubles(r, R, "Y0_nominal", {ANY, p});
        rec.F_measured = doubles(r, R, "F_measured", {ANY, m, p});
        rec.F_commanded = doubles(r, R, "F_commanded", {ANY, m, p});
        rec.F_external = doubles(r, R, "F_external", {ANY, m, p});
        rec.F_internal = doubles(r, R, "F_internal", {ANY, m, p});
        rec.r_contacts = doubles(r, R, "r_contacts", {ANY, m, npos});
        rec.squeeze = doubles(r, R, "squeeze", {ANY, pairs});
        rec.qp_status = ints(r, R, "qp_status", {ANY});
        rec.qp_binding = ints(r, R, "qp_binding", {ANY});
        rec.qp_iterations = ints(r, R, "qp_iterations", {ANY});
        rec.qp_active_rows = ints(r, R, "qp_active_rows", {ANY});
        for (const char* name : {"t", "x", "tau", "Y0_nominal", "F_measured", "F_commanded", "F_external",
                                 "F_internal", "r_contacts", "squeeze", "qp_status", "qp_binding", "qp_iterations",
                                 "qp_active_rows"})
            if (extent(r, name, 0) < N)
                throw nb::value_error((std::string("record.") + name + ": expected at least N = " +
                                       std::to_string(N) + " rows").c_str());
        if (pairs != m * (m - 1) / 2) throw nb::value_error("record.squeeze: expected m (m - 1) / 2 columns");
        nb::handle opts = model_obj_.attr("opts");
        rec.energy = doubles(opts, "opts", "energy_record", {ANY});
        rec.kinetic_energy = doubles(opts, "opts", "kinetic_energy_record", {ANY});
        if (md_.switches.passive && (extent(opts, "energy_record", 0) < N || extent(opts, "kinetic_energy_record", 0) < N))
            throw nb::value_error("opts.energy_record, opts.kinetic_energy_record: expected at least N rows");
    }

    void read_plan(nb::handle plan) {
        const std::string kind = plan_kind(plan);
        if (kind == "ExplicitPlan") {
            plan_.family = PeriodPlan::EXPLICIT;
            plan_.explicit_plan = read_explicit_plan(plan, md_.nx);
        } else if (kind == "ImplicitPlan") {
            plan_.family = PeriodPlan::IMPLICIT;
            plan_.implicit_plan = read_implicit_plan(plan, md_.nx, pinv_work_);
        } else if (kind == "EmbeddedPlan") {
            plan_.family = PeriodPlan::EMBEDDED;
            plan_.embedded_plan = embedded_plan(plan, static_cast<size_t>(md_.nx));
        } else if (kind == "TRBDF2Plan") {
            plan_.family = PeriodPlan::TRBDF2;
            plan_.trbdf2_plan = trbdf2_plan(plan, static_cast<size_t>(md_.nx), pinv_work_);
        } else {
            throw nb::type_error(("plan: a " + kind + ": expected an ExplicitPlan, ImplicitPlan, EmbeddedPlan or "
                                  "TRBDF2Plan").c_str());
        }
    }

    nb::object model_obj_, data_obj_, plan_obj_, control_obj_;  // the arrays the tick points into, kept alive
    std::unique_ptr<PythonLaw> leader_callback_, follower_callback_;
    TickModel md_{};
    TickData d_{};
    PeriodPlan plan_{};
    std::vector<double> pinv_work_;
    GIWorkspace ws_{};
    std::unique_ptr<plants::binding::PlanarPlant> planar_;
    std::unique_ptr<PlanarTickPlant> planar_plant_;
    std::unique_ptr<Tick<PlanarTickPlant>> planar_tick_;
    std::unique_ptr<plants::binding::SpatialPlant> spatial_;
    std::unique_ptr<SpatialTickPlant> spatial_plant_;
    std::unique_ptr<Tick<SpatialTickPlant>> spatial_tick_;
};

}  // namespace

void bind_tick(nb::module_& m) {
    // the stop codes and split sources by name (coopctrl/loop/tick_codes.py states the same numbers)
    nb::dict codes;
    codes["DONE"] = static_cast<int64_t>(TICK_DONE), codes["NONFINITE"] = static_cast<int64_t>(TICK_NONFINITE), codes["NEAR_SINGULARITY"] = static_cast<int64_t>(TICK_NEAR_SINGULARITY);
    codes["DEFORMATION"] = static_cast<int64_t>(TICK_DEFORMATION), codes["PLANT_ERROR"] = static_cast<int64_t>(TICK_PLANT_ERROR), codes["QP_FAILED"] = static_cast<int64_t>(TICK_QP_FAILED);
    codes["NOMINAL_SINGULAR"] = static_cast<int64_t>(TICK_NOMINAL_SINGULAR), codes["SINGULAR_JACOBIAN"] = static_cast<int64_t>(TICK_SINGULAR_JACOBIAN);
    codes["POSE_INCREMENT_SINGULAR"] = static_cast<int64_t>(TICK_POSE_INCREMENT_SINGULAR), codes["CHUNK_END"] = static_cast<int64_t>(TICK_CHUNK_END);
    codes["NEWTON_FAILED"] = static_cast<int64_t>(TICK_NEWTON_FAILED), codes["ENERGY"] = static_cast<int64_t>(TICK_ENERGY);
    codes["PLANT_EXTERNAL"] = static_cast<int64_t>(TICK_PLANT_EXTERNAL), codes["STEP_TOO_SMALL"] = static_cast<int64_t>(TICK_STEP_TOO_SMALL);
    codes["RECORDED"] = static_cast<int64_t>(TICK_RECORDED), codes["MEASUREMENT_NOT_FINITE"] = static_cast<int64_t>(TICK_MEASUREMENT_NOT_FINITE);
    codes["LAW_FAILED"] = static_cast<int64_t>(TICK_LAW_FAILED);
    codes["SPLIT_SOLVED"] = static_cast<int64_t>(SPLIT_SOLVED), codes["SPLIT_HELD"] = static_cast<int64_t>(SPLIT_HELD), codes["SPLIT_NONE"] = static_cast<int64_t>(SPLIT_NONE);
    m.attr("TICK_CODES") = codes;

    nb::class_<TickRun>(m, "Tick",
                        "One run's closed-loop tick (coopctrl/core/tick.h) on its model (coopctrl.loop.model.LoopModel) and "
                        "data (coopctrl.loop.data.LoopData), read by name once; the run's arrays are written in place.")
        .def(nb::init<nb::object, nb::object>(), nb::arg("model"), nb::arg("data"))
        .def("run_ticks", &TickRun::run_ticks, nb::arg("k0"), nb::arg("k_stop"),
             "Ticks k0 .. until N are recorded, an event, or tick k_stop; data.stop says which.")
        .def("controller_step", &TickRun::controller_step, nb::arg("k"), nb::arg("hold"), nb::arg("q"), nb::arg("dq"),
             nb::arg("wrench"), nb::arg("pose"), nb::arg("twist"),
             "The controller's step from a measurement at row k of the trajectory table (coopctrl.Controller); the "
             "code (data.stop.code), the torques in data.tau.")
        .def("world_moved", &TickRun::world_moved,
             "Read the plant's bases and gravity again after a world chart turned them in place.")
        .def("reference_step", &TickRun::reference_step, nb::arg("k"), nb::arg("act"), nb::arg("source"),
             nb::arg("qs"), nb::arg("qit"), nb::arg("qb"), nb::arg("sense_next"),
             "The reference path's entry per tick: act on tick k (with act), then sense tick k + 1 (with "
             "sense_next); (code, P changed).");
}

}  // namespace coopctrl::binding
