"""The compiled closed loop: one numba function advances the loop tick after tick.

:func:`run_ticks` runs ticks ``k0 .. N-1`` of the loop of :mod:`coopctrl.closed_loop` on the
arrays of a :class:`~coopctrl.loop.state.LoopState` and writes the record rows in place. One tick:

1. **sensors**: the plant's control terms at the true state (contact wrenches ``F_meas``, the
   guards) and, when a channel is noisy, at the measured state ``x + noise`` (quantised); the
   noise is drawn beforehand from the scenario's seeded generators, in the order the Python
   sensors draw it, and passed in (``noise_q``, ``noise_o``, ``noise_f``);
2. **guards**: a non-finite state, a node within the Euler-angle band (spatial), a contact
   deformation beyond ``max_deformation``;
3. **nominal motion and load**: the trajectory sample (``traj``), the nodes carried rigidly by the
   object (148) and the external load ``w_N``;
4. **QP**: its inputs from the measured terms (the contact normals and the torque-limit model of
   :mod:`coopctrl.load_distribution.contact_model`), the rows of
   :mod:`coopctrl.load_distribution.assembly` and the compiled Goldfarb-Idnani solve, warm started;
   the answer check of :class:`~coopctrl.load_distribution.LoadDistribution`;
5. **controllers**: the leader's computed torque on its nominal deformed node, the followers'
   force PI (integral clipped at ``integral_limit``), the null-space posture torque of a
   redundant arm;
6. **saturation** at ``tau_max``;
7. **plant**: zero-order hold over the period, one integrator step per entry of ``steps``
   (:func:`coopctrl.integrators.compiled.zoh_advance` with the run's plan ``method``: an
   ``ExplicitPlan`` for euler, symplectic Euler and RK4, an ``ImplicitPlan`` for implicit
   midpoint and implicit Euler, their Newton iteration included), each the arithmetic of the
   Python integrator.

A tick allocates nothing: every work array is made once per call, before the tick loop, and the
small solves run in the ``*_into`` kernels of :mod:`coopctrl.controllers._kernels` and
:mod:`plants.cooperative.loaded_state` (``tests/test_loop_kernel.py`` counts numba's allocations).

It returns when the run ends or an event stops it, with ``out_int = (code, tick, ...)``: the
caller (:mod:`coopctrl.loop.compiled`) raises the exception that names the stop and runs the
diagnosis in Python; a failed QP solve (:data:`QP_FAILED`) returns *before* the controllers
of its tick, so the caller can apply the failure policy and resume at the same tick with
``hold = 1`` (the last feasible split).

A tick is two phases, as MuJoCo's ``mj_step1`` and ``mj_step2``: :func:`tick_sense` senses, guards and
assembles the QP of the split (steps 1 to 4 but the solve); :func:`tick_act` takes the split and runs the
controllers, the saturation, the record and the plant (steps 5 to 7). :func:`run_ticks` calls the two
with the compiled solve between them (both are inlined into it). The reference path (another QP backend)
solves in Python between them: :func:`reference_step` runs phase 2 of a tick and phase 1 of the next, so
that path enters the kernel once per tick; the same tick, no re-entry.

The parts of the tick that make the torques are stages of their own, which the tick's phases call:
:func:`nominal_load` (step 3), :func:`assemble_split` and :func:`solve_split` (step 4), :func:`control_torques`
(steps 5 and 6). :func:`coopctrl.loop.controller_step.controller_step` calls the same stages, in the same
order, on a measurement given from outside instead of the plant's state (``coopctrl.Controller``): one source
for the loop and the controller's step.

The same tick serves every configuration (``opts``): a passive run (no QP, no controllers, zero
torques, the energy recorded), the ``max_energy`` guard (:data:`ENERGY`), the elastic split, the
tuning probes' signals; an integrator the kernel lacks stops after each tick's record
(:data:`PLANT_EXTERNAL`) for the caller to step the plant.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from coopctrl.controllers._kernels import WORK_MATRICES, WORK_VECTORS
from coopctrl.controllers.laws import (arm_torque_into, follower_acceleration_into, follower_correction_into,
                                       leader_target_into, pose_error_into, pose_increment_into)
from coopctrl.load_distribution.answer_check import (FAMILY_FRICTION, FAMILY_MIN_GRIP, FAMILY_TORQUE, answer_ok,
                                                     binding_families)
from coopctrl.load_distribution.assembly import (
    fill_friction_rows,
    fill_grasp_rows,
    fill_grip_rows,
    fill_squeeze_basis,
    fill_torque_rows,
    pseudo_inverse_external,
)
from coopctrl.load_distribution.contact_model import contact_normals_into, torque_model_into
from coopctrl.load_distribution.elastic_assembly import fill_elastic_split
from coopctrl.load_distribution.goldfarb_idnani import gi_active_inequalities, gi_solve
from coopctrl.integrators.adaptive_plans import (EmbeddedPlan, TRBDF2Plan, embedded_advance, embedded_plan_of,
                                                 trbdf2_advance, trbdf2_plan_of)
from coopctrl.integrators.compiled import (STEP_NEWTON_FAILED, STEP_OK, ExplicitPlan, ImplicitPlan, explicit_period,
                                           explicit_plan_of, implicit_period, implicit_plan_of, plan_slots)
from coopctrl.integrators.compiled import STEP_TOO_SMALL as STEP_TOO_SMALL_CODE
from coopctrl.loop.squeeze import pair_squeeze_into
from coopctrl.loop.stages import TickStages, compile_stage
from coopctrl.loop.energy import plant_energy
from plants.cooperative import _planar_kernel as _pk
from plants.cooperative import _spatial_kernel as _sk
from plants.cooperative.loaded_state import body_rates_into, planar_motion_into, spatial_motion_into
from plants.cooperative.plant_args import is_spatial
from plants.frames import rotation_zyx_into

# numba keys a cached function on its own file; the cache directory is keyed on every kernel source
# (plants.numba_cache), so a change to a kernel this file calls from another file recompiles this one too.

#: Codes of ``out_int[0]``.
DONE = 0            #: every tick ran
NONFINITE = 1       #: the state is not finite (``DivergenceError`` "state (non-finite)")
NEAR_SINGULARITY = 2  #: a node entered the Euler-angle band
DEFORMATION = 3     #: a contact deformed beyond ``max_deformation`` (``out_int[2]`` = contact)
PLANT_ERROR = 4     #: the plant kernel failed (``out_int[2:4]`` = its status); ``x_fail`` holds the state
QP_FAILED = 5       #: the QP answer failed its check (``out_int[2]`` = status, ``[3]`` iterations, ``[4]`` violated families)
NOMINAL_SINGULAR = 6  #: a nominal node pose is at the Euler singularity (``out_int[2]`` = node)
SINGULAR_JACOBIAN = 7  #: a controller met a singular Jacobian (``out_int[2]`` = arm)
POSE_INCREMENT_SINGULAR = 8  #: a node's body-rate map is singular in the compliance map (``out_int[2]`` = arm)
CHUNK_END = 9       #: stopped at ``k_stop`` (progress reporting); resume at ``out_int[1]``
NEWTON_FAILED = 10  #: an implicit step's Newton failed (``out_int[2:4]`` = step, iterations; ``out_float`` = correction, time)
ENERGY = 11         #: the total energy left ``max_energy`` (``out_float[0]`` = the energy [J])
PLANT_EXTERNAL = 13  #: tick ``out_int[1] - 1`` is recorded and its torques are in ``tau``: the caller integrates
                     #: ``x`` over the period and resumes at tick ``out_int[1]``
STEP_TOO_SMALL = 14  #: an error-controlled step fell below ``min_step`` (``out_float`` = step [s], time [s];
                     #: ``x_fail`` the state)
RECORDED = 15       #: :func:`tick_act`: the run's last tick is recorded (the plant is not advanced past it)

#: Where :func:`tick_act` takes the split from.
SPLIT_SOLVED = 0    #: the QP's answer, in ``x`` of ``qp_arrays`` (it becomes the last feasible split)
SPLIT_HELD = 1      #: the last feasible split (a failed solve, after the failure policy)
SPLIT_NONE = 2      #: none: a passive run (zero wrenches, no controllers)

#: Entries of ``opts.switches`` (int64 switches of a run).
OPT_PASSIVE = 0     #: no QP, no controllers, zero torques; energy recorded
OPT_ENERGY = 1      #: evaluate the energy each tick (1: record it, 2: also guard ``max_energy``)
OPT_ELASTIC = 2     #: ``split = "elastic"``: ``A_K`` and ``P = K^-1`` from the grasp stiffness
OPT_PROBES = 3      #: the followers' tuning probes (setpoint offset, PI output, error gain, delay)
OPT_EXTERNAL_PLANT = 4  #: stop after each tick's record with :data:`PLANT_EXTERNAL` (an integrator outside the kernel)


# The bits of the QP family masks (the record's ``qp_binding``), FAMILY_MIN_GRIP, FAMILY_FRICTION and
# FAMILY_TORQUE, are imported above from the answer check (coopctrl.load_distribution.answer_check).


def _terms(x, P, status, cws):
    """Fill the control workspace ``cws`` with the terms at ``x`` (:func:`_term_arrays`: ``(Y, dY, H, h,
    J, Jdq, W, w_free, S, Fw)``): the kernel form of ``CooperativePlant.control_terms``
    (``control_terms_into``); returns ``status[0]``, nonzero at a singularity. Compiled per kind (spatial or planar) by the type of ``P``'s
    bases, as :func:`coopctrl.integrators.compiled.rhs_into`."""
    raise NotImplementedError("called from numba only")


@overload(_terms)
def _terms_typed(x, P, status, cws):
    # the packed entry point (see coopctrl.integrators.compiled.rhs_into)
    terms_into = _sk.control_terms_packed if is_spatial(P) else _pk.control_terms_packed

    def impl(x, P, status, cws):
        status[0] = 0
        terms_into(x, P, status, cws)
        return status[0]
    return impl


def _terms_stage(x, P, status, cws):
    return _terms(x, P, status, cws)


@njit(inline="always", _nrt=False)
def _term_arrays(cws):
    """The arrays of the control workspace ``cws`` that :func:`_terms` fills: ``(Y, dY, H, h, J, Jdq, W,
    w_free, S, Fw)``."""
    return cws.ws.Y, cws.ws.dY, cws.ws.H, cws.ws.h, cws.ws.J, cws.ws.Jdq, cws.W, cws.w_free, cws.S, cws.Fw


# The plant's period advance, one stage per integrator family: each takes the plan in its slots (the same type
# for every family: run_ticks is compiled once for them all), rebuilds its family's plan from them and calls
# that family's branch of zoh_advance itself (the fixed-step schemes are copied into the stage, not compiled
# on their own: coopctrl.integrators.compiled).
def _advance_explicit_stage(slots, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    return explicit_period(explicit_plan_of(slots), x, tau, P, status, ws, terms, t, steps, x_fail, out_int)


def _advance_implicit_stage(slots, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    return implicit_period(implicit_plan_of(slots), x, tau, P, status, ws, t, steps, x_fail, out_int, out_float)


def _advance_embedded_stage(slots, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    return embedded_advance(embedded_plan_of(slots), x, tau, P, status, ws, terms, t, x_fail, out_int, out_float)


def _advance_trbdf2_stage(slots, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    return trbdf2_advance(trbdf2_plan_of(slots), x, tau, P, status, ws, terms, t, x_fail, out_int, out_float)


#: The plan families whose advance may allocate (the Newton matrix's ``pinv`` fallback): their stage is compiled
#: with numba's runtime.
NEWTON_PLANS = (ImplicitPlan, TRBDF2Plan)

#: The advance stage of each plan family (the class of the plan :func:`~coopctrl.integrators.compiled.make_plan` made).
ADVANCE_STAGES = {ExplicitPlan: _advance_explicit_stage, ImplicitPlan: _advance_implicit_stage,
                  EmbeddedPlan: _advance_embedded_stage, TRBDF2Plan: _advance_trbdf2_stage}


def _elastic_stage(M, k, K_obj, Y0, spatial, K, P, w, external, KGt, A, y, Rb, work):
    return fill_elastic_split(M, k, K_obj, Y0, spatial, K, P, w, external, KGt, A, y, Rb, work)


def _no_elastic_stage(M, k, K_obj, Y0, spatial, K, P, w, external, KGt, A, y, Rb, work):
    return 0, False


def _energy_stage(x, P, cws, F, dY0):
    return plant_energy(x, P, cws, F, dY0)


def _no_energy_stage(x, P, cws, F, dY0):
    return 0.0, 0.0, 0


@njit(cache=True)
def required_wrench(spatial, mass, inertia, gravity, Y0, dY0, ddY0, out, v, R):
    """``w_N`` of :func:`coopctrl.controllers.required_object_wrench`, written into ``out``; ``v``
    (8, 3) and ``R`` (3, 3) scratch."""
    if not spatial:
        out[0] = mass * (ddY0[0] - gravity[0])
        out[1] = mass * (ddY0[1] - gravity[1])
        out[2] = inertia[0] * ddY0[2]
        return
    w, dw, tb = v[0], v[1], v[2]
    A = Y0[3:]
    body_rates_into(A, dY0[3:], ddY0[3:], w, dw)
    Iw0, Iw1, Iw2 = inertia[0] * w[0], inertia[1] * w[1], inertia[2] * w[2]
    tb[0] = inertia[0] * dw[0] + (w[1] * Iw2 - w[2] * Iw1)
    tb[1] = inertia[1] * dw[1] + (w[2] * Iw0 - w[0] * Iw2)
    tb[2] = inertia[2] * dw[2] + (w[0] * Iw1 - w[1] * Iw0)
    rotation_zyx_into(A, R)
    for a in range(3):
        out[a] = mass * (ddY0[a] - gravity[a])
        out[3 + a] = R[a, 0] * tb[0] + R[a, 1] * tb[1] + R[a, 2] * tb[2]


@njit(cache=True, _nrt=False)
def _guards(spatial, x, Y, rho, band, max_deformation, R3, d):
    """Stage of a tick: the guards on the state (non-finite, Euler band, deformation); ``(code, contact, deformation)``."""
    m = rho.shape[0]
    Nn = m + 1
    nx = x.shape[0]
    npos = 3 if spatial else 2
    finite = True
    for c in range(nx):
        if not math.isfinite(x[c]):
            finite = False
            break
    if not finite:
        return NONFINITE, 0, 0.0
    if spatial:
        cmin = 2.0
        for j in range(Nn):
            c = abs(math.cos(Y[j, 4]))
            if c < cmin:
                cmin = c
        if cmin < band:
            return NEAR_SINGULARITY, 0, 0.0
    worst = 0.0
    which = 0
    R0 = R3[0]
    if spatial:
        rotation_zyx_into(Y[0, 3:6], R0)
    for i in range(m):
        if spatial:
            for a in range(3):
                s = 0.0
                for b in range(3):
                    s += R0[b, a] * (Y[i + 1, b] - Y[0, b])
                d[a] = s - rho[i, a]
        else:
            c0, s0 = math.cos(Y[0, 2]), math.sin(Y[0, 2])
            e0, e1 = Y[i + 1, 0] - Y[0, 0], Y[i + 1, 1] - Y[0, 1]
            d[0] = c0 * e0 + s0 * e1 - rho[i, 0]
            d[1] = -s0 * e0 + c0 * e1 - rho[i, 1]
        s = 0.0
        for a in range(npos):
            s += d[a] * d[a]
        v = math.sqrt(s)
        if not v <= worst:
            worst = v
            which = i
    if worst > max_deformation:
        return DEFORMATION, which, worst
    return DONE, 0, 0.0


def _qp_rows(spatial, Ym, Y0N, wN, ddYn, Wm, wm_free, Hm, hm, Jm, Jdqm, arm_kind, arm_dof, qp, qp_arrays, opts, rc, r0, nrm, Jg, bias, Wa, rhs_t, qdd, piv, wv, wm, R3, elastic_split):
    """Stage of a tick: the QP of the split (equality rows, ``P``, ``g``, the grip, friction and torque rows)
    into ``qp_arrays``, from the measured terms (``Ym`` .. ``Jdqm``) and the nominal node accelerations
    ``ddYn``: the normals ``nrm`` and the torque model ``(Jg, bias)`` of
    :mod:`coopctrl.load_distribution.contact_model`, the rows of :mod:`coopctrl.load_distribution.assembly`;
    ``(code, P changed)``, ``code`` 0 or the failure detail of :data:`QP_FAILED`. ``elastic_split``: the
    elastic split's stage (:func:`tick_stages`), called when ``opts`` select it."""
    m = arm_kind.shape[0]
    p = 6 if spatial else 3
    npos = 3 if spatial else 2
    W_diag, W_inv_diag, s_des, tau_qp = qp.W_diag, qp.W_inv_diag, qp.s_des, qp.tau_qp
    cos_phi, sin_phi, qp_num, qp_int = qp.cos_phi, qp.sin_phi, qp.numbers, qp.rows
    mu_c = qp_num[1]
    has_squeeze = qp_int[0] != 0
    row_grip, row_fric, row_tau, n_fric = qp_int[1], qp_int[2], qp_int[3], qp_int[4]
    torque_limits = row_tau >= 0
    need_normals = row_grip >= 0 or row_fric >= 0
    Mq, lo, hi, Hq, gq = qp_arrays.M, qp_arrays.lo, qp_arrays.hi, qp_arrays.H, qp_arrays.g
    external, Fpref, Ework, Ak, yk = qp_arrays.external, qp_arrays.F_pref, qp_arrays.E, qp_arrays.A, qp_arrays.y
    switches, K_obj = opts.switches, opts.K_obj
    Kw, KGt, Rb, ework = opts.elastic_K, opts.elastic_KGt, opts.elastic_Rb, opts.elastic_work
    elastic = switches[OPT_ELASTIC] != 0
    for a in range(p):
        lo[a] = wN[a]
        hi[a] = wN[a]
    for i in range(m):
        for a in range(npos):
            rc[i, a] = Ym[i + 1, a]
    for a in range(npos):
        r0[a] = Ym[0, a]
    fill_grasp_rows(Mq, rc, r0, spatial)
    P_changed = False
    if elastic:
        ecode, P_changed = elastic_split(Mq, p, K_obj, Y0N, spatial, Kw, Hq, wN, external, KGt, Ak, yk, Rb, ework)
        if ecode != 0:
            return ecode, False  # -1 degenerate grasp, -3 singular grasp stiffness
    elif not pseudo_inverse_external(Mq, p, W_inv_diag, wN, external, Ak, yk):
        return -1, False  # degenerate grasp (ScenarioError in the Python problem)
    n = W_diag.shape[0]
    if has_squeeze:
        if not fill_squeeze_basis(Ework, rc, p):
            return -2, False
        for c in range(n):
            s = 0.0
            for e in range(s_des.shape[0]):
                s += Ework[c, e] * s_des[e]
            Fpref[c] = external[c] + s
    else:
        for c in range(n):
            Fpref[c] = external[c]
    if elastic:  # g = -P F_pref
        for c in range(n):
            s = 0.0
            for e in range(n):
                s += Hq[c, e] * Fpref[e]
            gq[c] = -s
    else:
        for c in range(n):
            gq[c] = -W_diag[c] * Fpref[c]
    if need_normals:
        contact_normals_into(Ym, spatial, nrm, R3[0])
        if row_grip >= 0:
            fill_grip_rows(Mq, p + row_grip, nrm, p)
        if row_fric >= 0:
            fill_friction_rows(Mq, p + row_fric, nrm, p, n_fric, mu_c, cos_phi, sin_phi, spatial)
    if torque_limits:
        torque_model_into(spatial, Ym, ddYn, Wm, wm_free, Hm, hm, Jm, Jdqm, arm_kind, arm_dof, Jg, bias, Wa, rhs_t, qdd, piv,
                          wv, wm, R3)
        fill_torque_rows(Mq, lo, hi, p + row_tau, Jg, arm_dof, p, tau_qp, bias)
    return 0, P_changed


def _qp_answer(Hq, gq, Mq, lo, hi, xq, zq, ws, P_changed, flags, p, m, n, n_in, eps_abs, max_iter, answer_rho, row_grip, row_fric, row_tau, n_fric):
    """Stage of a tick: the warm-started solve, its answer check and the binding families;
    ``(status, iterations, ok, families)``."""
    first = flags[3] == 0
    code, qit = gi_solve(Hq, gq, Mq, lo, hi, p, xq, zq, ws, first or P_changed, eps_abs, max_iter)
    flags[3] += 1
    qs = code
    okqp = code == 0 and answer_ok(Mq, lo, hi, xq, n, p, eps_abs, answer_rho)
    if not okqp:
        return code, qit, False, 0
    flags[1] = 0
    qb = binding_families(gq, zq, p, n, n_in, m, row_grip, row_fric, n_fric, row_tau)
    return code, qit, True, qb


def _control(spatial, passive, ctrl, posture, C_comp, arm_kind, arm_dof, q_off, T, F_set, F_cmd, F_seen, Y0N, Yn, dYn, ddYn, Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, zx, lead_off, integ, tau, R3, pv, inc, Yv, err, a_cmd, corr, tp, wv, wm, piv, ti, leader_law, law_params):
    """Stage of a tick: the leader's and the followers' controllers into ``tau`` (before saturation);
    ``(code, arm)``, ``code`` :data:`DONE` or the event. The leader's node acceleration is its law's
    (``leader_law`` with its constants ``law_params``, :mod:`coopctrl.controllers.leader_law`: the
    computed torque with the leader's gains unless the user gave another), from the pose error to its
    target."""
    m = arm_kind.shape[0]
    p = 6 if spatial else 3
    npos = 3 if spatial else 2
    nz = zx.shape[0] // 2
    post_gain, q_rest = posture
    leader = int(ctrl[0])
    Kp_l, Kd_l = ctrl[1], ctrl[2]
    kp_f, ki_f, Kp_f, Kd_f = ctrl[3], ctrl[4], ctrl[5], ctrl[6]
    force_loop = ctrl[7] != 0.0
    integral_limit = ctrl[8]
    kl = leader + 1
    okp = pose_increment_into(spatial, C_comp[leader], F_set[leader], Y0N, Yn[kl], R3, pv, inc)
    if not okp:
        return POSE_INCREMENT_SINGULAR, leader
    for i in range(0 if passive else m):  # a passive run keeps tau = 0
        ki = i + 1
        ni = arm_dof[i]
        o = q_off[i]
        if i == leader:
            leader_target_into(Yn[kl], inc, lead_off, Yv)
            pose_error_into(Yv, Ym[kl], npos, err)
            leader_law(err, dYn[kl], dYm[kl], ddYn[kl], npos, law_params, a_cmd)
        else:
            follower_correction_into(F_cmd[i], F_seen[i], integ[i], T, kp_f, ki_f, integral_limit, force_loop, corr)
            if not follower_acceleration_into(spatial, C_comp[i], corr, Y0N, Yn[ki], Ym[ki], dYn[ki], dYm[ki], ddYn[ki],
                                              Kp_f, Kd_f, npos, R3, pv, Yv, err, a_cmd):
                return POSE_INCREMENT_SINGULAR, i
        okt = arm_torque_into(arm_kind[i] != 0, ni, Wm[ki], wm_free[ki], Sm[ki], Hm[i], hm[i], Jm[i], Jdqm[i], a_cmd,
                              zx[o:o + ni], zx[nz + o:nz + o + ni], q_rest[i], post_gain, wv, wm, piv, tp, ti)
        if not okt:
            return SINGULAR_JACOBIAN, i
        for c in range(ni):
            tau[o + c] = ti[c]
    return DONE, 0


@njit(inline="always", _nrt=False)
def _copy(dst, src):
    """``dst[:] = src`` as a loop (the slice assignment needs numba's reference counting)."""
    for c in range(src.shape[0]):
        dst[c] = src[c]


@njit(inline="always", _nrt=False)
def _plant_failed(status, y, x_fail, out_int):
    """The event of the plant's terms failing at the state ``y`` (``status``: its code) into ``out_int``, ``y``
    kept in ``x_fail``; returns :data:`PLANT_ERROR`."""
    out_int[0] = PLANT_ERROR
    out_int[2] = status[0]
    out_int[3] = status[1]
    _copy(x_fail, y)
    return PLANT_ERROR


@njit(inline="always", _nrt=False)
def _step_failed(step_code, status, out_int):
    """The event of a plant advance that returned ``step_code`` (not ``STEP_OK``) into ``out_int``; returns it:
    :data:`NEWTON_FAILED`, :data:`STEP_TOO_SMALL`, or :data:`PLANT_ERROR` with the plant's ``status``."""
    if step_code == STEP_NEWTON_FAILED:
        out_int[0] = NEWTON_FAILED
    elif step_code == STEP_TOO_SMALL_CODE:
        out_int[0] = STEP_TOO_SMALL
    else:
        out_int[0] = PLANT_ERROR
        out_int[2] = status[0]
        out_int[3] = status[1]
    return out_int[0]


#: The tick's work arrays (:func:`tick_workspace`), by the names :func:`run_ticks` and its stages use.
TickWorkspace = namedtuple("TickWorkspace", "F_cmd F_seen status xm Fm F_set wN nrm Jg bias a_cmd err d Yn dYn ddYn R3 v3 pv rc r0 Wa rhs_t qdd piv wv wm inc corr Yv tp ti obj_inertia")


def tick_workspace(spatial: bool, m: int, nx: int, nu: int, arm_dof) -> TickWorkspace:
    """Every work array of :func:`run_ticks`'s tick, made once per run (``tw``): the kernel itself
    allocates nothing, so it runs without numba's reference counting (``_nrt=False``: no atomic count
    per array use, and a smaller function for LLVM to optimize). ``m`` arms, ``nx`` states, ``nu``
    joints, ``arm_dof`` the joints per arm. Entries that must start at zero are zeros; the others are
    written before they are read in every tick."""
    p, npos = (6, 3) if spatial else (3, 2)
    nmax = max(p, *(int(n) for n in arm_dof))
    e = np.empty
    return TickWorkspace(
        F_cmd=e((m, p)), F_seen=e((m, p)), status=np.zeros(2, np.int64), xm=e(nx), Fm=e((m, p)), F_set=e((m, p)),
        wN=e(p), nrm=e((m, npos)), Jg=np.zeros((m, p, nmax)), bias=np.zeros(nu), a_cmd=e(p), err=e(p), d=e(npos),
        Yn=e((m + 1, p)), dYn=e((m + 1, p)), ddYn=e((m + 1, p)), R3=e((4, 3, 3)), v3=e((8, 3)), pv=e((3, 6)),
        rc=e((m, npos)), r0=e(npos), Wa=e(p), rhs_t=e(p), qdd=e(nmax), piv=e(nmax, np.int64),
        wv=e((WORK_VECTORS, nmax)), wm=e((WORK_MATRICES, nmax, nmax)), inc=e(p), corr=e(p), Yv=e(p), tp=e(nmax),
        ti=e(nmax), obj_inertia=e(3 if spatial else 1))  # the object's inertia, set once per run (run_compiled)


def leader_law_stage(law, p: int):
    """The leader law ``law`` (:class:`~coopctrl.controllers.leader_law.LeaderLaw`) compiled for the tick
    (:func:`~coopctrl.loop.stages.compile_stage`: a ``cfunc`` kept in numba's cache) with its constants
    as a float array: ``(stage, params)``. Its argument types are the tick's (``p`` pose components)."""
    f64v = np.zeros(p)
    stage = compile_stage(law.function, types.void, f64v, f64v, f64v, f64v, types.int64, law.param_array, f64v)
    return stage, law.param_array


def tick_stages(spatial: bool, plan, P, plant_ws, steps, traj, qp, qp_arrays, opts, ws, tw, ctrl, posture, C_comp, x,
                tau, integ, flags, x_fail, out_int, out_float, types_only: bool = False) -> tuple:
    """The stages :func:`run_ticks` calls through their addresses (its ``stages``), compiled for the
    types of the run's arrays (the arguments of :func:`run_ticks` of the same names) by
    :func:`coopctrl.loop.stages.compile_stage`: ``(advance, terms, qp_rows, qp_answer, control,
    energy, elastic)``, the plant's period advance (:func:`coopctrl.integrators.compiled.zoh_advance`),
    :func:`_terms`, :func:`_qp_rows`, :func:`_qp_answer`, :func:`_control`, the plant's energy
    (:func:`coopctrl.loop.energy.plant_energy`) and the elastic split's inputs
    (:func:`coopctrl.load_distribution.elastic_assembly.fill_elastic_split`, which ``_qp_rows`` calls
    through the pointer it is given). A run that evaluates no energy, or splits the load by the
    pseudo-inverse, gets a stage with the same signature that does nothing: those are compiled only
    for the runs that use them. With ``types_only`` nothing is compiled: each stage is its numba type as an
    argument of :func:`run_ticks` (:func:`~coopctrl.loop.stages.compile_stage`), which is all that compiling
    :func:`run_ticks` needs (:mod:`coopctrl.loop.compile_ahead`)."""
    i64, f64, b1 = types.int64, types.float64, types.boolean
    t = types_only
    pws, cws, _ = plant_ws
    Y, dY, H, h, J, Jdq, W, w_free, S = (cws.ws.Y, cws.ws.dY, cws.ws.H, cws.ws.h, cws.ws.J, cws.ws.Jdq, cws.W, cws.w_free,
                                         cws.S)
    arm_kind, arm_dof, q_off = P.arm_kind, P.arm_dof, P.q_off
    Y0N = tw.wN  # (p,) float64, the type of a row of traj (which has none in a run of no tick)
    Mq, lo, hi, Hq, gq, xq, zq = (qp_arrays.M, qp_arrays.lo, qp_arrays.hi, qp_arrays.H, qp_arrays.g, qp_arrays.x,
                                  qp_arrays.z)
    switches, eF, eDY0 = opts.switches, opts.energy_F, opts.energy_dY0
    lead_off, leader_law, law_params = opts.leader_offset, opts.leader_law, opts.law_params
    # the plant's period advance; with numba's runtime only where a scheme may allocate (the Newton schemes'
    # pinv fallback): the runtime's reference counts cost the explicit schemes about 1.2 us a tick on the carry
    # (``plan`` is the family's plan, which picks the stage; the stage takes it in its slots, as run_ticks holds it)
    advance = compile_stage(ADVANCE_STAGES[type(plan)], i64, plan_slots(plan), x, tau, P, tw.status, pws, cws, f64,
                            steps, x_fail, out_int, out_float, runtime=type(plan) in NEWTON_PLANS, types_only=t)
    terms = compile_stage(_terms_stage, i64, x, P, tw.status, cws, types_only=t)
    K_obj, Kw, KGt, Rb, ework = opts.K_obj, opts.elastic_K, opts.elastic_KGt, opts.elastic_Rb, opts.elastic_work
    external, Ak, yk = qp_arrays.external, qp_arrays.A, qp_arrays.y
    elastic = compile_stage(_elastic_stage if switches[OPT_ELASTIC] != 0 else _no_elastic_stage, types.Tuple((i64, b1)),
                            Mq, i64, K_obj, Y0N, b1, Kw, Hq, tw.wN, external, KGt, Ak, yk, Rb, ework, types_only=t)
    qp_rows = compile_stage(_qp_rows, types.Tuple((i64, b1)), b1, Y, Y0N, tw.wN, tw.ddYn, W, w_free, H, h, J, Jdq,
                            arm_kind, arm_dof, qp, qp_arrays, opts, tw.rc, tw.r0, tw.nrm, tw.Jg, tw.bias, tw.Wa, tw.rhs_t,
                            tw.qdd, tw.piv, tw.wv, tw.wm, tw.R3, elastic, types_only=t)
    qp_answer = compile_stage(_qp_answer, types.Tuple((i64, i64, b1, i64)), Hq, gq, Mq, lo, hi, xq, zq, ws, b1, flags,
                              i64, i64, i64, i64, f64, i64, f64, i64, i64, i64, i64, types_only=t)
    control = compile_stage(_control, types.UniTuple(i64, 2), b1, b1, ctrl, posture, C_comp, arm_kind, arm_dof, q_off,
                            f64, tw.F_set, tw.F_cmd, tw.F_seen, Y0N, tw.Yn, tw.dYn, tw.ddYn, Y, dY, H, h, J, Jdq, W, w_free,
                            S, x, lead_off, integ, tau, tw.R3, tw.pv, tw.inc, tw.Yv, tw.err, tw.a_cmd, tw.corr, tw.tp, tw.wv,
                            tw.wm, tw.piv, tw.ti, leader_law, law_params, types_only=t)
    energy = compile_stage(_energy_stage if switches[OPT_ENERGY] != 0 else _no_energy_stage, types.Tuple((f64, f64, i64)),
                           x, P, cws, eF, eDY0, types_only=t)
    return TickStages(advance=advance, terms=terms, qp_rows=qp_rows, qp_answer=qp_answer, control=control,
                      energy=energy, elastic_split=elastic)


@njit(cache=True, inline="always", _nrt=False)
def tick_sense(k, assemble, model, data):
    """Phase 1 of tick ``k`` of the run ``model``, ``data`` (:class:`~coopctrl.loop.model.LoopModel`, :class:`~coopctrl.loop.data.LoopData`): the sensors (the true control terms, the
    measured state and wrenches with their noise), the guards on the state, the energy, the nominal motion of
    the nodes and the object's required wrench ``w_N``, and with ``assemble`` the QP of the split in
    ``qp_arrays`` from the measured terms. Returns ``(code, P changed)``: :data:`DONE`, or the event (also in
    ``out_int[0]``, its details as :func:`run_ticks` says) and False. The split is then solved (the compiled
    solver in :func:`run_ticks`, or the reference path's backend from Python) and :func:`tick_act` finishes
    the tick."""
    spatial, P, rho = model.spatial, model.P, model.rho
    band, max_deformation, opts, stages = model.band, model.max_deformation, model.opts, model.stages
    noise_q, noise_o, noise_f, noise_cfg = model.noise_q, model.noise_o, model.noise_f, model.noise_cfg
    x, plant_ws, tw = data.x, data.plant_ws, data.tw
    x_good, x_fail, out_int, out_float = data.x_good, data.x_fail, data.out_int, data.out_float
    m = P.arm_kind.shape[0]
    p = 6 if spatial else 3
    nx = x.shape[0]
    nz = nx // 2
    switches, reals, eF, eDY0 = opts.switches, opts.reals, opts.energy_F, opts.energy_dY0
    rec_E, rec_KE = opts.energy, opts.kinetic_energy
    passive = switches[OPT_PASSIVE] != 0
    energy_on = switches[OPT_ENERGY] != 0
    energy_guard = switches[OPT_ENERGY] == 2
    max_energy = reals[0]
    noisy_state = noise_cfg[0] != 0.0 or noise_cfg[1] != 0.0 or noise_cfg[2] != 0.0 or noise_cfg[3] != 0.0
    q_joint, q_force, q_obj = noise_cfg[1], noise_cfg[4], noise_cfg[3]
    pws, cws_true, cws_meas = plant_ws
    # the stages, one a line (a tuple of functions would be unified into one function type, numba's experimental path)
    terms = stages.terms
    energy = stages.energy
    # the tick's work arrays (TickWorkspace), by name
    status, xm, Fm, d, R3 = tw.status, tw.xm, tw.Fm, tw.d, tw.R3
    out_int[1] = k
    kq = k if noise_q.shape[0] > 1 else 0  # a noise-free channel passes one row of zeros
    ko = k if noise_o.shape[0] > 1 else 0
    kf = k if noise_f.shape[0] > 1 else 0
    # ---- sensors (true terms: forces, guards)
    terms(x, P, status, cws_true)
    Y, dY, H, h, J, Jdq, W, w_free, S, Fw = _term_arrays(cws_true)
    if status[0] != 0:
        return _plant_failed(status, x, x_fail, out_int), False
    if noisy_state:
        for c in range(nz - p):
            xm[c] = x[c] + noise_q[kq, c]
            xm[nz + c] = x[nz + c] + noise_q[kq, nz - p + c]
            if q_joint != 0.0:
                xm[c] = np.rint(xm[c] / q_joint) * q_joint
                xm[nz + c] = np.rint(xm[nz + c] / q_joint) * q_joint
        for c in range(p):
            xm[nz - p + c] = x[nz - p + c] + noise_o[ko, c]
            xm[nx - p + c] = x[nx - p + c] + noise_o[ko, p + c]
            if q_obj != 0.0:
                xm[nz - p + c] = np.rint(xm[nz - p + c] / q_obj) * q_obj
                xm[nx - p + c] = np.rint(xm[nx - p + c] / q_obj) * q_obj
        terms(xm, P, status, cws_meas)
        if status[0] != 0:
            return _plant_failed(status, xm, x_fail, out_int), False
    for i in range(m):
        for a in range(p):
            v = Fw[i, a] + noise_f[kf, i * p + a]
            if q_force != 0.0:
                v = np.rint(v / q_force) * q_force
            Fm[i, a] = v
    # ---- guards on the state we are at
    gcode, which, worst = _guards(spatial, x, Y, rho, band, max_deformation, R3, d)
    if gcode != DONE:
        out_int[0] = gcode
        if gcode == NEAR_SINGULARITY:
            _copy(x_fail, x)
        elif gcode == DEFORMATION:
            out_int[2] = which
            out_float[0] = worst
        return gcode, False
    if energy_on:  # the energy guard; a passive run records the energy
        E, KE, est = energy(x, P, cws_true, eF, eDY0)
        if est != 0:
            out_int[0] = PLANT_ERROR
            out_int[2] = est
            out_int[3] = 0
            _copy(x_fail, x)
            return PLANT_ERROR, False
        if energy_guard and not abs(E) <= max_energy:
            out_int[0] = ENERGY
            out_float[0] = E
            return ENERGY, False
        if passive:
            rec_E[k] = E
            rec_KE[k] = KE
    _copy(x_good, x)
    out_int[6] = k  # the last tick whose state passed the guards
    # ---- nominal motion and load
    code = nominal_load(k, model, data)
    if code != DONE or not assemble:
        return code, False
    # ---- the QP of the split, from the measured terms
    if noisy_state:
        Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, Fwm = _term_arrays(cws_meas)
    else:
        Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, Fwm = Y, dY, H, h, J, Jdq, W, w_free, S, Fw
    return assemble_split(k, model, data, Ym, Wm, wm_free, Hm, hm, Jm, Jdqm)


@njit(cache=True, inline="always", _nrt=False)
def nominal_load(k, model, data):
    """Stage of a tick (phase 1, and :func:`coopctrl.loop.controller_step.controller_step`): the nominal motion
    of the nodes carried rigidly by the object at trajectory row ``k`` (148: ``Yn``, ``dYn``, ``ddYn`` of
    ``data.tw``) and the object's required wrench ``w_N`` (``tw.wN`` [N, N m]). Returns :data:`DONE`, or
    :data:`NOMINAL_SINGULAR` (``out_int[2]``: the node at the Euler singularity)."""
    spatial, traj, grasps, obj, gravity = model.spatial, model.traj, model.grasps, model.obj, model.P.gravity
    tw, out_int = data.tw, data.out_int
    Yn, dYn, ddYn, R3, v3, wN, obj_inertia = tw.Yn, tw.dYn, tw.ddYn, tw.R3, tw.v3, tw.wN, tw.obj_inertia
    Y0N = traj[0, k]
    dY0N = traj[1, k]
    ddY0N = traj[2, k]
    if spatial:
        bad = spatial_motion_into(Y0N, dY0N, ddY0N, grasps, Yn, dYn, ddYn, R3, v3)
        if bad >= 0:
            out_int[0] = NOMINAL_SINGULAR
            out_int[2] = bad
            return NOMINAL_SINGULAR
    else:
        planar_motion_into(Y0N, dY0N, ddY0N, grasps, Yn, dYn, ddYn)
    required_wrench(spatial, obj[0], obj_inertia, gravity, Y0N, dY0N, ddY0N, wN, v3, R3[0])
    return DONE


@njit(cache=True, inline="always", _nrt=False)
def assemble_split(k, model, data, Ym, Wm, wm_free, Hm, hm, Jm, Jdqm):
    """Stage of a tick (phase 1, and the controller's step): the QP of the split (the ``qp_rows`` stage) into
    ``data.qp_arrays`` from the measured terms ``Ym`` .. ``Jdqm`` and the nominal motion of
    :func:`nominal_load` at row ``k``. Returns ``(code, P changed)``: :data:`DONE`, or :data:`QP_FAILED`
    (``out_int[2]``: the assembly's failure detail) and False."""
    spatial, traj, qp, opts, P = model.spatial, model.traj, model.qp, model.opts, model.P
    qp_rows = model.stages.qp_rows
    elastic_split = model.stages.elastic_split
    tw, qp_arrays, out_int = data.tw, data.qp_arrays, data.out_int
    qcode, P_changed = qp_rows(spatial, Ym, traj[0, k], tw.wN, tw.ddYn, Wm, wm_free, Hm, hm, Jm, Jdqm, P.arm_kind,
                               P.arm_dof, qp, qp_arrays, opts, tw.rc, tw.r0, tw.nrm, tw.Jg, tw.bias, tw.Wa, tw.rhs_t,
                               tw.qdd, tw.piv, tw.wv, tw.wm, tw.R3, elastic_split)
    if qcode != 0:
        out_int[0] = QP_FAILED
        out_int[2] = qcode
        return QP_FAILED, False
    return DONE, P_changed


@njit(cache=True, inline="always", _nrt=False)
def solve_split(model, data, P_changed):
    """Stage of a tick (between the phases, and the controller's step): the compiled solve of the split the
    QP arrays hold (the ``qp_answer`` stage: warm started, its answer check and binding families), then the
    inequality rows active at the answer. Returns ``(ok, status, iterations, binding families, active
    rows)``; not ``ok``: ``out_int = (QP_FAILED, -, status, iterations)``."""
    qp, spatial = model.qp, model.spatial
    qp_answer = model.stages.qp_answer
    qp_arrays, ws, flags, out_int = data.qp_arrays, data.ws, data.flags, data.out_int
    p = 6 if spatial else 3
    m = model.P.arm_kind.shape[0]
    W_diag, qp_num, qp_int = qp.W_diag, qp.numbers, qp.rows
    eps_abs, answer_rho = qp_num[0], qp_num[4]
    max_iter = int(qp_num[2])
    row_grip, row_fric, row_tau, n_fric = qp_int[1], qp_int[2], qp_int[3], qp_int[4]
    Mq = qp_arrays.M
    n = W_diag.shape[0]
    n_in = Mq.shape[0] - p
    qs, qit, okqp, qb = qp_answer(qp_arrays.H, qp_arrays.g, Mq, qp_arrays.lo, qp_arrays.hi, qp_arrays.x, qp_arrays.z, ws,
                                  P_changed, flags, p, m, n, n_in, eps_abs, max_iter, answer_rho, row_grip, row_fric,
                                  row_tau, n_fric)
    if not okqp:
        out_int[0] = QP_FAILED
        out_int[2] = qs
        out_int[3] = qit
        return False, qs, qit, qb, -1
    return True, qs, qit, qb, gi_active_inequalities(ws, p)


@njit(cache=True, inline="always", _nrt=False)
def tick_act(k, source, qs, qit, qb, qact, model, data):
    """Phase 2 of tick ``k``, after :func:`tick_sense` (``model``, ``data`` as there): the split
    (``source``: :data:`SPLIT_SOLVED`, the QP's answer in ``x`` of ``qp_arrays``, which becomes the last
    feasible split; :data:`SPLIT_HELD`, the last feasible split; :data:`SPLIT_NONE`, a passive run's zero
    wrenches), with its QP status ``qs``, iterations ``qit``, binding families mask ``qb`` and active
    inequality rows ``qact`` for the record; the followers' setpoints (the tuning probes), the controllers,
    the saturation, the record row ``k``, then the plant over the period. Returns :data:`DONE` (the plant
    advanced to tick ``k + 1``), :data:`RECORDED` (tick ``k`` was the run's last: recorded, not advanced),
    :data:`PLANT_EXTERNAL` (recorded; the caller advances the plant) or the event (also in ``out_int[0]``)."""
    spatial, N, k_base, T, steps, P, traj = model.spatial, model.N, model.k_base, model.T, model.steps, model.P, model.traj
    opts, noise_cfg = model.opts, model.noise_cfg
    plan, plant_ws, tw, sq, rec = data.plan, data.plant_ws, data.tw, data.sq, data.record
    x, tau, last = data.x, data.tau, data.last_split
    x_fail, out_int, out_float = data.x_fail, data.out_int, data.out_float
    m = P.arm_kind.shape[0]
    p = 6 if spatial else 3
    npos = 3 if spatial else 2
    plant_outside = opts.switches[OPT_EXTERNAL_PLANT] != 0
    noisy_state = noise_cfg[0] != 0.0 or noise_cfg[1] != 0.0 or noise_cfg[2] != 0.0 or noise_cfg[3] != 0.0
    pws, cws_true, cws_meas = plant_ws
    advance = model.stages.advance  # the stages, one a line (see tick_sense)
    # the tick's work arrays (TickWorkspace), by name
    status, xm, Fm, F_set = tw.status, tw.xm, tw.Fm, tw.F_set
    sq_desired, sq_E, sq_W, sq_V, sq_sigma = sq.desired, sq.E, sq.W, sq.V, sq.sigma
    Y = cws_true.ws.Y
    if noisy_state:
        Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, Fwm = _term_arrays(cws_meas)
        zx = xm
    else:
        Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, Fwm = _term_arrays(cws_true)
        zx = x
    Y0N = traj[0, k]
    t = (k_base + k) * T
    # ---- the split, the controllers and the saturation
    code = control_torques(k, source, model, data, rec.F_measured, Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, zx)
    if code != DONE:
        return code
    # ---- record
    rec.t[k] = t
    _copy(rec.x[k], x)
    _copy(rec.tau[k], tau)
    _copy(rec.Y0_nominal[k], Y0N)
    for i in range(m):
        for a in range(p):
            rec.F_measured[k, i, a] = Fm[i, a]
            rec.F_commanded[k, i, a] = F_set[i, a]
            rec.F_external[k, i, a] = last[1, i, a]
            rec.F_internal[k, i, a] = last[2, i, a]
        for a in range(npos):
            rec.r_contacts[k, i, a] = Y[i + 1, a]
    pair_squeeze_into(rec.r_contacts[k], Fm, sq_desired, sq_E, sq_W, sq_V, sq_sigma, rec.squeeze[k])
    rec.qp_status[k] = qs
    rec.qp_binding[k] = qb
    rec.qp_iterations[k] = qit
    rec.qp_active_rows[k] = qact
    out_int[5] = k + 1  # ticks recorded
    if k == N - 1:
        return RECORDED
    if plant_outside:  # an integrator the kernel lacks: the caller advances x over the period, then goes on
        out_int[0] = PLANT_EXTERNAL
        out_int[1] = k + 1
        return PLANT_EXTERNAL
    # ---- plant, zero-order hold over the period (coopctrl.integrators.compiled: the Python integrators' arithmetic)
    step_code = advance(plan, x, tau, P, status, pws, cws_true, t, steps, x_fail, out_int, out_float)
    if step_code != STEP_OK:
        # the Python loop keeps the state of the tick (the exception leaves ``advance``)
        _copy(x, rec.x[k])
        return _step_failed(step_code, status, out_int)
    return DONE


@njit(cache=True, inline="always", _nrt=False)
def control_torques(k, source, model, data, F_rec, Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, zx):
    """Stage of a tick (phase 2, and :func:`coopctrl.loop.controller_step.controller_step`): the split of tick ``k``
    (``source``: :data:`SPLIT_SOLVED`, the QP's answer in ``x`` of ``qp_arrays``, which becomes the last
    feasible split ``last_split``; :data:`SPLIT_HELD`, the last feasible split; :data:`SPLIT_NONE`, zero
    wrenches), the followers' setpoints and measured wrenches (``tw.Fm`` [N, N m]; a tuning probe's offset,
    delay and gain, its delayed readings from ``F_rec`` (rows, m, p)), the leader's and the followers' laws
    (the ``control`` stage) on the measured terms ``Ym`` .. ``Sm`` and joint state ``zx`` into ``data.tau``
    [N m], then the actuator saturation at ``tau_max`` (its tallies in ``flags`` and ``saturated_joints``).
    Returns :data:`DONE`, or the controllers' event (also in ``out_int[0]``, the arm in ``out_int[2]``)."""
    spatial, k_base, T, P, traj = model.spatial, model.k_base, model.T, model.P, model.traj
    ctrl, posture, C_comp, qp, opts = model.ctrl, model.posture, model.C_comp, model.qp, model.opts
    qp_arrays, tw = data.qp_arrays, data.tw
    tau, integ, last, flags = data.tau, data.integrals, data.last_split, data.flags
    sat_joints, out_int = data.saturated_joints, data.out_int
    arm_kind, arm_dof, q_off = P.arm_kind, P.arm_dof, P.q_off
    m = arm_kind.shape[0]
    p = 6 if spatial else 3
    nu = tau.shape[0]
    tau_max = qp.tau_max
    xq, external = qp_arrays.x, qp_arrays.external
    switches, lead_off, law_params = opts.switches, opts.leader_offset, opts.law_params
    leader_law = opts.leader_law
    pr_r, pr_v, pr_g, pr_d = opts.probe_offset, opts.probe_pi, opts.probe_gain, opts.probe_delay
    passive = switches[OPT_PASSIVE] != 0
    probes = switches[OPT_PROBES] != 0
    control = model.stages.control  # (a stage, one a line: see tick_sense)
    # the tick's work arrays (TickWorkspace), by name
    F_cmd, F_seen, Fm, F_set, a_cmd = tw.F_cmd, tw.F_seen, tw.Fm, tw.F_set, tw.a_cmd
    err, Yn, dYn, ddYn, R3, pv, piv, wv, wm = tw.err, tw.Yn, tw.dYn, tw.ddYn, tw.R3, tw.pv, tw.piv, tw.wv, tw.wm
    inc, corr, Yv, tp, ti = tw.inc, tw.corr, tw.Yv, tw.tp, tw.ti
    Y0N = traj[0, k]
    # ---- the split
    if source == SPLIT_SOLVED:
        for i in range(m):
            for a in range(p):
                F_set[i, a] = xq[i * p + a]
                last[0, i, a] = xq[i * p + a]
                last[1, i, a] = external[i * p + a]
                last[2, i, a] = xq[i * p + a] - external[i * p + a]
        flags[0] = 1
    elif source == SPLIT_HELD:
        for i in range(m):
            for a in range(p):
                F_set[i, a] = last[0, i, a]
    else:  # no QP (the caller records no split)
        for i in range(m):
            for a in range(p):
                F_set[i, a] = 0.0
    # the followers' setpoint and measured force (a tuning probe's F* + r + v and delayed, scaled error)
    for i in range(m):
        for a in range(p):
            if probes:
                fc = (F_set[i, a] + pr_r[i, a]) + pr_v[i, a]
                j = max(k - pr_d[i, a], 0)  # the reading of tick j (recorded, or this tick's)
                seen = Fm[i, a] if j == k else F_rec[j, i, a]
                F_cmd[i, a] = fc
                F_seen[i, a] = fc - pr_g[i, a] * (fc - seen)
            else:
                F_cmd[i, a] = F_set[i, a]
                F_seen[i, a] = Fm[i, a]
    # ---- controllers: the leader on its nominal deformed node
    ccode, carm = control(spatial, passive, ctrl, posture, C_comp, arm_kind, arm_dof, q_off, T, F_set, F_cmd, F_seen, Y0N,
                          Yn, dYn, ddYn, Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm, zx, lead_off, integ, tau, R3, pv, inc,
                          Yv, err, a_cmd, corr, tp, wv, wm, piv, ti, leader_law, law_params)
    if ccode != DONE:
        out_int[0] = ccode
        out_int[2] = carm
        return ccode
    # ---- actuator saturation
    sat = False
    for c in range(nu):
        if abs(tau[c]) > tau_max[c]:
            sat = True
    if sat:
        flags[2] += 1
        if flags[2] == 1:
            flags[4] = k_base + k
        flags[5] = k_base + k
        for c in range(nu):
            if abs(tau[c]) > tau_max[c]:
                sat_joints[c] += 1
        for c in range(nu):
            if tau[c] < -tau_max[c]:
                tau[c] = -tau_max[c]
            elif tau[c] > tau_max[c]:
                tau[c] = tau_max[c]
    return DONE


@njit(cache=True, _nrt=False)
def reference_step(k, act, source, qs, qit, qb, sense_next, model, data):
    """The reference path's one entry into the compiled tick per tick (its QP solved by a backend in Python
    between the phases): phase 2 of tick ``k`` (:func:`tick_act`, with ``act``) with the backend's split
    ``source``, QP status ``qs``, iterations ``qit`` and binding families ``qb``, then, with ``sense_next``,
    phase 1 of tick ``k + 1`` (:func:`tick_sense`: its QP assembled for the next solve). ``act = False``:
    phase 1 of tick ``k + 1`` alone (a run's first tick, or after a chunk's end or a plant step in Python).
    ``model``, ``data``: the run (:class:`~coopctrl.loop.model.LoopModel`, :class:`~coopctrl.loop.data.LoopData`). Returns ``(code, P changed)``: :data:`DONE`
    with tick ``k + 1`` sensed (or with ``sense_next`` False, tick ``k`` done and the plant advanced),
    :data:`RECORDED`, :data:`PLANT_EXTERNAL` or the event of either phase (``out_int`` as they leave it)."""
    if act:
        code = tick_act(k, source, qs, qit, qb, -1, model, data)
        if code != DONE or not sense_next:
            return code, False
    return tick_sense(k + 1, True, model, data)


@njit(cache=True, _nrt=False)
def run_ticks(model, data, k0, k_stop):
    """Advance the run (``model``: :class:`~coopctrl.loop.model.LoopModel`, ``data``: :class:`~coopctrl.loop.data.LoopData`) from tick ``k0`` until
    ``model.N`` ticks are recorded, an event, or tick ``k_stop``: per tick :func:`tick_sense`, the compiled
    solve of the split (warm started; its answer check and binding families), :func:`tick_act`.

    Ticks are counted from the run's start: tick ``k`` is at ``t = (k_base + k) T`` [s] and is row ``k`` of
    the record, the trajectory table and the noise streams. ``data.flags[6] = 1``: before anything else the
    plant advances over the period of tick ``k_base - 1`` with the held ``tau``, the step a run ending at that
    tick did not take (a continuation, :class:`~coopctrl.loop.state.LoopState`), and the flag is cleared.
    ``data.hold[0] = 1``: tick ``k0`` takes the last feasible split (the caller applied the failure policy to
    a failed solve), with QP status ``hold[1]`` and iterations ``hold[2]``.

    Returns nothing; ``out_int = (code, tick, detail, detail, -, ticks recorded, last tick that passed
    the guards, right-hand-side evaluations)`` and ``out_float = (value, ...)``.
    """
    spatial, N, k_base, T, steps, stages, P = model.spatial, model.N, model.k_base, model.T, model.steps, model.stages, model.P
    opts = model.opts
    plan, plant_ws, tw, x, tau = data.plan, data.plant_ws, data.tw, data.x, data.tau
    flags, hold_status, x_good, x_fail, out_int, out_float = (data.flags, data.hold, data.x_good, data.x_fail, data.out_int,
                                                              data.out_float)
    passive = opts.switches[OPT_PASSIVE] != 0
    pws, cws_true, cws_meas = plant_ws
    advance = stages.advance  # the stages, one a line (see tick_sense)
    terms = stages.terms
    status = tw.status
    k = k0
    out_int[0] = DONE
    if flags[6] != 0:  # the period a run that ended at tick k_base - 1 did not advance
        flags[6] = 0
        terms(x, P, status, cws_true)  # the terms at x, which that tick's sensing left for the step's first slope
        step_code = STEP_OK if status[0] == 0 else -1
        if step_code == STEP_OK:
            step_code = advance(plan, x, tau, P, status, pws, cws_true, (k_base - 1) * T, steps, x_fail, out_int,
                                out_float)
        if step_code != STEP_OK:
            out_int[1] = 0
            _copy(x, x_good)  # the state of the run's start, as a step that fails within a run keeps its tick's
            _step_failed(step_code, status, out_int)
            return
    while k < N:
        if k == k_stop:
            out_int[0] = CHUNK_END
            out_int[1] = k
            return
        hold = hold_status[0] == 1
        assemble = not passive and not hold
        code, P_changed = tick_sense(k, assemble, model, data)
        if code != DONE:
            return
        # ---- the split: none (passive), the last one held (the caller applied the failure policy), or solved
        if passive:
            source, qs, qit, qb, qact = SPLIT_NONE, 0, -1, 0, -1
        elif hold:
            hold_status[0] = 0
            source, qs, qit, qb, qact = SPLIT_HELD, hold_status[1], hold_status[2], 0, -1
        else:
            okqp, qs, qit, qb, qact = solve_split(model, data, P_changed)
            if not okqp:
                return
            source = SPLIT_SOLVED
        code = tick_act(k, source, qs, qit, qb, qact, model, data)
        if code == RECORDED:
            break
        if code != DONE:
            return
        k += 1
    out_int[1] = k
    out_int[0] = DONE
