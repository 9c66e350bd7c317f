"""``LoopModel``: the constants of one run of the compiled loop, by name (as MuJoCo's ``mjModel``).

The compiled tick (:class:`coopctrl._core.Tick`, coopctrl/core/tick_model.h) reads them by name;
:mod:`coopctrl.loop.build` builds one per run from the loop's constants (:class:`~coopctrl.loop.build.LoopConstants`)
and the run's trajectory table and noise. Its companion, what a run writes, is :class:`~coopctrl.loop.data.LoopData`.
"""

from __future__ import annotations

from collections import namedtuple

#: The constants of a run, by name (as MuJoCo's ``mjModel``): what every tick reads and none writes.
LoopModel = namedtuple("LoopModel", "spatial N k_base T steps P grasps traj object_mass object_inertia rho "
                                    "max_deformation band control qp opts sensors")
LoopModel.__doc__ = """The constants of one run of the compiled tick (:class:`coopctrl._core.Tick`), by name.

- ``spatial`` (bool); ``N`` ticks to record; ``k_base``: the index of the run's first tick in the motion (0,
  or where the run it continues ended); ``T`` [s] the control period; ``steps`` [s] the plant steps of one
  period;
- ``P``: the plant's arrays by name (:class:`~plants.cooperative.plant_args.PlantArgs`: ``arm_kind``,
  ``arm_dof``, ``q_off``, ``tables``, ``table_off``, ``bases``, ``tools``, ``gravity``, ``node_params``,
  ``edge_index``, ``edge_params``, ``Y_ref``, ``immobile``; ``CooperativePlant.plant_args``);
- ``grasps`` (m, p) the grasp offsets; ``traj`` (3, N, p) the nominal object motion ``(Y, dY, ddY)`` per tick;
  ``object_mass`` [kg] and ``object_inertia`` (3,) spatial, (1,) planar [kg m^2]: the object's; ``rho`` (m, npos)
  the contact points in the object frame [m]; ``max_deformation`` [m] and ``band`` (the Euler band's
  ``|cos theta|``): the guards;
- ``control``: the controllers (:class:`ControlModel`);
- ``qp``: the QP's constants (:class:`QPConstants`); ``opts``: what the run switches on (:class:`RunOptions`);
- ``sensors``: the sensor noise drawn beforehand and the quantization (:class:`SensorModel`).
"""

#: The sensors of a run, by name (``LoopModel.sensors``).
SensorModel = namedtuple("SensorModel", "joints object wrench noisy_state joint_step object_step wrench_step")
SensorModel.__doc__ = """The sensors of one run (``LoopModel.sensors``), by name.

- ``joints`` (rows, 2 nq): the joint angle and rate noise per tick [rad, rad/s], arm by arm (q, then dq);
  ``object`` (rows, 2 p): the object pose and twist noise; ``wrench`` (rows, m p): the contact wrench noise
  [N, N m]; a noise-free channel is one row of zeros (the tick reads row 0);
- ``noisy_state``: the state is measured apart from the true one (a joint or object channel is noisy or
  quantized); ``joint_step`` [rad], ``object_step`` [m, rad], ``wrench_step`` [N, N m]: the quantization steps
  (0: none).
"""


#: The QP's constants of a run, by name (``LoopModel.qp``).
QPConstants = namedtuple("QPConstants", "W_diag W_inv_diag s_des tau_qp tau_max cos_phi sin_phi eps_abs mu_c max_iter "
                                        "min_grip answer_rho has_squeeze min_grip_row friction_row torque_row facets "
                                        "max_consecutive_failures")
QPConstants.__doc__ = """The load-distribution QP's constants of a run (``LoopModel.qp``), by name.

- ``W_diag``, ``W_inv_diag`` (n,): the weights of the contact wrenches and their inverses; ``s_des`` the desired
  squeeze [N]; ``tau_qp`` (nu,) the joint torque limits the QP's torque rows use [N m]; ``tau_max`` (nu,) the
  saturation limits [N m]; ``cos_phi``, ``sin_phi``: the friction pyramid's facet directions (spatial; one zero
  otherwise);
- ``eps_abs`` [N] the solver's feasibility tolerance; ``mu_c`` the inscribed pyramid's friction coefficient;
  ``max_iter`` the solver's iteration limit; ``min_grip`` [N] the least normal force (0 when the family is off);
  ``answer_rho`` the fraction of the load an answer may miss;
- the row layout, counted from the first inequality row: ``has_squeeze``; ``min_grip_row``, ``friction_row``,
  ``torque_row`` each family's first row (-1 where absent); ``facets`` the friction rows per contact;
  ``max_consecutive_failures`` the failed solves in a row before the run stops.
"""

#: What a run switches on and the arrays that go with it, by name (``LoopModel.opts``).
RunOptions = namedtuple("RunOptions", "passive energy max_energy elastic_split probes plant_outside energy_record "
                                      "kinetic_energy_record K_obj leader_offset probe_offset probe_pi probe_gain "
                                      "probe_delay")
RunOptions.__doc__ = """What one run switches on and the arrays that go with it (``LoopModel.opts``), by name.

- ``passive``: no QP, no controllers, zero torques (the energy recorded); ``energy``: 0, or 1 to evaluate the
  energy each tick, 2 to also stop when it leaves ``max_energy`` [J]; ``energy_record``,
  ``kinetic_energy_record`` (N,) [J]: a passive run's energy;
- ``elastic_split``: the QP's cost from the grasp stiffness ``K_obj`` (m, p, p) [N/m, N m/rad];
- ``plant_outside``: an integrator outside the core steps the plant (the tick stops after each record);
- the tuning probes (``probes``: the followers'): ``leader_offset`` (p,) [m, rad] and, per arm (m, p), the
  followers' setpoint offset ``probe_offset`` and PI output ``probe_pi`` [N, N m], error gain ``probe_gain`` [-]
  and measurement delay ``probe_delay`` (int64, ticks).
"""


#: The controllers of a run, by name, as the compiled core's tick reads them (coopctrl/core/tick_model.h's
#: ControlModel).
ControlModel = namedtuple("ControlModel", "leader leader_Kp leader_Kd follower_kp follower_ki follower_Kp follower_Kd "
                                          "force_loop integral_limit posture_gain q_rest compliance leader_law "
                                          "leader_law_params follower_law follower_law_params")
ControlModel.__doc__ = """The controllers of one run, by name (the compiled core's ``ControlModel``).

- ``leader``: the leader arm's index; ``leader_Kp`` [1/s^2], ``leader_Kd`` [1/s]: its computed torque's gains;
- the followers' force PI ``follower_kp`` [-], ``follower_ki`` [1/s] (``integral_limit`` [N s] its clip, closed when
  ``force_loop``) and motion loop ``follower_Kp`` [1/s^2], ``follower_Kd`` [1/s];
- ``posture_gain`` (2,) = (Kp [1/s^2], Kd [1/s]) of a redundant arm's null-space posture torque, ``q_rest`` (m, nmax)
  its rest angles [rad];
- ``compliance`` (m, p, p): the grasp compliances [m/N, rad/(N m)];
- ``leader_law``, ``follower_law``: the nodes' laws, a built-in law's name (``"computed_torque"``,
  ``"object_impedance"``) or a Python function ``law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd)`` (the slower
  path); ``leader_law_params``, ``follower_law_params`` their constants.
"""
