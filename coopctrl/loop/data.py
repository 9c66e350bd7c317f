"""``LoopData``: what one run of the compiled loop reads and writes, by name (as MuJoCo's ``mjData``), and
``TickRecord``, the record rows a tick writes.

The loop state's arrays in it are those of the run's :class:`~coopctrl.loop.state.LoopState` (a copy of the
state the run was given: a run changes nothing it was given); :mod:`coopctrl.loop.run` builds one per run.
Its companion, the run's constants, is :class:`~coopctrl.loop.model.LoopModel`.
"""

from __future__ import annotations

from collections import namedtuple

#: The rows a tick records (row ``k``), by the record's names (:class:`~coopctrl.loop.record.LoopRecord`).
TickRecord = namedtuple("TickRecord", "t x tau Y0_nominal F_measured F_commanded F_external F_internal r_contacts "
                                      "squeeze qp_status qp_binding qp_iterations qp_active_rows")

#: What a run reads and writes, by name (as MuJoCo's ``mjData``): its state, work arrays, record and outputs.
LoopData = namedtuple("LoopData", "plan qp_arrays ws sq x tau integrals last_split flags saturated_joints hold record "
                                  "x_good x_fail stop")
LoopData.__doc__ = """What one run of the compiled tick (:class:`coopctrl._core.Tick`) reads and writes, by name.

- ``plan``: the integration plan (:func:`coopctrl.integrators.compiled.make_plan`: its work arrays and the
  step-to-step state, an implicit scheme's Newton matrix, an error-controlled scheme's step and statistics);
  ``qp_arrays``: the QP and its answer (:class:`QPArrays`); ``ws``: the compiled QP's workspace (its warm
  start); ``sq``: the squeeze's desired values (:func:`coopctrl.loop.squeeze.squeeze_workspace`); the tick's
  own work arrays are the core's (made once per run);
- the loop state, updated in place (:class:`~coopctrl.loop.state.LoopState`, whose fields these are): ``x``
  (nx) the plant state; ``tau`` (nu) the held torques [N m]; ``integrals`` (m, p) the followers' force-error
  integrals [N s]; ``last_split`` (3, m, p) the last feasible split ``(F, external, internal)`` [N, N m];
  ``flags`` the run's tallies (:class:`coopctrl._core.LoopFlags`, by name); ``saturated_joints`` (nu,) int64;
  ``hold`` the next tick's hold (:class:`coopctrl._core.HoldState`);
- ``record``: the rows written per tick (:class:`TickRecord`; ``squeeze`` the virtual-linkage squeeze [N] of
  the measured wrenches, ``qp_active_rows`` the inequality rows active at the compiled solver's answer, -1 on
  a held, passive or externally solved tick);
- ``x_good``: the last state that passed the guards; ``x_fail``: the state a failure was met at; ``stop``: how
  the run stopped (:class:`coopctrl._core.StopReport`: its code, tick and details by name,
  :mod:`coopctrl.loop.tick_codes`); ``record`` is None for a controller's step, which records nothing.
"""


#: The QP of a tick and its answer, by name (``LoopData.qp_arrays``).
QPArrays = namedtuple("QPArrays", "M lo hi H g x z external F_pref E A y K")
QPArrays.__doc__ = """The load-distribution QP a tick assembles and its answer (``LoopData.qp_arrays``), by name.

``lo <= M F <= hi`` with the cost ``F^T H F / 2 + g^T F``: ``M`` (p + n_in, n) the object's wrench rows (equal
bounds: the required wrench) and the inequality rows; ``x`` (n,) the answer ``F`` [N, N m] and ``z`` its row
multipliers; ``external`` (n,) and ``F_pref`` (n,) the external share and the preferred split [N, N m]; ``E``,
``A`` (p, p), ``y`` (p,): the elastic split's work arrays; ``K`` (n, n): the elastic split's world-frame grasp stiffness
of the last tick [N/m, N m/rad] (its ``H`` is redone when ``K`` changes).
"""
