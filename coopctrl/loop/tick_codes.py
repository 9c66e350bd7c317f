"""The closed loop's tick codes: how a call of the compiled tick (:class:`coopctrl._core.Tick`,
coopctrl/core/tick.h) stopped, where a tick's split comes from, and the bits of the QP's binding families.

The numbers are those of ``TickCode`` and ``SplitSource`` in coopctrl/core/tick_model.h (a test checks them):
``out_int[0]`` of a run holds the code, ``out_int[1]`` the tick, ``out_int[2:5]`` its details and ``out_float``
its real details, as each code says.
"""

from __future__ import annotations

from coopctrl.load_distribution.answer_check import FAMILY_FRICTION, FAMILY_MIN_GRIP, FAMILY_TORQUE  # noqa: F401

DONE = 0            #: every tick ran
NONFINITE = 1       #: the state is not finite (``DivergenceError`` "state (non-finite)")
NEAR_SINGULARITY = 2  #: a node entered the Euler-angle band
DEFORMATION = 3     #: a contact deformed beyond ``max_deformation`` (``out_int[2]`` = contact, ``out_float[0]`` [m])
PLANT_ERROR = 4     #: the plant failed (``out_int[2:4]`` = its status); ``x_fail`` holds the state
QP_FAILED = 5       #: the QP failed its check (``out_int[2]`` = status or assembly code, ``[3]`` iterations)
NOMINAL_SINGULAR = 6  #: a nominal node pose is at the Euler singularity (``out_int[2]`` = node)
SINGULAR_JACOBIAN = 7  #: a controller met a singular Jacobian (``out_int[2]`` = arm)
POSE_INCREMENT_SINGULAR = 8  #: a node's body-rate map is singular in the compliance map (``out_int[2]`` = arm)
CHUNK_END = 9       #: stopped at ``k_stop`` (progress reporting); resume at ``out_int[1]``
NEWTON_FAILED = 10  #: an implicit step's Newton failed (``out_int[2:4]`` = step, iterations; ``out_float`` = correction, time)
ENERGY = 11         #: the total energy left ``max_energy`` (``out_float[0]`` = the energy [J])
PLANT_EXTERNAL = 13  #: tick ``out_int[1] - 1`` is recorded and its torques are in ``tau``: the caller integrates
                     #: ``x`` over the period and resumes at tick ``out_int[1]``
STEP_TOO_SMALL = 14  #: an error-controlled step fell below ``min_step`` (``out_float`` = step [s], time [s])
RECORDED = 15       #: the run's last tick is recorded (the plant is not advanced past it)
MEASUREMENT_NOT_FINITE = 16  #: a controller step's measured value is not finite (``out_int[2:5]``: field, arm, entry)
LAW_FAILED = 17     #: a law written in Python failed (what it raised is raised; ``out_int[2]`` = arm)

#: Where a tick's split comes from.
SPLIT_SOLVED = 0    #: the QP's answer (it becomes the last feasible split)
SPLIT_HELD = 1      #: the last feasible split (a failed solve, after the failure policy)
SPLIT_NONE = 2      #: none: a passive run (zero wrenches, no controllers)

#: Entries of ``RunOptions.switches`` (int64 switches of a run).
OPT_PASSIVE = 0     #: no QP, no controllers, zero torques; energy recorded
OPT_ENERGY = 1      #: evaluate the energy each tick (1: record it, 2: also guard ``max_energy``)
OPT_ELASTIC = 2     #: ``split = "elastic"``: the QP's cost from the grasp stiffness
OPT_PROBES = 3      #: the followers' tuning probes (setpoint offset, PI output, error gain, delay)
OPT_EXTERNAL_PLANT = 4  #: stop after each tick's record with :data:`PLANT_EXTERNAL` (an integrator outside the core)
