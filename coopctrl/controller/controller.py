"""``Controller``: the scene's whole control layer as one object, stepped once per control period.

::

    controller = coopctrl.Controller(scenario)
    while running:                                   # every T = simulation.control_period [s]
        torques = controller.step(t, measurement)    # Measurement -> Torques [N m], held over the period

Each step runs the compiled stages of the loop's tick that make the torques
(the tick's controller step, coopctrl/core/tick.h: the control terms at the measured state, the nominal
motion and load, the QP of the split and its warm-started solve, the leader's and the followers' laws, the
saturation): the same code as ``coopctrl run``, on the caller's measurement instead of the elastic plant's
state. Everything it carries between steps is :attr:`Controller.state`, a frozen snapshot that can be put back.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from coopctrl.controller.controller_state import ControllerState
from coopctrl.controller.measurement import Measurement
from coopctrl.controller.torques import Torques
from coopctrl.errors import MeasurementError, ScenarioError

_F64 = np.dtype(np.float64)

#: The measurement's fields, in the compiled step's order, with what each holds.
_FIELDS = ("q", "dq", "wrench", "object_pose", "object_twist")
_WHAT = {"q": "joint positions [rad]", "dq": "joint rates [rad/s]", "wrench": "grasp wrenches [N, N m]",
         "object_pose": "the object's pose [m, rad]", "object_twist": "the object's pose rate [m/s, rad/s]"}


def _ready(a, shape) -> bool:
    """Whether ``a`` can go to the compiled step as it is: a writable C-contiguous float64 array of ``shape``."""
    if type(a) is not np.ndarray or a.dtype is not _F64 or a.shape != shape:
        return False
    flags = a.flags
    return flags.c_contiguous and flags.writeable


class Controller:
    """The control layer of ``scenario`` (a :class:`~coopctrl.scenario.Scenario`): QP load split, the leader's
    computed torque, the followers' force loops, the actuator saturation, with explicit state.

    Call :meth:`step` once per control period ``T`` (``simulation.control_period`` [s]): the followers'
    force integrals advance by ``T`` per call, whatever ``t`` says. ``t`` [s] is the time on the scene's
    trajectory (0 at its start; after its end the trajectory holds its last pose).

    Args:
        scenario: The scene (``coopctrl.load_scenario(path)``). Its sensor noise is not applied: the
            measurement is the sensors' output.

    Attributes:
        arm_names: The arms' names, in order; ``joint_counts``: their joints ``n_i``; ``p``: the pose size
            (6 spatial, 3 planar); ``control_period``: ``T`` [s].

    Raises:
        TypeError: ``scenario`` is not a Scenario.
        ScenarioError: a scene the step cannot run (controllers disabled, a QP solver other than the
            compiled one), with the setting that would make it run.
    """

    def __init__(self, scenario):
        from coopctrl import wiring

        wiring.check_scenario(scenario)
        if not scenario.controllers.enabled:
            raise ScenarioError("controllers.enabled", False, "true: a Controller runs the scene's controllers")
        if scenario.load_distribution.solver != "compiled":
            raise ScenarioError("load_distribution.solver", scenario.load_distribution.solver,
                                '"compiled": the Controller solves the split with the compiled solver')
        self.scenario = scenario
        self._loop = loop = wiring.closed_loop(scenario)
        self._build(loop)

    # ------------------------------------------------------------------ set-up
    def _build(self, loop) -> None:
        import coopctrl._core as _core
        import coopctrl.integrators.compiled as I
        from coopctrl.integrators import ExplicitEuler
        from coopctrl.loop import build as B
        from coopctrl.loop.data import LoopData
        from coopctrl.loop.euler_band import margin_cos
        from coopctrl.loop.model import LoopModel, SensorModel
        from coopctrl.loop.squeeze import squeeze_workspace
        from coopctrl.loop.state import LoopState

        plant = loop.plant
        cl = B.constants(loop)
        self._cl = cl
        m, p, nx, nu = plant.arm_count, plant.p, plant.state_size, plant.input_size
        self.p = p
        self.control_period = T = float(loop.T)
        self.arm_names = tuple(a.name for a in plant.arms)
        self.joint_counts = tuple(int(n) for n in plant.arm_dofs)
        offsets = np.concatenate([[0], np.cumsum(self.joint_counts)]).astype(int)
        self._slices = tuple(slice(int(a), int(b)) for a, b in zip(offsets[:-1], offsets[1:]))
        self._nz = plant.nz
        # the trajectory table: one row per period over the scene's duration, and a last row for a time between
        self._rows = int(round(self.scenario.simulation.duration / T)) + 1
        self._trajectory = loop.trajectory
        traj = np.zeros((3, self._rows + 1, p))
        P = cl.P
        self._charts = loop.rotations == "charts"
        if self._charts:  # the loop's world chart (coopctrl.loop.charts), its first one: the book's world
            own = plant.with_own_world().plant_args
            P = P._replace(bases=own.bases, gravity=own.gravity)
        traj[:, :self._rows] = self._table(np.arange(self._rows) * T)
        self._traj = traj
        # [s] where the trajectory ends (its motion is constant from there on), and the table's first row there
        self._trajectory_end = float(getattr(loop.trajectory, "duration", math.inf))
        end_row = math.ceil(self._trajectory_end / T - 1e-9) if math.isfinite(self._trajectory_end) else self._rows
        self._end_row = end_row if end_row < self._rows else None
        state = LoopState.start(np.zeros(nx), nu, m, p, cl.n, p + cl.n_in)
        self._state = state
        qa = cl.qp_arrays()
        opts = cl.options(loop, loop.empty_record(1), False)
        x_fail = np.zeros(nx)
        stop = _core.StopReport()
        nq = plant.nz - p
        self._P = P
        # the run's model and data (coopctrl.loop.model, .data) with no plant advance and no record: the tick's
        # controller step reads the measurement instead of the plant's state
        model = LoopModel(spatial=cl.spatial, N=self._rows + 1, k_base=0, T=T, steps=cl.steps, P=P, grasps=cl.grasps,
                          traj=traj, object_mass=cl.object_mass, object_inertia=cl.object_inertia, rho=cl.rho,
                          max_deformation=loop.max_deformation, band=margin_cos(), control=cl.control_model(loop),
                          qp=cl.qp, opts=opts,
                          sensors=SensorModel(joints=np.zeros((1, 2 * nq)), object=np.zeros((1, 2 * p)),
                                              wrench=np.zeros((1, m * p)), noisy_state=False, joint_step=0.0,
                                              object_step=0.0, wrench_step=0.0))
        data = LoopData(plan=I.make_plan(ExplicitEuler(), nx, T, 1), qp_arrays=qa, ws=state.ws,
                        sq=squeeze_workspace(m, 3 if cl.spatial else 2, loop.squeeze_desired), x=state.x,
                        tau=state.tau, integrals=state.integrals, last_split=state.last_split, flags=state.flags,
                        saturated_joints=state.saturated_joints, hold=state.hold, record=None, x_good=np.zeros(nx),
                        x_fail=x_fail, stop=stop)
        self._model, self._data, self._qa, self._opts = model, data, qa, opts  # the tick shares their arrays
        self._stop, self._x_fail = stop, x_fail
        self._tick = _core.Tick(model, data)
        self._tau = state.tau
        from coopctrl.loop.charts import RECENTRE_COS

        self._recentre_cos = RECENTRE_COS  # [-] the loop re-centres its world chart below this |cos theta|
        self._steps = 0
        self._shapes = (tuple((n,) for n in self.joint_counts), (m, p), (p,))
        self._live = {"tau": state.tau, "integrals": state.integrals, "last_split": state.last_split,
                      "flags": state.flags, "saturated_joints": state.saturated_joints, "qp_workspace": state.ws,
                      "qp_hessian": qa.H, "qp_answer": qa.x, "qp_multipliers": qa.z,
                      "elastic_stiffness": qa.K}
        self._initial = self.state

    # ------------------------------------------------------------------ the step
    def step(self, t: float, measurement: Measurement) -> Torques:
        """The torques to hold over the period that starts at ``t`` [s], from ``measurement`` taken at ``t``.

        Per call, in the loop's order: the measurement checked (shapes, then every value finite) and written
        into the measured state; the control terms there (node poses, the arms' dynamics and Jacobians); the
        nominal motion of the object and its nodes at ``t`` and the required object wrench ``w_N``; the QP of
        the split, solved warm-started (a failed solve: the load distribution's failure policy holds the last
        feasible split); the leader's computed torque and the followers' force PI and computed torque; the
        saturation at the arms' torque limits. The state advances (:attr:`state`).

        Raises:
            MeasurementError: a field missing, of the wrong shape, or not finite (the state is unchanged).
            InfeasibleLoad: the split failed and there is no split to hold, or too many failed in a row.
            PlantError: a singular Jacobian or an Euler-angle singularity at the measured state.
        """
        k = self._row(t)
        q, dq, wrench, pose, twist = self._checked(measurement)
        if self._charts and math.isfinite(pose[4]) and abs(math.cos(pose[4])) < self._recentre_cos:
            self._beyond_chart(pose)
        code = self._tick.controller_step(k, False, q, dq, wrench, pose, twist)
        if code != 0:
            self._event(code, k, (q, dq, wrench, pose, twist))
        self._steps += 1
        return Torques(self._tau.copy(), self.arm_names, self._slices)

    def _table(self, times) -> np.ndarray:
        """The nominal object motion ``(Y, dY, ddY)`` at ``times`` (N,) [s], (3, N, p), as the loop tabulates it
        (in rotation charts: in the world chart, here the book's world, through the rotation group)."""
        from coopctrl.loop import charts as loop_charts
        from coopctrl.loop.build import trajectory_samples

        if not self._charts:
            return trajectory_samples(self._trajectory, times, self.p)
        return loop_charts.world_table(self._trajectory, times)

    def _row(self, t) -> int:
        """The trajectory table's row of time ``t`` [s]: its period's row; after the trajectory's end, the row where it
        ends; else the spare last row, filled at ``t`` (the trajectory evaluated in Python: 0.1 to 0.5 ms)."""
        T = self.control_period
        try:
            k = round(t / T)
        except (TypeError, ValueError, OverflowError):
            k = None
        if k is None or not t >= 0.0:
            raise ValueError(f"t = {t!r} is invalid: expected a finite time >= 0 [s] on the scene's trajectory")
        if k < self._rows and abs(t - k * T) <= 1e-9 * T:
            return k
        if self._end_row is not None and t >= self._trajectory_end:  # the trajectory holds its last pose
            return self._end_row
        self._traj[:, -1] = self._table(np.array([float(t)]))[:, 0]
        return self._rows

    def _beyond_chart(self, pose) -> None:
        raise MeasurementError("object_pose[4]", float(pose[4]),
                               f"a pitch within {math.degrees(math.acos(self._recentre_cos)):.1f} deg of level [rad]: "
                               "a scene in rotation charts (scene.rotations = \"charts\") is stepped in its first "
                               "world chart only; the loop (coopctrl run) re-centres it")

    def _checked(self, meas) -> tuple:
        """The measurement's arrays as the compiled step takes them; :class:`MeasurementError` for a field missing
        or of the wrong shape (the values' finiteness is checked in the compiled step)."""
        try:
            q, dq, wrench, pose, twist = meas.q, meas.dq, meas.wrench, meas.object_pose, meas.object_twist
        except AttributeError:
            return self._normalized(meas)
        q_shapes, w_shape, p_shape = self._shapes
        if type(q) is tuple and type(dq) is tuple and len(q) == len(q_shapes) and len(dq) == len(q_shapes):
            for a, b, s in zip(q, dq, q_shapes):
                if not (_ready(a, s) and _ready(b, s)):
                    break
            else:
                if _ready(wrench, w_shape) and _ready(pose, p_shape) and _ready(twist, p_shape):
                    return q, dq, wrench, pose, twist
        return self._normalized(meas)

    def _normalized(self, meas) -> tuple:
        """The measurement's fields converted to float64 arrays, or :class:`MeasurementError` naming the first
        bad one."""
        q_shapes, w_shape, p_shape = self._shapes
        m = len(q_shapes)
        out = []
        for name in _FIELDS:
            value = getattr(meas, name, None)
            per_arm = name in ("q", "dq")
            want = (f"{m} arrays of {', '.join(str(s[0]) for s in q_shapes)} " if per_arm else
                    f"an array of shape {w_shape if name == 'wrench' else p_shape} ") + _WHAT[name]
            if value is None:
                raise MeasurementError(name, "missing", want)
            try:
                if per_arm:
                    if len(value) != m:
                        raise MeasurementError(name, f"{len(value)} arrays", want)
                    arrays = tuple(np.array(v, dtype=float) for v in value)
                else:
                    arrays = np.array(value, dtype=float)
            except (TypeError, ValueError) as exc:
                if isinstance(exc, MeasurementError):
                    raise
                raise MeasurementError(name, f"{type(value).__name__} (not numbers)", want) from None
            if per_arm:
                for i, (a, s) in enumerate(zip(arrays, q_shapes)):
                    if a.shape != s:
                        raise MeasurementError(f"{name}[{i}]", f"an array of shape {a.shape}",
                                               f"shape {s} (arm {self.arm_names[i]!r}) {_WHAT[name]}")
            elif arrays.shape != (w_shape if name == "wrench" else p_shape):
                raise MeasurementError(name, f"an array of shape {arrays.shape}", want)
            out.append(arrays)
        return tuple(out)

    def _event(self, code: int, k: int, args: tuple) -> None:
        """Handle a step that did not end with torques: refuse the measurement, apply the QP's failure policy
        and hold the last split, or raise the stage's event."""
        from coopctrl.loop import run as R
        from coopctrl.loop import tick_codes as K

        stop = self._stop
        if code == K.MEASUREMENT_NOT_FINITE:
            field, i, c = stop.detail
            name = _FIELDS[field]
            a = args[field][i] if field < 2 else args[field]
            where = f"{name}[{i}][{c}]" if field < 2 else (f"{name}[{i}][{c}]" if field == 2 else f"{name}[{c}]")
            value = float(a[c] if field != 2 else a[i, c])
            raise MeasurementError(where, value, f"a finite value: {_WHAT[name]}")
        if code == K.QP_FAILED:  # the load distribution's failure policy, as the loop applies it (may raise)
            R.qp_failure(self._loop, self._cl, self._qa, stop.detail[0], stop.detail[1],
                          SimpleNamespace(ws=self._state.ws, flags=self._state.flags))
            code = self._tick.controller_step(k, True, *args)
            if code == 0:
                return
        raise R.stop_exception(self._loop, self._cl, code, k, stop, self._x_fail, self._traj)

    # ------------------------------------------------------------------ state
    @property
    def state(self) -> ControllerState:
        """A frozen snapshot of everything the controller carries between steps (:class:`ControllerState`)."""
        return ControllerState.of(self._live, self._steps)

    @state.setter
    def state(self, snapshot: ControllerState) -> None:
        self.restore(snapshot)

    def restore(self, snapshot: ControllerState) -> None:
        """Put back a snapshot taken from :attr:`state` of a controller of the same scene: the next steps are
        those that followed it (bit for bit)."""
        if not isinstance(snapshot, ControllerState):
            raise TypeError(f"snapshot = {type(snapshot).__name__}: expected a ControllerState (controller.state)")
        snapshot.copy_into(self._live)
        self._steps = snapshot.steps

    def reset(self) -> None:
        """Back to the state at construction: zero integrals and torques, no split yet, the QP cold."""
        self.restore(self._initial)

    # ------------------------------------------------------------------ helpers
    def measurement(self, x, wrench) -> Measurement:
        """The :class:`Measurement` of the elastic plant's state ``x = (q, Y_0, dq, dY_0)`` (nx,) and the grasp
        wrenches ``wrench`` (m, p) [N, N m] (views of ``x``, no copy)."""
        x = np.ascontiguousarray(x, dtype=float)
        nz, p = self._nz, self.p
        if x.shape != (2 * nz,):
            raise ValueError(f"x has shape {x.shape}: expected ({2 * nz},), the plant state (q, Y_0, dq, dY_0)")
        return Measurement(q=tuple(x[s] for s in self._slices),
                           dq=tuple(x[nz + s.start:nz + s.stop] for s in self._slices),
                           wrench=np.ascontiguousarray(wrench, dtype=float), object_pose=x[nz - p:nz],
                           object_twist=x[2 * nz - p:])

    def __repr__(self) -> str:
        return (f"Controller({self.scenario.name!r}: {len(self.arm_names)} arms, T = {self.control_period:g} s, "
                f"{self._steps} steps)")


__all__ = ["Controller"]
