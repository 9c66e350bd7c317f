// The closed loop's tick by name, as MuJoCo's mjModel and mjData: what a run holds constant (TickModel, by concern:
// the run, the object, the guards, the sensors, the control, the QP, the switches) and what it writes (TickData: the
// loop state, the QP and its answer, the record, the stop report). coopctrl/loop/model.py and data.py name the same
// arrays on the Python side; coopctrl/core/bind_tick.cpp reads them there by name, once per run.
#pragma once

#include <cstdint>

#include "coopctrl/core/qp_constants.h"
#include "coopctrl/core/run_state.h"

namespace coopctrl {

/// Codes of a tick's stop (StopReport::code): the numbers of coopctrl/loop/kernel.py's constants of the same names.
enum TickCode : int64_t {
    TICK_DONE = 0,                     ///< every tick ran
    TICK_NONFINITE = 1,                ///< the state is not finite
    TICK_NEAR_SINGULARITY = 2,         ///< a node entered the Euler-angle band
    TICK_DEFORMATION = 3,              ///< a contact deformed beyond max_deformation (detail[0]: the contact)
    TICK_PLANT_ERROR = 4,              ///< the plant's terms failed (detail: its status); x_fail holds the state
    TICK_QP_FAILED = 5,                ///< the QP failed (detail: status or assembly code, iterations)
    TICK_NOMINAL_SINGULAR = 6,         ///< a nominal node pose at the Euler singularity (detail[0]: the node)
    TICK_SINGULAR_JACOBIAN = 7,        ///< a controller met a singular Jacobian (detail[0]: the arm)
    TICK_POSE_INCREMENT_SINGULAR = 8,  ///< a node's body-rate map is singular in the compliance map (the arm)
    TICK_CHUNK_END = 9,                ///< stopped at k_stop; resume at StopReport::tick
    TICK_NEWTON_FAILED = 10,           ///< an implicit step's Newton failed (detail: step, iterations)
    TICK_ENERGY = 11,                  ///< the total energy left max_energy (value[0]: the energy [J])
    TICK_PLANT_EXTERNAL = 13,          ///< recorded; the caller integrates over the period, resumes at tick
    TICK_STEP_TOO_SMALL = 14,          ///< an error-controlled step fell below its minimum (value: step, time [s])
    TICK_RECORDED = 15,                ///< the run's last tick is recorded (the plant not advanced past it)
    TICK_MEASUREMENT_NOT_FINITE = 16,  ///< a controller step's measured value is not finite (detail: field, arm, entry)
    TICK_LAW_FAILED = 17,              ///< a law given as a callback failed (detail[0]: the arm)
};

/// Where a tick's split comes from (coopctrl/loop/kernel.py's SPLIT_*).
enum SplitSource : int64_t {
    SPLIT_SOLVED = 0,  ///< the QP's answer (it becomes the last feasible split)
    SPLIT_HELD = 1,    ///< the last feasible split (a failed solve, after the failure policy)
    SPLIT_NONE = 2,    ///< zero wrenches (a passive run)
};

/// The node laws the core runs: a node's commanded acceleration a_cmd from its pose error err [m, rad] and its
/// reference and measured rates (coopctrl/controllers/leader_law.py).
enum NodeLawKind : int64_t {
    LAW_COMPUTED_TORQUE = 0,  ///< a = ddY_ref + Kd (dY_ref - dY) + Kp err, params (Kp [1/s^2], Kd [1/s])
    LAW_OBJECT_IMPEDANCE = 1, ///< M e'' + D e' + K e = 0, params (M_t, D_t, K_t, M_r, D_r, K_r)
    LAW_CALLBACK = 2,         ///< a function the caller gives (a law written in Python: the slower path)
};

/// A law the caller gives: call(context, err, dY_ref, dY, ddY_ref, p, npos, a_cmd) writes a_cmd (p) and returns
/// false where it failed (the caller keeps why).
struct LawCallback {
    bool (*call)(void* context, const double* err, const double* dY_ref, const double* dY, const double* ddY_ref,
                 int p, int npos, double* a_cmd) noexcept;
    void* context;
};

/// A node's law and its constants.
struct NodeLaw {
    NodeLawKind kind;
    const double* params;   ///< the law's constants (units as its kind says)
    int n_params;
    LawCallback callback;   ///< LAW_CALLBACK's function
};

/// The run: ticks, period, plant steps, the nominal motion.
struct RunModel {
    int64_t N;             ///< ticks to record
    int64_t k_base;        ///< the index of the run's first tick in the motion (tick k is at (k_base + k) T)
    double T;              ///< [s] the control period
    const double* steps;   ///< [s] the plant steps of one period
    int n_steps;
    const double* traj;    ///< (3, N, p): the nominal object pose, rate and acceleration per tick [m, rad, /s, /s^2]
};

/// The carried object and its grasps.
struct ObjectModel {
    double mass;           ///< [kg]
    double inertia[3];     ///< [kg m^2] principal (spatial), inertia[0] about y (planar)
    const double* grasps;  ///< (m, p) the contact nodes' offsets in the object frame [m, rad]
    const double* rho;     ///< (m, npos) the contact points in the object frame [m]
    const double* gravity; ///< (npos) [m/s^2]
};

/// The guards on the state.
struct GuardModel {
    double max_deformation;  ///< [m] a contact's largest offset from its grasp point
    double band;             ///< |cos theta| below which a node is in the Euler band (spatial)
};

/// The sensors' noise, drawn beforehand a row per tick (one row of zeros for a noise-free channel).
struct SensorModel {
    const double* joints;   ///< (rows_joints, 2 (nz - p)) joint angle and rate noise
    int64_t rows_joints;
    const double* object;   ///< (rows_object, 2 p) object pose and rate noise
    int64_t rows_object;
    const double* wrench;   ///< (rows_wrench, m p) contact wrench noise [N, N m]
    int64_t rows_wrench;
    bool noisy_state;       ///< the state is measured apart (a joint or object channel is noisy or quantized)
    double joint_step;      ///< [rad] quantization of the joint readings (0: none)
    double object_step;     ///< quantization of the object readings (0: none)
    double wrench_step;     ///< [N] quantization of the wrench readings (0: none)
};

/// The controllers: the leader's computed torque, the followers' force PI, the posture of a redundant arm.
struct ControlModel {
    int leader;                 ///< the leader arm's index
    double leader_Kp;           ///< [1/s^2]
    double leader_Kd;           ///< [1/s]
    double follower_kp;         ///< [-] force PI proportional gain
    double follower_ki;         ///< [1/s] force PI integral gain
    double follower_Kp;         ///< [1/s^2] the followers' motion loop
    double follower_Kd;         ///< [1/s]
    bool force_loop;            ///< the followers' force loop is closed
    double integral_limit;      ///< [N s] the integrals' clip
    double posture_gain[2];     ///< (Kp [1/s^2], Kd [1/s]) of the null-space posture torque
    const double* q_rest;       ///< (m, ld_q_rest) rest angles [rad]
    int ld_q_rest;
    const double* compliance;   ///< (m, p, p) the grasp compliances C_i [m/N, rad/(N m)]
    NodeLaw leader_law;         ///< the leader node's law toward its target
    NodeLaw follower_law;       ///< the followers' nodes' law toward theirs (computed torque: follower_Kp, _Kd)
};

/// The tuning probes (a run's switches and inputs beside the controllers).
struct ProbeModel {
    bool followers;               ///< the followers' probes are on
    const double* leader_offset;  ///< (p) [m, rad] added to the leader's target
    const double* offset;         ///< (m, p) the followers' setpoint offset [N, N m]
    const double* pi_output;      ///< (m, p) the followers' PI output added [N, N m]
    const double* gain;           ///< (m, p) [-] the error gain
    const int64_t* delay;         ///< (m, p) [ticks] the measurement delay
};

/// What a run switches on.
struct RunSwitches {
    bool passive;         ///< no QP, no controllers, zero torques; the energy recorded
    int energy;           ///< 0 off, 1 record it, 2 also guard max_energy
    double max_energy;    ///< [J]
    bool elastic_split;   ///< split = "elastic": the QP's cost from the grasp stiffness
    bool plant_outside;   ///< stop after each record with TICK_PLANT_EXTERNAL (an integrator outside the core)
};

/// The constants of one run, by concern.
struct TickModel {
    bool spatial;
    int m;        ///< arms
    int p;        ///< pose components per node (6 spatial, 3 planar)
    int npos;     ///< position components (3, 2)
    int nx;       ///< state size 2 nz
    int nu;       ///< joints of all arms
    const int64_t* arm_kind;  ///< (m) plants::ArmKind
    const int64_t* arm_dof;   ///< (m) joints per arm
    const int64_t* q_offset;  ///< (m) where each arm's joints start in z and tau
    RunModel run;
    ObjectModel object;
    GuardModel guards;
    SensorModel sensors;
    ControlModel control;
    QPConstants qp;
    ProbeModel probes;
    RunSwitches switches;
    const double* K_obj;  ///< (m, p, p) object-frame grasp stiffness (the elastic split) [N/m, N m/rad]
    const double* squeeze_desired;  ///< (pairs) the desired squeeze the recorded squeeze is relative to [N]
};

/// The rows a tick records (row k), by the record's names (coopctrl/loop/record.py).
struct TickRecord {
    double* t;              ///< (N) [s]
    double* x;              ///< (N, nx)
    double* tau;            ///< (N, nu) [N m]
    double* Y0_nominal;     ///< (N, p) [m, rad]
    double* F_measured;     ///< (N, m, p) [N, N m]
    double* F_commanded;    ///< (N, m, p)
    double* F_external;     ///< (N, m, p)
    double* F_internal;     ///< (N, m, p)
    double* r_contacts;     ///< (N, m, npos) [m]
    double* squeeze;        ///< (N, pairs) [N]
    int64_t* qp_status;     ///< (N)
    int64_t* qp_binding;    ///< (N) families mask
    int64_t* qp_iterations; ///< (N)
    int64_t* qp_active_rows;///< (N)
    double* energy;         ///< (N) [J] (passive runs)
    double* kinetic_energy; ///< (N) [J]
};

/// The QP a tick assembles and its answer (coopctrl/loop/data.py's QPArrays).
struct QPArrays {
    int n_rows;        ///< p + inequality rows
    double* M;         ///< (n_rows, n)
    double* lo;        ///< (n_rows)
    double* hi;        ///< (n_rows)
    double* H;         ///< (n, n)
    double* g;         ///< (n)
    double* x;         ///< (n) the answer F [N, N m]
    double* z;         ///< (n_rows) its multipliers
    double* external;  ///< (n) the external share [N, N m]
    double* F_pref;    ///< (n) the preferred split
    double* E;         ///< (n, ld_E) the squeeze basis
    int ld_E;
    double* A;         ///< (p, p) work
    double* y;         ///< (p) work
    double* K;         ///< (n, n) the elastic split's world-frame grasp stiffness of the last tick (H redone when it changes)
};

/// What a run reads and writes (the loop state's arrays are LoopState's, updated in place).
struct TickData {
    double* x;               ///< (nx) the plant state
    double* tau;             ///< (nu) the held torques [N m]
    double* integrals;       ///< (m, p) the followers' force-error integrals [N s]
    double* last_split;      ///< (3, m, p) the last feasible split (F, external, internal) [N, N m]
    LoopFlags* flags;
    int64_t* saturated_joints;  ///< (nu) saturated ticks per joint
    HoldState* hold;
    QPArrays qp;
    TickRecord record;
    double* x_good;          ///< (nx) the last state that passed the guards
    double* x_fail;          ///< (nx) the state a failure was met at
    StopReport* stop;
};

}  // namespace coopctrl
