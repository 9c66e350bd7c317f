"""``LoopModel``: the constants of one run of the compiled loop, by name (as MuJoCo's ``mjModel``).

The compiled tick (:mod:`coopctrl.loop.kernel`) reads them by name; :mod:`coopctrl.loop.compiled` builds one
per run from the loop's constant arrays (:class:`~coopctrl.loop.compiled.CompiledLoop`) and the run's
trajectory table, noise and stages. Its companion, what a run writes, is :class:`~coopctrl.loop.data.LoopData`.
"""

from __future__ import annotations

from collections import namedtuple

#: The constants of a run, by name (as MuJoCo's ``mjModel``): what every tick reads and none writes.
LoopModel = namedtuple("LoopModel", "spatial N k_base T steps stages P grasps traj obj rho max_deformation band ctrl "
                                    "posture C_comp qp opts noise_q noise_o noise_f noise_cfg")
LoopModel.__doc__ = """The constants of one run of the compiled loop (:func:`~coopctrl.loop.kernel.run_ticks`), by name.

- ``spatial`` (bool); ``N`` ticks to record; ``k_base``: the index of the run's first tick in the motion (0,
  or where the run it continues ended); ``T`` [s] the control period; ``steps`` [s] the plant steps of one
  period;
- ``stages``: the tick's large stages as function pointers (:func:`~coopctrl.loop.kernel.tick_stages`);
- ``P``: the plant's kernel arguments ``(arm_kind, arm_dof, q_off, tables, table_off, bases, tools, gravity,
  node_params, edge_index, edge_params, Y_ref, immobile)`` (``CooperativePlant.kernel`` without the status);
- ``grasps`` (m, p) the grasp offsets; ``traj`` (3, N, p) the nominal object motion ``(Y, dY, ddY)`` per tick;
  ``obj`` the object's mass [kg] and inertia [kg m^2]; ``rho`` (m, npos) the contact points in the object
  frame [m]; ``max_deformation`` [m] and ``band`` (the Euler band's ``|cos theta|``): the guards;
- ``ctrl``: ``(leader, Kp_l, Kd_l, kp_f, ki_f, Kp_f, Kd_f, force_loop, integral_limit)``; ``posture``: the
  null-space posture gains and rest angles; ``C_comp`` (m, p, p) the grasp compliances;
- ``qp``: the QP's weights, desired squeeze, torque limits, friction facets, numbers ``(eps_abs, mu, max_iter,
  min_grip, answer tolerance)`` and row layout ``(has_squeeze, grip row, friction row, torque row, facets,
  max_consecutive_failures)``;
- ``opts = (switches, reals, energy_scratch, zero_rates, rec_energy, rec_kinetic, K_obj, K, KGt, Rb, work,
  leader_offset, r, v, g, d, leader_law, law_params)``: ``switches`` int64 (``OPT_*``); ``reals = (max_energy
  [J],)``; the energy's scratch and record ``(N,)`` [J]; the elastic split's ``K_obj`` (m, p, p) object-frame
  grasp stiffness [N/m, N m/rad] and its work arrays; the tuning probes: ``leader_offset`` (p,) [m, rad] and,
  per arm (m, p), the followers' setpoint offset ``r`` and PI output ``v`` [N, N m], error gain ``g`` [-] and
  measurement delay ``d`` (int64, ticks); ``leader_law``, ``law_params``: the leader's law
  (:func:`~coopctrl.loop.kernel.leader_law_stage`) and its constants;
- ``noise_q``, ``noise_o``, ``noise_f``: the sensor noise drawn beforehand, a row per tick (one row of zeros
  for a noise-free channel); ``noise_cfg``: the noise levels and quantization steps.
"""
