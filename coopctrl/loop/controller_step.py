"""The controller's step: the control layer of one tick, from a measurement, without the plant.

:func:`controller_step` runs the stages of the compiled tick (:mod:`coopctrl.loop.kernel`) that make the
torques, in the tick's order, on a measurement given by the caller instead of the plant's state:

1. **measurement**: every value checked finite, then written into the measured state ``x_m = (z, z')``
   (the arms' joint positions and rates, the object's pose ``Y_0`` and its rate) and the measured
   contact wrenches ``F_meas``;
2. **terms**: the plant's control terms at ``x_m`` (the ``terms`` stage: node poses, the arms' dynamics
   and Jacobians), as the tick's sensors compute them at the measured state;
3. **nominal motion and load**: :func:`~coopctrl.loop.kernel.nominal_load` (the nodes carried rigidly by
   the object, 148, and ``w_N``);
4. **QP**: :func:`~coopctrl.loop.kernel.assemble_split` and :func:`~coopctrl.loop.kernel.solve_split`
   (warm started), or the last feasible split when the caller holds it;
5. **controllers and saturation**: :func:`~coopctrl.loop.kernel.control_torques` into ``tau``.

No guard needs the plant's true state and no plant advance runs: the caller owns the plant. The run's
model and data live in one :class:`ControllerBox` (a compiled structure built once,
:func:`new_controller_box`), so that a call from Python converts one object, not the few hundred arrays
the tick reads (:func:`controller_step`, which hands them to :func:`run_step`).
"""

from __future__ import annotations

import math
from collections import namedtuple

from numba import njit, types
from numba.experimental import structref

from coopctrl.loop.kernel import (DONE, PLANT_ERROR, QP_FAILED, SPLIT_HELD, SPLIT_SOLVED, assemble_split,
                                  control_torques, nominal_load, solve_split)

#: Code of ``out_int[0]``: a measured value is not finite (``out_int[2]`` the field, ``[3]`` the arm or
#: grasp, ``[4]`` the component).
MEASUREMENT_NOT_FINITE = 16

#: The measurement's fields, by the index ``out_int[2]`` names them with.
FIELD_Q, FIELD_DQ, FIELD_WRENCH, FIELD_POSE, FIELD_TWIST = 0, 1, 2, 3, 4


#: What the controller's step reads and writes, by name: the part of a run's
#: :class:`~coopctrl.loop.data.LoopData` its stages use (the same arrays), with ``cws`` the control terms'
#: workspace and ``F_record`` (1, m, p) the readings a tuning probe would delay (none: the controller has no probes).
ControllerData = namedtuple("ControllerData", "qp_arrays ws tw cws tau integrals last_split flags saturated_joints x_fail "
                                              "out_int F_record")


@structref.register
class ControllerBoxType(types.StructRef):
    """The compiled type of a :class:`ControllerBox`: fields ``model`` and ``data``."""


class ControllerBox(structref.StructRefProxy):
    """A run's :class:`~coopctrl.loop.model.LoopModel` and :class:`~coopctrl.loop.data.LoopData` held by the
    compiled code (their arrays are shared with the Python objects they were built from)."""


structref.define_constructor(ControllerBox, ControllerBoxType, ["model", "data"])
structref.define_boxing(ControllerBoxType, ControllerBox)


@njit(cache=True)
def new_controller_box(model, data):
    """The :class:`ControllerBox` of ``model`` and ``data`` (converted once; cached on disk per type)."""
    return ControllerBox(model, data)


@njit(inline="always", _nrt=False)
def _refused(out_int, field, index, component):
    out_int[0] = MEASUREMENT_NOT_FINITE
    out_int[2] = field
    out_int[3] = index
    out_int[4] = component
    return MEASUREMENT_NOT_FINITE


@njit(cache=True, _nrt=False)
def measurement_into(q, dq, wrench, pose, twist, q_off, arm_dof, xm, Fm, out_int):
    """The measurement into the measured state ``xm = (q, Y_0, dq, dY_0)`` and wrenches ``Fm`` (m, p), every
    value checked finite first (nothing is written otherwise). ``q``, ``dq``: per arm (n_i,) [rad], [rad/s];
    ``wrench`` (m, p) [N, N m]; ``pose``, ``twist`` (p,) [m, rad], [m/s, rad/s]. Returns :data:`DONE` or
    :data:`MEASUREMENT_NOT_FINITE` (``out_int[2:5]``: field, arm or grasp, component)."""
    m = q_off.shape[0]
    p = pose.shape[0]
    for i in range(m):
        for c in range(arm_dof[i]):
            if not math.isfinite(q[i][c]):
                return _refused(out_int, FIELD_Q, i, c)
            if not math.isfinite(dq[i][c]):
                return _refused(out_int, FIELD_DQ, i, c)
        for a in range(p):
            if not math.isfinite(wrench[i, a]):
                return _refused(out_int, FIELD_WRENCH, i, a)
    for a in range(p):
        if not math.isfinite(pose[a]):
            return _refused(out_int, FIELD_POSE, 0, a)
        if not math.isfinite(twist[a]):
            return _refused(out_int, FIELD_TWIST, 0, a)
    nz = xm.shape[0] // 2
    for i in range(m):
        o = q_off[i]
        for c in range(arm_dof[i]):
            xm[o + c] = q[i][c]
            xm[nz + o + c] = dq[i][c]
        for a in range(p):
            Fm[i, a] = wrench[i, a]
    for a in range(p):
        xm[nz - p + a] = pose[a]
        xm[2 * nz - p + a] = twist[a]
    return DONE


@njit(cache=True, _nrt=False)
def run_step(model, data, k, hold, q, dq, wrench, pose, twist):
    """One control period of the controller of ``model`` (:class:`~coopctrl.loop.model.LoopModel`) and ``data``
    (:class:`ControllerData`) at row ``k`` of its trajectory table, from the measurement ``q``, ``dq``, ``wrench``, ``pose``, ``twist`` (:func:`measurement_into`):
    the tick's stages in its order (the module docstring). ``hold``: take the last feasible split instead of
    solving (the caller applied the failure policy to a failed solve of this period).

    Returns the code (also in ``data.out_int[0]``): :data:`~coopctrl.loop.kernel.DONE` with the saturated
    torques in ``data.tau`` [N m]; :data:`MEASUREMENT_NOT_FINITE` (nothing changed); :data:`QP_FAILED`
    (``out_int[2:4]`` as the loop leaves them; nothing of the controllers ran); or the event of a stage
    (:data:`~coopctrl.loop.kernel.PLANT_ERROR` at the measured state, ``NOMINAL_SINGULAR``, ``SINGULAR_JACOBIAN``,
    ``POSE_INCREMENT_SINGULAR``)."""
    P = model.P
    tw, out_int = data.tw, data.out_int
    xm, Fm, status = tw.xm, tw.Fm, tw.status
    terms = model.stages.terms  # the stages, one a line (see coopctrl.loop.kernel.tick_sense)
    cws = data.cws
    out_int[0] = DONE
    out_int[1] = k
    # ---- measurement
    code = measurement_into(q, dq, wrench, pose, twist, P.q_off, P.arm_dof, xm, Fm, out_int)
    if code != DONE:
        return code
    # ---- the control terms at the measured state
    status[0] = 0
    terms(xm, P, status, cws)
    if status[0] != 0:
        out_int[0] = PLANT_ERROR
        out_int[2] = status[0]
        out_int[3] = status[1]
        for c in range(xm.shape[0]):
            data.x_fail[c] = xm[c]
        return PLANT_ERROR
    Ym, dYm, Hm, hm, Jm, Jdqm = cws.ws.Y, cws.ws.dY, cws.ws.H, cws.ws.h, cws.ws.J, cws.ws.Jdq
    Wm, wm_free, Sm = cws.W, cws.w_free, cws.S
    # ---- nominal motion and load
    code = nominal_load(k, model, data)
    if code != DONE:
        return code
    # ---- the split: solved, or the last feasible one held
    if hold:
        source = SPLIT_HELD
    else:
        code, P_changed = assemble_split(k, model, data, Ym, Wm, wm_free, Hm, hm, Jm, Jdqm)
        if code != DONE:
            return code
        okqp, qs, qit, qb, qact = solve_split(model, data, P_changed)
        if not okqp:
            return QP_FAILED
        source = SPLIT_SOLVED
    # ---- controllers and saturation
    return control_torques(k, source, model, data, data.F_record, Ym, dYm, Hm, hm, Jm, Jdqm, Wm, wm_free, Sm,
                           xm)


@njit(cache=True)
def controller_step(box, k, hold, q, dq, wrench, pose, twist):
    """:func:`run_step` of the controller in ``box`` (:class:`ControllerBox`): the entry from Python (the box's
    structure needs numba's runtime; the step itself runs without it)."""
    return run_step(box.model, box.data, k, hold, q, dq, wrench, pose, twist)
