"""The closed loop's tick codes: how a call of the compiled tick (:class:`coopctrl._core.Tick`,
coopctrl/core/tick.h) stopped, where a tick's split comes from, and the bits of the QP's binding families.

The numbers are those of ``TickCode`` and ``SplitSource`` in coopctrl/core/tick_model.h, read by name from the
compiled core (``coopctrl._core.TICK_CODES``), their one definition:
a run's :class:`coopctrl._core.StopReport` holds the code (``stop.code``), the tick (``stop.tick``), its integer
details (``stop.detail``) and its real details (``stop.value``), as each code says.
"""

from __future__ import annotations

from coopctrl._core import TICK_CODES as _CODES
from coopctrl.load_distribution.answer_check import FAMILY_FRICTION, FAMILY_MIN_GRIP, FAMILY_TORQUE  # noqa: F401

#: every tick ran
DONE = _CODES["DONE"]
#: the state is not finite (``DivergenceError`` "state (non-finite)")
NONFINITE = _CODES["NONFINITE"]
#: a node entered the Euler-angle band
NEAR_SINGULARITY = _CODES["NEAR_SINGULARITY"]
#: a contact deformed beyond ``max_deformation`` (``detail[0]`` = contact, ``value[0]`` [m])
DEFORMATION = _CODES["DEFORMATION"]
#: the plant failed (``detail[:2]`` = its status); ``x_fail`` holds the state
PLANT_ERROR = _CODES["PLANT_ERROR"]
#: the QP failed its check (``detail[0]`` = status or assembly code, ``detail[1]`` iterations)
QP_FAILED = _CODES["QP_FAILED"]
#: a nominal node pose is at the Euler singularity (``detail[0]`` = node)
NOMINAL_SINGULAR = _CODES["NOMINAL_SINGULAR"]
#: a controller met a singular Jacobian (``detail[0]`` = arm)
SINGULAR_JACOBIAN = _CODES["SINGULAR_JACOBIAN"]
#: a node's body-rate map is singular in the compliance map (``detail[0]`` = arm)
POSE_INCREMENT_SINGULAR = _CODES["POSE_INCREMENT_SINGULAR"]
#: stopped at ``k_stop`` (progress reporting); resume at ``tick``
CHUNK_END = _CODES["CHUNK_END"]
#: an implicit step's Newton failed (``detail[:2]`` = step, iterations; ``value`` = correction, time)
NEWTON_FAILED = _CODES["NEWTON_FAILED"]
#: the total energy left ``max_energy`` (``value[0]`` = the energy [J])
ENERGY = _CODES["ENERGY"]
#: tick ``tick - 1`` is recorded and its torques are in ``tau``: the caller integrates ``x`` over the period
#: and resumes at ``tick``
PLANT_EXTERNAL = _CODES["PLANT_EXTERNAL"]
#: an error-controlled step fell below ``min_step`` (``value`` = step [s], time [s])
STEP_TOO_SMALL = _CODES["STEP_TOO_SMALL"]
#: the run's last tick is recorded (the plant is not advanced past it)
RECORDED = _CODES["RECORDED"]
#: a controller step's measured value is not finite (``detail``: field, arm, entry)
MEASUREMENT_NOT_FINITE = _CODES["MEASUREMENT_NOT_FINITE"]
#: a law written in Python failed (what it raised is raised; ``detail[0]`` = arm)
LAW_FAILED = _CODES["LAW_FAILED"]

#: Where a tick's split comes from: the QP's answer (it becomes the last feasible split), the last feasible split
#: (a failed solve, after the failure policy), none (a passive run: zero wrenches, no controllers).
SPLIT_SOLVED = _CODES["SPLIT_SOLVED"]
SPLIT_HELD = _CODES["SPLIT_HELD"]
SPLIT_NONE = _CODES["SPLIT_NONE"]
