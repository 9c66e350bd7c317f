// The closed loop's tick in coopctrl._core (coopctrl/core/tick.h): `Tick(model, data, plan, control)` reads a run's
// model and data by name once (coopctrl/loop/model.py's LoopModel, data.py's LoopData, the integration plan, the
// control model), then `run_ticks(k0, k_stop)` runs ticks and `reference_step(...)` serves the reference path.
// The arrays are the run's own: what the tick writes is in them.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <memory>
#include <string>
#include <vector>

#include "coopctrl/core/adaptive_plan_reader.h"
#include "coopctrl/core/array_reader.h"
#include "coopctrl/core/goldfarb_idnani.h"
#include "coopctrl/core/plan_reader.h"
#include "coopctrl/core/tick.h"
#include "coopctrl/core/tick_model.h"
#include "coopctrl/core/tick_plants.h"
#include "plants/core/planar_plant_reader.h"
#include "plants/core/spatial_plant_reader.h"

namespace coopctrl::binding {

namespace {

static_assert(sizeof(LoopFlags) == 7 * sizeof(int64_t), "LoopFlags is LoopState.flags, 7 int64");
static_assert(sizeof(HoldState) == 4 * sizeof(int64_t), "HoldState is LoopState.hold, 4 int64");
static_assert(sizeof(StopReport) == 8 * sizeof(int64_t), "StopReport is out_int, 8 int64");

template <class T>
T attr(nb::handle owner, const char* name) {
    return nb::cast<T>(owner.attr(name));
}

/// One run's tick: the model and data read by name, the plant, the plan and the QP workspace.
class TickRun {
public:
    TickRun(nb::object model, nb::object data, nb::object plan, nb::object control)
        : model_obj_(model), data_obj_(data), plan_obj_(plan), control_obj_(control) {
        read_model(model, control);
        read_data(data);
        read_plan(plan);
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
        nb::gil_scoped_release release;
        if (md_.spatial)
            spatial_tick_->run(k0, k_stop);
        else
            planar_tick_->run(k0, k_stop);
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
        return nb::make_tuple(code, P_changed);
    }

private:
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
        const double* obj = doubles(model, M, "obj", {md_.spatial ? 4 : 2});  // mass [kg], inertia [kg m^2]
        ob.mass = obj[0];
        for (int a = 0; a < (md_.spatial ? 3 : 1); ++a) ob.inertia[a] = obj[1 + a];
        ob.grasps = doubles(model, M, "grasps", {m, p});
        ob.rho = doubles(model, M, "rho", {m, npos});
        ob.gravity = doubles(P, "P", "gravity", {npos});
        md_.guards.max_deformation = attr<double>(model, "max_deformation");
        md_.guards.band = attr<double>(model, "band");
        // the sensors
        SensorModel& sn = md_.sensors;
        sn.rows_joints = extent(model, "noise_q", 0);
        sn.joints = doubles(model, M, "noise_q", {sn.rows_joints, 2 * (nz - p)});
        sn.rows_object = extent(model, "noise_o", 0);
        sn.object = doubles(model, M, "noise_o", {sn.rows_object, 2 * p});
        sn.rows_wrench = extent(model, "noise_f", 0);
        sn.wrench = doubles(model, M, "noise_f", {sn.rows_wrench, m * p});
        // noise_cfg = (joint std, joint step, object std, object step, wrench step)
        const double* cfg = doubles(model, M, "noise_cfg", {5});
        sn.noisy_state = cfg[0] != 0.0 || cfg[1] != 0.0 || cfg[2] != 0.0 || cfg[3] != 0.0;
        sn.joint_step = cfg[1];
        sn.object_step = cfg[3];
        sn.wrench_step = cfg[4];
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
        const std::string law = attr<std::string>(control, "law");
        if (law == "computed_torque")
            cm.law = LAW_COMPUTED_TORQUE;
        else if (law == "object_impedance")
            cm.law = LAW_OBJECT_IMPEDANCE;
        else
            throw nb::value_error(("control.law = '" + law + "': expected 'computed_torque' or 'object_impedance'")
                                      .c_str());
        cm.n_law_params = static_cast<int>(extent(control, "law_params", 0));
        cm.law_params = doubles(control, C, "law_params", {cm.law == LAW_COMPUTED_TORQUE ? 2 : 6});
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
        c.numbers = reinterpret_cast<const QPNumbers*>(doubles(qp, "qp", "numbers", {5}));
        c.rows = reinterpret_cast<const QPRows*>(ints(qp, "qp", "rows", {6}));
        // the switches and the probes (RunOptions, by name)
        nb::handle opts = model.attr("opts");
        const int64_t* switches = ints(opts, "opts", "switches", {ANY});  // coopctrl/loop/kernel.py's OPT_*
        RunSwitches& sw = md_.switches;
        sw.passive = switches[0] != 0;
        sw.energy = static_cast<int>(switches[1]);
        sw.elastic_split = switches[2] != 0;
        md_.probes.followers = switches[3] != 0;
        sw.plant_outside = switches[4] != 0;
        sw.max_energy = doubles(opts, "opts", "reals", {1})[0];
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
        d_.flags = reinterpret_cast<LoopFlags*>(ints(data, D, "flags", {7}));
        d_.saturated_joints = ints(data, D, "saturated_joints", {nu});
        d_.hold = reinterpret_cast<HoldState*>(ints(data, D, "hold", {4}));
        d_.x_good = doubles(data, D, "x_good", {nx});
        d_.x_fail = doubles(data, D, "x_fail", {nx});
        d_.stop = reinterpret_cast<StopReport*>(ints(data, D, "out_int", {8}));
        d_.stop_value = doubles(data, D, "out_float", {2});
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
        md_.squeeze_desired = doubles(data.attr("sq"), "data.sq", "desired", {pairs});
        nb::handle opts = model_obj_.attr("opts");
        rec.energy = doubles(opts, "opts", "energy", {ANY});
        rec.kinetic_energy = doubles(opts, "opts", "kinetic_energy", {ANY});
        if (md_.switches.passive || md_.switches.energy != 0)
            if (extent(opts, "energy", 0) < N || extent(opts, "kinetic_energy", 0) < N)
                throw nb::value_error("opts.energy, opts.kinetic_energy: expected at least N rows");
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
    nb::class_<TickRun>(m, "Tick",
                        "One run's closed-loop tick (coopctrl/core/tick.h) on its model, data, integration plan and "
                        "control model, read by name once; the run's arrays are written in place.")
        .def(nb::init<nb::object, nb::object, nb::object, nb::object>(), nb::arg("model"), nb::arg("data"),
             nb::arg("plan"), nb::arg("control"))
        .def("run_ticks", &TickRun::run_ticks, nb::arg("k0"), nb::arg("k_stop"),
             "Ticks k0 .. until N are recorded, an event, or tick k_stop; data.out_int says which.")
        .def("world_moved", &TickRun::world_moved,
             "Read the plant's bases and gravity again after a world chart turned them in place.")
        .def("reference_step", &TickRun::reference_step, nb::arg("k"), nb::arg("act"), nb::arg("source"),
             nb::arg("qs"), nb::arg("qit"), nb::arg("qb"), nb::arg("sense_next"),
             "The reference path's entry per tick: act on tick k (with act), then sense tick k + 1 (with "
             "sense_next); (code, P changed).");
}

}  // namespace coopctrl::binding
