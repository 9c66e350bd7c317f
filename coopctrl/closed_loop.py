"""The closed loop, wired in one place: plant, sensors, load distribution, leader, followers.

::

        +--------------------------------------------------------------------------+
        |  trajectory(t) --> nominal node motion (148) --> w_N (external load)      |
        |                                                     |                     |
        |  sensors(x) --> q, dq, Y_0, F_meas ----------> QP (G F = w_N, squeeze)    |
        |       ^                 |                           | F*                  |
        |       |                 +--> leader: computed torque on Y_v^N(F*_v)       |
        |       |                 +--> followers: force PI --> computed torque      |
        |       |                                             | tau (ZOH)           |
        |       +------------------ plant: x' = f(t, x, tau) <+  (substeps x h)     |
        +--------------------------------------------------------------------------+

The controller runs at the control period ``T``; the torques are held (zero-order hold) while
the plant is integrated with ``substeps`` fixed steps ``h = T / substeps`` of the chosen
integrator. Divergence (a non-finite state, a deformation beyond ``max_deformation``, an
energy beyond ``max_energy``, or a numerical failure of the plant) stops the run with a
diagnostic naming the time, the quantity and a suggested step; it never runs on silently.
"""

from __future__ import annotations

import math
import time as _time

import numpy as np

from coopctrl.controllers import required_object_wrench
from coopctrl.errors import DivergenceError, InfeasibleLoad
from coopctrl.load_distribution import grasp_matrix, internal_force_basis
from plants.cooperative import ContactPoint, nominal_node_motion
from plants.errors import PlantError
from plants.frames import body_rate_map, rotation_zyx


#: Fraction of each joint torque limit the load-distribution QP may plan with [-].
TORQUE_HEADROOM = 0.9


class ClosedLoop:
    """A fixed-step closed loop over a cooperative plant.

    Args:
        plant: The cooperative plant (simulated, and also the controllers' model).
        trajectory: Object trajectory with ``evaluate(t) -> (Y, dY, ddY)``.
        grasps: (m, p) grasp poses in the object frame, as the controllers know them.
        load_distribution: :class:`~coopctrl.load_distribution.LoadDistribution`.
        compliance: :class:`~coopctrl.controllers.GraspCompliance`.
        leader: :class:`~coopctrl.controllers.LeaderController`.
        followers: Mapping arm index -> :class:`~coopctrl.controllers.FollowerForceController`.
        sensors: :class:`~coopctrl.sensors.SensorSuite`.
        integrator: A fixed-step integrator (``step(f, t, x, u, h)``).
        control_period: ``T`` [s]; substeps: integration steps per period.
        squeeze_desired: (n_pairs,) desired virtual-linkage squeeze [N].
        max_deformation: Divergence bound on any node's displacement from its rigid pose [m].
        max_energy: Optional bound on the total energy [J].
    """

    def __init__(self, plant, trajectory, grasps, load_distribution, compliance, leader, followers, sensors,
                 integrator, control_period: float, substeps: int, squeeze_desired, max_deformation: float,
                 max_energy: float | None = None, torque_limits: bool = False, name: str = "scenario",
                 enabled: bool = True):
        self.plant = plant
        self.trajectory = trajectory
        self.grasps = np.asarray(grasps, dtype=float)
        self.ld = load_distribution
        self.compliance = compliance
        self.leader = leader
        self.followers = dict(followers)
        self.sensors = sensors
        self.integrator = integrator
        self.T = float(control_period)
        self.substeps = int(substeps)
        self.h = self.T / self.substeps
        self.squeeze_desired = np.asarray(squeeze_desired, dtype=float)
        self.max_deformation = float(max_deformation)
        self.max_energy = max_energy
        self.torque_limits = bool(torque_limits)
        self.name = name
        self.enabled = bool(enabled)
        self.space = plant.space
        self.npos = 3 if self.space == "spatial" else 2
        el = plant.elastic
        self.object_mass = float(el.node_params[0, 0])
        self.object_inertia = el.node_params[0, 1:].copy()
        self.gravity = el.gravity.copy()
        self.tau_max = np.concatenate([np.asarray(a.tau_max, dtype=float) for a in plant.arms])
        #: The QP plans torques within ``TORQUE_HEADROOM`` of each limit, leaving the rest for
        #: the feedback terms; the applied torques are saturated at the limit (actuators).
        self._qp_tau_max = [TORQUE_HEADROOM * np.asarray(a.tau_max, dtype=float) for a in plant.arms]
        self._x_ref = None
        self._omega_cache = None
        Yr = el.Y_ref
        self._rho = np.array([self._to_object_frame(Yr[0], Yr[i + 1, :self.npos] - Yr[0, :self.npos])
                              for i in range(plant.arm_count)])

    # ------------------------------------------------------------------ helpers
    def _to_object_frame(self, Y0, d):
        if self.space == "spatial":
            return rotation_zyx(Y0[3:6]).T @ d
        c, s = math.cos(Y0[2]), math.sin(Y0[2])
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def _deformation(self, Y) -> tuple[float, int]:
        """Largest displacement [m] of a contact node from its rigid place on the object, and which."""
        worst, which = 0.0, 0
        for i in range(self.plant.arm_count):
            d = self._to_object_frame(Y[0], Y[i + 1, :self.npos] - Y[0, :self.npos]) - self._rho[i]
            v = float(np.sqrt(d @ d))
            if not v <= worst:  # also catches nan
                worst, which = v, i
        return worst, which

    def omega_max(self, x=None) -> float:
        """Highest mode [rad/s] of the plant linearized at ``x`` (default: the state the last run
        started from; before any run, the unloaded state): ``max |eig(df/dx)|``.

        The arms' inertia is included, so this is the frequency the integrator actually meets.
        """
        if x is None:
            x = self._x_ref
        if self._omega_cache is not None and self._omega_cache[0] is x:
            return self._omega_cache[1]
        A, _ = self.plant.jacobians(x, np.zeros(self.plant.input_size))
        w = float(np.max(np.abs(np.linalg.eigvals(A))))
        self._omega_cache = (x, w)
        return w

    def suggested_step(self) -> float:
        """A step [s] the chosen integrator should survive: half its predicted limit at ``omega_max``."""
        w = self.omega_max()
        limit = self.integrator.predicted_max_step(w) if w > 0 else math.inf
        if limit == 0.0 or not math.isfinite(limit):
            limit = 2.0 * math.sqrt(2.0) / w if w > 0 else self.h  # RK4's limit as a reference
        return 0.5 * min(limit, self.h * 10)

    def _step_hint(self):
        """A suggested step when the step is beyond the predicted stability limit, else None."""
        return None if self.numerically_stable_step() else self.suggested_step()

    def numerically_stable_step(self) -> bool:
        """True if the integration step is within the chosen integrator's predicted limit."""
        w = self.omega_max()
        return w == 0 or self.h <= self.integrator.predicted_max_step(w)

    def diagnose(self, x) -> str:
        """Why a run at state ``x`` (the loaded start) cannot stay bounded, if the physics says so.

        Checks the object's stiffness with the contact nodes held (:meth:`ElasticSystem.node_stiffness`):
        a negative eigenvalue is a static instability of the grasp, whatever the step.
        """
        Y = self.plant.node_poses(x)
        K0 = self.plant.elastic.node_stiffness(Y, 0)
        npos = self.npos
        ev, vec = np.linalg.eigh(K0[:npos, :npos])
        if ev[0] < 0:
            d = vec[:, 0] * np.sign(vec[np.argmax(np.abs(vec[:, 0])), 0])
            axes = "xyz" if npos == 3 else "xz"
            direction = ", ".join(f"{c}: {v:+.2f}" for c, v in zip(axes, d))
            return (f"the grasp is statically unstable: the object's translational stiffness has a negative "
                    f"eigenvalue {ev[0]:.4g} N/m along ({direction}); central springs carry lateral load only "
                    "through tension and squeeze makes their lateral stiffness negative, so the object buckles out "
                    "of the grasp line (MODEL.md s.3). Use element = \"offset\" (shear stiffness) or less squeeze")
        return ""

    def _torque_model(self, terms, ddYn):
        """QP torque-limit rows: ``tau_i = Jg_i^T F_i + bias_i`` with the nominal node accelerations."""
        jac, bias = [], []
        for i, arm in enumerate(self.plant.arms):
            k = i + 1
            n = arm.dof
            if isinstance(arm, ContactPoint):
                jac.append(np.eye(self.plant.p))
                bias.append(terms.W[k] @ ddYn[k] + terms.w_free[k])
                continue
            J = terms.J[i, :, :n]
            if self.space == "spatial":
                Ai = terms.Y[k, 3:6]
                Jg = J.copy()
                Jg[3:] = rotation_zyx(Ai) @ body_rate_map(Ai) @ J[3:]
            else:
                Jg = J
            try:
                qdd = np.linalg.solve(J, ddYn[k] - terms.Jdq[i]) if J.shape[0] == n else np.linalg.lstsq(
                    J, ddYn[k] - terms.Jdq[i], rcond=None)[0]
            except np.linalg.LinAlgError:
                qdd = np.zeros(n)
            jac.append(Jg)
            bias.append(terms.H[i, :n, :n] @ qdd + terms.h[i, :n] + J.T @ (terms.W[k] @ ddYn[k] + terms.w_free[k]))
        return jac, bias

    def _normals(self, terms):
        """Inward contact normals: each node's approach axis (its frame's x axis)."""
        Y = terms.Y
        out = np.empty((self.plant.arm_count, self.npos))
        for i in range(self.plant.arm_count):
            if self.space == "spatial":
                out[i] = rotation_zyx(Y[i + 1, 3:6])[:, 0]
            else:
                out[i] = (math.cos(Y[i + 1, 2]), math.sin(Y[i + 1, 2]))
        return out

    def loaded_state(self, x_unloaded) -> np.ndarray:
        """The loaded state at rest at t = 0, as the controllers plan it.

        The object is on its nominal pose; each contact node is at the pose that makes its
        interconnection carry the QP split of t = 0 (with the desired squeeze); each arm reaches
        its node by inverse kinematics (seeded with the unloaded configuration).
        """
        plant = self.plant
        p, npos, m = plant.p, self.npos, plant.arm_count
        Y0N, dY0N, ddY0N = self.trajectory.evaluate(0.0)
        Yn = nominal_node_motion(Y0N, dY0N, ddY0N, self.grasps, self.space)[0]
        w_N = required_object_wrench(self.space, self.object_mass, self.object_inertia, self.gravity, Y0N, dY0N, ddY0N)
        from coopctrl.load_distribution import LoadDistribution

        ld = LoadDistribution(self.ld.config, self.space, m)
        terms = plant.control_terms(x_unloaded)
        kwargs = {}
        if self.ld.config.min_grip is not None or self.ld.config.friction_coefficient is not None:
            kwargs["normals"] = self._normals(terms)
        if self.torque_limits:
            kwargs["jacobians"], kwargs["biases"] = self._torque_model(terms, np.zeros((m + 1, p)))
            kwargs["tau_max"] = self._qp_tau_max
        if self.ld.config.split == "elastic":
            kwargs["K"] = self.compliance.stiffness_world(Y0N)
        F = ld.solve(Yn[1:, :npos], Y0N[:npos], w_N, **kwargs).F
        x = np.array(x_unloaded, dtype=float)
        nz = plant.nz
        x[nz:] = 0.0
        x[nz - p:nz] = Y0N
        for i, arm in enumerate(plant.arms):
            Yi = self.compliance.deformation(i, F[i], Y0N, Yn[i + 1])
            sl = plant.q_slice(i)
            x[sl] = arm.inverse_kinematics(Yi, x_unloaded[sl]) if not isinstance(arm, ContactPoint) else Yi
        return x

    # ------------------------------------------------------------------ the loop
    def run(self, x0, duration: float, progress: bool = False) -> dict:
        """Simulate ``duration`` [s] from ``x0``; returns the recorded arrays and the run status."""
        plant = self.plant
        m, p = plant.arm_count, plant.p
        n_ticks = int(round(duration / self.T))
        nx, nu = plant.state_size, plant.input_size
        N = n_ticks + 1
        rec = self.empty_record(N)
        return self._run(rec, x0, N, progress)

    def empty_record(self, N: int = 0) -> dict:
        """The arrays a run records, for ``N`` samples (NaN-filled; a run truncates them)."""
        plant = self.plant
        m, p = plant.arm_count, plant.p
        nx, nu = plant.state_size, plant.input_size
        return {
            "t": np.full(N, np.nan), "x": np.full((N, nx), np.nan), "tau": np.full((N, nu), np.nan),
            "Y0_nominal": np.full((N, p), np.nan), "F_measured": np.full((N, m, p), np.nan),
            "F_commanded": np.full((N, m, p), np.nan), "F_external": np.full((N, m, p), np.nan),
            "F_internal": np.full((N, m, p), np.nan), "r_contacts": np.full((N, m, self.npos), np.nan),
            "qp_status": [], "qp_iterations": np.full(N, -1, dtype=np.int64), "qp_solve_time_s": np.full(N, np.nan),
            "status": "ok", "reason": "", "events": [], "wall_time_s": 0.0, "qp_time_s": 0.0,
            "qp_binding_counts": {}, "saturated_ticks": 0,
            "energy": np.full(N, np.nan), "kinetic_energy": np.full(N, np.nan),
        }

    def _run(self, rec, x0, N, progress):
        plant = self.plant
        m, p = plant.arm_count, plant.p
        nu = plant.input_size
        events: list[tuple[float, str, str]] = []
        status, reason = "ok", ""
        x = np.array(x0, dtype=float)
        self._x_ref = x.copy()
        q_slices = [plant.q_slice(i) for i in range(m)]
        nz = plant.nz
        rhs = plant.rhs
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=n_ticks, unit="tick", desc=self.name, leave=False, mininterval=0.2)
        tau = np.zeros(nu)
        k_done = 0
        state_exact = self.sensors.joints.config.is_exact and self.sensors.object.config.is_exact
        wall0 = _time.perf_counter()
        qp_time = 0.0
        saturated = 0
        binding_counts: dict[str, int] = {}
        try:
            for k in range(N):
                t = k * self.T
                # ---- sensors
                true_terms = plant.control_terms(x)
                if state_exact:
                    terms = true_terms
                else:
                    xm = x.copy()
                    for i in range(m):
                        xm[q_slices[i]], xm[nz:][q_slices[i]] = self.sensors.read_joints(x[q_slices[i]], x[nz:][q_slices[i]])
                    xm[nz - p:nz], xm[2 * nz - p:] = self.sensors.read_object(x[nz - p:nz], x[2 * nz - p:])
                    terms = plant.control_terms(xm)
                F_meas = self.sensors.read_forces(true_terms.Fw)
                # ---- divergence checks on the state we are at
                if not np.all(np.isfinite(x)):
                    raise DivergenceError(t, "state (non-finite)", float("nan"), self._step_hint())
                dmax, which = self._deformation(true_terms.Y)
                if dmax > self.max_deformation:
                    raise DivergenceError(t, f"deformation of contact {which} [m]", dmax, self._step_hint())
                if self.max_energy is not None:
                    E = plant.energy(x)
                    if not abs(E) <= self.max_energy:
                        raise DivergenceError(t, "energy [J]", E, self._step_hint())
                # ---- nominal motion and load
                Y0N, dY0N, ddY0N = self.trajectory.evaluate(t)
                if not self.enabled:  # passive run: no QP, no torques; the energy is recorded
                    rec["t"][k], rec["x"][k], rec["tau"][k], rec["Y0_nominal"][k] = t, x, tau, Y0N
                    rec["F_measured"][k] = F_meas
                    rec["r_contacts"][k] = true_terms.Y[1:, :self.npos]
                    rec["energy"][k] = plant.energy(x)
                    rec["kinetic_energy"][k] = plant.kinetic_energy(x)
                    k_done = k + 1
                    if k == N - 1:
                        break
                    for s in range(self.substeps):
                        x = self.integrator.step(rhs, t + s * self.h, x, tau, self.h)
                    continue
                Yn, dYn, ddYn = nominal_node_motion(Y0N, dY0N, ddY0N, self.grasps, self.space)
                w_N = required_object_wrench(self.space, self.object_mass, self.object_inertia, self.gravity,
                                             Y0N, dY0N, ddY0N)
                kwargs = {}
                if self.ld.config.min_grip is not None or self.ld.config.friction_coefficient is not None:
                    kwargs["normals"] = self._normals(terms)
                if self.torque_limits:
                    kwargs["jacobians"], kwargs["biases"] = self._torque_model(terms, ddYn)
                    kwargs["tau_max"] = self._qp_tau_max
                if self.ld.config.split == "elastic":
                    kwargs["K"] = self.compliance.stiffness_world(Y0N)
                q0 = _time.perf_counter()
                split = self.ld.solve(terms.Y[1:, :self.npos], terms.Y[0, :self.npos], w_N, **kwargs)
                qp_time += _time.perf_counter() - q0
                if split.held:
                    events.append((t, "qp_held", f"QP status '{split.status}' (binding: {', '.join(split.binding) or '-'}); "
                                                 "holding the last feasible split"))
                F_set = split.F
                for fam in split.binding:
                    binding_counts[fam] = binding_counts.get(fam, 0) + 1
                # ---- controllers
                Yv = self.compliance.deformation(self.leader.index, F_set[self.leader.index], Y0N, Yn[self.leader.index + 1])
                tau[q_slices[self.leader.index]] = self.leader.torque(terms, Yv, dYn[self.leader.index + 1],
                                                                     ddYn[self.leader.index + 1])
                for i, ctrl in self.followers.items():
                    tau[q_slices[i]] = ctrl.torque(terms, F_set[i], F_meas[i], Yn[i + 1], dYn[i + 1], ddYn[i + 1],
                                                   Y0N, self.T)
                # ---- actuator saturation
                if np.any(np.abs(tau) > self.tau_max):
                    saturated += 1
                    np.clip(tau, -self.tau_max, self.tau_max, out=tau)
                # ---- record
                rec["t"][k] = t
                rec["x"][k] = x
                rec["tau"][k] = tau
                rec["Y0_nominal"][k] = Y0N
                rec["F_measured"][k] = F_meas
                rec["F_commanded"][k] = F_set
                rec["F_external"][k] = split.external
                rec["F_internal"][k] = split.internal
                rec["r_contacts"][k] = true_terms.Y[1:, :self.npos]
                rec["qp_status"].append(split.status)
                rec["qp_iterations"][k] = split.iterations
                rec["qp_solve_time_s"][k] = split.solve_time_s
                k_done = k + 1
                if k == N - 1:
                    break
                # ---- plant, zero-order hold over the period
                for s in range(self.substeps):
                    x = self.integrator.step(rhs, t + s * self.h, x, tau, self.h)
                if bar is not None and k % 50 == 0:
                    bar.update(50)
        except DivergenceError as exc:
            status, reason = "diverged", str(exc)
            why = self.diagnose(np.asarray(x0, dtype=float))
            if why:
                reason = f"{reason}: {why}"
            events.append((exc.time, "diverged", reason))
        except InfeasibleLoad as exc:
            status, reason = "qp_failed", str(exc)
            events.append((k * self.T, "qp_failed", str(exc)))
        except PlantError as exc:
            t_fail = k * self.T
            status = "diverged"
            reason = f"at t = {t_fail:.6g} s: {exc}; suggested step {self.suggested_step():.3g} s"
            events.append((t_fail, "diverged", reason))
        finally:
            if bar is not None:
                bar.close()
        wall = _time.perf_counter() - wall0
        for key, val in rec.items():
            if isinstance(val, np.ndarray):
                rec[key] = val[:k_done]
        if saturated:
            events.append((0.0, "torque_saturation", f"commanded torques clipped at their limits on {saturated} ticks"))
        rec.update(status=status, reason=reason, events=events, wall_time_s=wall, qp_time_s=qp_time,
                   qp_binding_counts=binding_counts, saturated_ticks=saturated)
        return rec

    # ------------------------------------------------------------------ post-processing
    def squeeze_of(self, F, r_contacts, r_object) -> np.ndarray:
        """Virtual-linkage squeeze [N] of the internal part of contact wrenches ``F`` (m, p).

        The internal part is ``F - G^+ G F`` (the Moore-Penrose split of the same resultant),
        decomposed on the virtual-linkage basis by least squares.
        """
        G = grasp_matrix(r_contacts, r_object, self.space)
        f = F.reshape(-1)
        f_int = f - np.linalg.pinv(G) @ (G @ f)
        E = internal_force_basis(r_contacts, self.space)
        return np.linalg.lstsq(E, f_int, rcond=None)[0]
