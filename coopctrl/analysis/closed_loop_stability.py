"""The largest stable plant step of the closed loop that actually runs: its one-period map,
linearized, and the spectral radius of that map as a function of the step ``h``.

One control period of :class:`~coopctrl.closed_loop.ClosedLoop` takes the loop state
``s_k = (x_k, I_k)`` (the plant state and the followers' force-error integrals ``I`` [N s]) to
``s_{k+1}``: the controller (sensors, QP, leader, followers) computes ``tau_k`` at ``t_k`` and
updates ``I``; the torques are held (ZOH) while the plant is integrated over the period with the
chosen scheme, ``n = floor(T / h)`` steps of ``h`` and a remainder step (or ``n`` uniform steps for
a scheme whose steps do not commute; :meth:`ClosedLoop.set_step`). Linearized about ``(s_k, t_k)``:

.. math::
    \\tau_k = K_x\\, x_k + K_I\\, I_k, \\qquad I_{k+1} = E_x\\, x_k + E_I\\, I_k

    x_{k+1} = P_x(h)\\, x_k + P_u(h)\\, \\tau_k, \\qquad
    \\begin{bmatrix} P_x & P_u \\\\ 0 & 1 \\end{bmatrix}
    = G_r \\, G_h^{\\,n}, \\quad
    G_h = \\begin{bmatrix} M(h) & N(h) \\\\ 0 & 1 \\end{bmatrix}

    \\Phi(h) = \\begin{bmatrix} P_x + P_u K_x & P_u K_I \\\\ E_x & E_I \\end{bmatrix}

``K_x, K_I, E_x, E_I`` are central differences of the loop's own controller code (one tick of
``ClosedLoop.run`` at ``t_k``, exact sensors, the trajectory shifted to ``t_k``); ``M(h), N(h)``
are one step of the scheme on the plant linearized at ``(x_k, tau_k)``, ``dx/dt = A x + B tau``
(:meth:`CooperativePlant.jacobians`; :meth:`LoopLinearization.step_matrices`). The period map is
stable at ``h`` when no more of its eigenvalues lie outside the unit circle (by
:data:`GROWTH_TOLERANCE`) than at a step ``h_0`` far below every limit (none for a loop that holds;
a physically unstable loop, a buckling grasp, keeps its growing modes at every step, which no step
cures). The predicted limit is the first ``h`` on a log grid up to ``T``
where it is not, refined by bisection to :data:`RESOLUTION`; ``math.inf`` when ``h = T`` is stable
(the loop cannot step longer than ``T``).

Along the nominal trajectory the loop is linearized at the start state and at
:data:`TRAJECTORY_SAMPLES` instants of a nominal run (RK4 at a small step, exact sensors; the
integrals rebuilt from its recorded force errors, their anti-windup clip ignored), and the
predicted limit is the smallest over them (frozen-time analysis: each instant's map as if it held).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.integrators import get_integrator

#: Relative resolution of the bisection on the predicted limit [-].
RESOLUTION = 1e-3
#: An eigenvalue ``|mu| <= 1 + GROWTH_TOLERANCE`` of the period map counts as stable [-]: above the
#: finite-difference noise of the controller Jacobian (~1e-7), far below the growth per period of a
#: numerically unstable step (a mode crossing the unit circle grows by ``1 + c (h / h* - 1)``, ``c`` of
#: order one, so the bisection still resolves the crossing to ~1e-4).
GROWTH_TOLERANCE = 1e-5
#: Points of the log grid scanned from ``h_0`` to ``T`` before the bisection [-].
GRID_POINTS = 48
#: Instants along the nominal trajectory at which the loop is also linearized [-].
TRAJECTORY_SAMPLES = 6
#: Rise [-] of an eigenvalue's modulus over the tiny-step period map's beyond which the step counts as
#: destabilizing that mode (:meth:`ModeProbe.mode`): above the finite-difference noise of the map (~1e-7),
#: far below the rise a step near its limit gives the limiting mode (to ``|mu| = 1``, typically 1e-2 and more).
MOVED = 1e-4
#: Central-difference steps: plant state (relative to ``max(1, |x|)``) [m, rad, m/s, rad/s], integrals [N s].
STEP_STATE = 1e-6
STEP_INTEGRAL = 1e-6


class _ShiftedTrajectory:
    """A trajectory read ``t0`` [s] later: ``evaluate(t) = inner.evaluate(t + t0)`` (``sample`` and, for a path
    on the rotations, ``sample_rotation`` likewise);
    its via ``times`` are the inner ones less ``t0``, its ``poses`` the inner ones (the same path, which the
    loop checks against the Euler-angle band when it is built)."""

    def __init__(self, inner, t0: float):
        self.inner = inner
        self.t0 = float(t0)
        self.times = np.asarray(inner.times, dtype=float) - self.t0
        self.poses = inner.poses
        if hasattr(inner, "sample_rotation"):  # a path on the rotations: the loop in charts reads them
            self.sample_rotation = lambda t: inner.sample_rotation(np.asarray(t, dtype=float) + self.t0)

    def evaluate(self, t):
        return self.inner.evaluate(t + self.t0)

    def sample(self, t):
        return self.inner.sample(np.asarray(t, dtype=float) + self.t0)


def _exact_sensors(scenario):
    from coopctrl.scenario import SensorsConfig

    return dataclasses.replace(scenario, sensors=SensorsConfig())


@dataclass(frozen=True, eq=False)
class LoopLinearization:
    """The closed loop linearized about ``(x, I)`` at ``t`` (module docstring).

    Attributes:
        t: Time of the linearization [s].
        x: Plant state; ``integral`` the stacked force-error integrals [N s] of the followers with a force loop.
        tau: Torques the controller commands there [N m].
        A, B: Plant Jacobians ``df/dx`` [1/s, ...], ``df/dtau``.
        Kx, KI: Controller Jacobians ``dtau/dx``, ``dtau/dI``.
        Ex, EI: Integral update Jacobians ``dI'/dx``, ``dI'/dI``.
        control_period: ``T`` [s].
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    t: float
    x: np.ndarray
    integral: np.ndarray
    tau: np.ndarray
    A: np.ndarray
    B: np.ndarray
    Kx: np.ndarray
    KI: np.ndarray
    Ex: np.ndarray
    EI: np.ndarray
    control_period: float

    def step_matrices(self, scheme, h: float) -> tuple[np.ndarray, np.ndarray]:
        """``(M, N)`` of one step ``h`` [s] of ``scheme`` on ``dx/dt = A x + B tau`` (tau held):
        ``x' = M x + N tau``.

        A Runge-Kutta scheme is a function of ``Z = h A_u``, ``A_u = [[A, B], [0, 0]]`` (the held input
        as a state with zero rate): its stability polynomial for an explicit scheme, and stage by stage for
        a diagonally implicit one, ``(I - gamma Z) K_i = A_u (I + h sum_{j<i} a_ij K_j)``,
        ``G = I + h sum_i b_i K_i`` (what its Newton iteration converges to on a linear system). Any other
        scheme (symplectic Euler) is :meth:`Integrator.step` applied to the columns of the identity.
        """
        A, B = self.A, self.B
        nx, nu = B.shape
        n = nx + nu
        Au = np.zeros((n, n))
        Au[:nx, :nx], Au[:nx, nx:] = A, B
        h = float(h)
        tableau = getattr(scheme, "tableau", ())
        if tableau:
            gamma = tableau[0][0]
            lhs = np.eye(n) - gamma * h * Au
            K = []
            for i, row in enumerate(tableau):
                acc = np.eye(n)
                for j in range(i):
                    acc = acc + h * row[j] * K[j]
                K.append(np.linalg.solve(lhs, Au @ acc))
            G = np.eye(n) + h * sum(b * k for b, k in zip(scheme.weights, K))
            return G[:nx, :nx], G[:nx, nx:]
        if scheme.stability_polynomial is not None:
            Z = h * Au
            G = np.zeros((n, n))
            for c in reversed(scheme.stability_polynomial):  # Horner
                G = G @ Z + c * np.eye(n)
            return G[:nx, :nx], G[:nx, nx:]
        f = lambda t, x, u: A @ x + B @ u  # noqa: E731 - a new array per call, as step() requires
        M = np.empty((nx, nx))
        N = np.empty((nx, nu))
        zu, zx = np.zeros(nu), np.zeros(nx)
        for j in range(nx):
            e = np.zeros(nx)
            e[j] = 1.0
            scheme.reset()
            M[:, j] = scheme.step(f, 0.0, e, zu, h)
        for j in range(nu):
            e = np.zeros(nu)
            e[j] = 1.0
            scheme.reset()
            N[:, j] = scheme.step(f, 0.0, zx, e, h)
        scheme.reset()
        return M, N

    def period_matrix(self, scheme, steps) -> np.ndarray:
        """``Phi`` of one control period made of the plant steps ``steps`` [s] (equal ones first)."""
        nx, nu = self.B.shape
        G = np.eye(nx + nu)
        cache: dict[float, np.ndarray] = {}
        runs: list[tuple[float, int]] = []
        for hs in steps:
            if runs and runs[-1][0] == hs:
                runs[-1] = (hs, runs[-1][1] + 1)
            else:
                runs.append((hs, 1))
        for hs, count in runs:
            Gh = cache.get(hs)
            if Gh is None:
                M, N = self.step_matrices(scheme, hs)
                Gh = np.eye(nx + nu)
                Gh[:nx, :nx], Gh[:nx, nx:] = M, N
                cache[hs] = Gh
            G = np.linalg.matrix_power(Gh, count) @ G
        Px, Pu = G[:nx, :nx], G[:nx, nx:]
        ni = self.EI.shape[0]
        Phi = np.empty((nx + ni, nx + ni))
        Phi[:nx, :nx] = Px + Pu @ self.Kx
        Phi[:nx, nx:] = Pu @ self.KI
        Phi[nx:, :nx] = self.Ex
        Phi[nx:, nx:] = self.EI
        return Phi

    def eigenvalues(self, scheme, h: float) -> np.ndarray:
        """Eigenvalues of ``Phi(h)`` with the period split as the loop splits it (:func:`period_steps`)."""
        M = self.period_matrix(scheme, period_steps(scheme, h, self.control_period))
        if not np.all(np.isfinite(M)):
            return np.array([np.inf])
        return np.linalg.eigvals(M)

    def spectral_radius(self, scheme, h: float) -> float:
        """``rho(Phi(h))`` [-]."""
        return float(np.max(np.abs(self.eigenvalues(scheme, h))))

    def unstable_count(self, scheme, h: float) -> int:
        """Number of eigenvalues of ``Phi(h)`` outside the unit circle by more than :data:`GROWTH_TOLERANCE`."""
        return int(np.sum(np.abs(self.eigenvalues(scheme, h)) > 1.0 + GROWTH_TOLERANCE))

    def max_stable_step(self, scheme, resolution: float = RESOLUTION) -> tuple[float, float]:
        """``(h*, rho_0)``: the largest step [s] with every smaller one stable (module docstring;
        ``math.inf`` when ``T`` is stable) and the loop's own spectral radius ``rho_0`` [-] at ``h_0``.
        A step is stable when ``Phi(h)`` has no more eigenvalues outside the unit circle than
        ``Phi(h_0)``: a physically unstable loop (a buckling grasp) keeps its growing modes at every step,
        which no step cures and which do not limit it. For a scheme whose steps do not commute (symplectic
        Euler) the steps taken are ``T / n`` (:func:`period_steps`), and ``h*`` is the largest stable one."""
        T = self.control_period
        lam = np.linalg.eigvals(self.A)
        fastest = float(np.max(np.abs(lam))) if lam.size else 0.0
        h0 = min(T, 1e-2 / fastest) if fastest > 0 else T
        mu0 = self.eigenvalues(scheme, h0)
        rho0 = float(np.max(np.abs(mu0)))
        allowed = int(np.sum(np.abs(mu0) > 1.0 + GROWTH_TOLERANCE))
        stable = lambda h: self.unstable_count(scheme, h) <= allowed  # noqa: E731
        if h0 >= T:
            return math.inf, rho0
        grid = np.geomspace(h0, T, GRID_POINTS)
        lo = h0
        for h in grid[1:]:
            if stable(h):
                lo = float(h)
                continue
            hi = float(h)
            while hi / lo - 1.0 > resolution:
                mid = math.sqrt(lo * hi)
                if stable(mid):
                    lo = mid
                else:
                    hi = mid
            return max(period_steps(scheme, lo, T)), rho0  # the step taken (T / n for a non-commuting scheme)
        return math.inf, rho0


def period_steps(scheme, h: float, control_period: float) -> tuple[float, ...]:
    """The plant steps [s] of one period at a trial step ``h`` as the stability trials take them
    (:func:`coopctrl.analysis.stability.effective_step`; :meth:`ClosedLoop.set_step`)."""
    from coopctrl.analysis.stability import commutes

    T = control_period
    h = min(float(h), T)
    if not commutes(scheme):
        n = max(1, int(math.ceil(T / h * (1.0 - 1e-12))))
        return (T / n,) * n
    n = max(1, int(math.floor(T / h * (1.0 + 1e-12))))
    rest = T - n * h
    return (h,) * n + ((rest,) if rest > 1e-9 * T else ())


class LoopLinearizer:
    """Linearizes a scenario's closed loop (exact sensors) at any ``(x, I, t)``.

    Args:
        scenario: A :class:`~coopctrl.scenario.Scenario`.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    def __init__(self, scenario):
        from coopctrl.wiring import closed_loop

        self.scenario = scenario
        self._exact = _exact_sensors(scenario)
        # a tick that fails here is only refused (ArithmeticError): the loop's own reason, never the
        # closed-loop diagnosis (coopctrl.analysis.diagnosis, which runs in simulate and linearizes too)
        self.loop = closed_loop(self._exact)
        self._at = (None, None)  # (t, the loop on the trajectory read from t): built once per instant
        self.trajectory = self.loop.trajectory
        self.plant = self.loop.plant
        self.T = self.loop.T
        self.pi = [i for i in sorted(self.loop.followers) if getattr(self.loop.followers[i], "force_loop", False)
                   and (self.loop.followers[i].kp != 0 or self.loop.followers[i].ki != 0)]
        self.p = self.plant.p

    @property
    def integral_size(self) -> int:
        return self.p * len(self.pi)

    def controller(self, x, integral, t: float) -> tuple[np.ndarray, np.ndarray]:
        """``(tau, I')``: one tick of the loop's controller at ``(x, I)`` and time ``t`` [s]: a run of no
        duration of the scenario's loop built on its trajectory read from ``t``
        (:func:`~coopctrl.wiring.closed_loop` with ``trajectory``), ``I`` its followers' starting integrals
        and ``I'`` their integrals at the end of the run."""
        p = self.p
        loop = self._loop_at(t)
        # the integrals enter as the run's starting loop state (a run starts from a fresh LoopState)
        start = {i: integral[p * k:p * (k + 1)] for k, i in enumerate(self.pi)}
        rec = loop.run(np.asarray(x, dtype=float), 0.0, integrals=start)
        if rec["status"] != "ok":
            raise ArithmeticError(f"the controller failed at t = {t:.6g} s: {rec['reason']}")
        if not self.pi:
            return rec["tau"][0].copy(), np.zeros(0)
        final = rec["final_state"]  # the followers' integrals at the end of the run, (m, p) [N s, N m s]
        new = np.concatenate([np.asarray(final.integrals[i], dtype=float) for i in self.pi])
        return rec["tau"][0].copy(), new

    def _loop_at(self, t: float):
        """The scenario's loop (exact sensors) on its trajectory read from ``t`` [s], built once per instant
        (a linearization asks for one instant many times)."""
        from coopctrl.wiring import closed_loop

        t = float(t)
        if self._at[0] != t:
            self._at = (t, closed_loop(self._exact, trajectory=_ShiftedTrajectory(self.trajectory, t)))
        return self._at[1]

    def linearize(self, x, integral=None, t: float = 0.0) -> LoopLinearization:
        """:class:`LoopLinearization` about ``(x, I)`` at ``t`` [s] (``I`` default 0)."""
        x = np.asarray(x, dtype=float)
        ni = self.integral_size
        integral = np.zeros(ni) if integral is None else np.asarray(integral, dtype=float)
        nx = x.size
        tau, _ = self.controller(x, integral, t)
        nu = tau.size
        Kx, Ex = np.empty((nu, nx)), np.empty((ni, nx))
        KI, EI = np.empty((nu, ni)), np.empty((ni, ni))
        for k in range(nx):
            d = STEP_STATE * max(1.0, abs(x[k]))
            xp, xm = x.copy(), x.copy()
            xp[k] += d
            xm[k] -= d
            (tp, ip), (tm, im) = self.controller(xp, integral, t), self.controller(xm, integral, t)
            Kx[:, k] = (tp - tm) / (2 * d)
            Ex[:, k] = (ip - im) / (2 * d)
        for k in range(ni):
            d = STEP_INTEGRAL * max(1.0, abs(integral[k]))
            ip_, im_ = integral.copy(), integral.copy()
            ip_[k] += d
            im_[k] -= d
            (tp, ip), (tm, im) = self.controller(x, ip_, t), self.controller(x, im_, t)
            KI[:, k] = (tp - tm) / (2 * d)
            EI[:, k] = (ip - im) / (2 * d)
        A, B = self.plant.jacobians(x, tau)
        return LoopLinearization(t=float(t), x=x.copy(), integral=integral.copy(), tau=tau, A=A, B=B, Kx=Kx, KI=KI,
                                 Ex=Ex, EI=EI, control_period=self.T)

    def integrals_of(self, rec: dict) -> np.ndarray:
        """``I_k`` [N s] entering each recorded tick: ``T sum_{j<k} (F*_j - F_meas_j)`` (the clip ignored)."""
        n = len(rec["t"])
        ni = self.integral_size
        out = np.zeros((n, ni))
        if not ni or n == 0:
            return out
        e = np.concatenate([rec["F_commanded"][:, i, :] - rec["F_measured"][:, i, :] for i in self.pi], axis=1)
        out[1:] = np.cumsum(e[:-1] * self.T, axis=0)
        return out


@dataclass(frozen=True)
class ClosedLoopLimit:
    """The closed loop's predicted largest stable step for one integrator.

    Attributes:
        integrator: Registry name.
        max_step_s: Smallest limit over the linearization instants [s]; ``math.inf`` when ``h = T`` is
            stable at all of them (the loop cannot step longer than ``T``).
        at_time_s: The instant [s] that sets it (``nan`` when none does).
        start_max_step_s: The limit at the start state alone [s].
        loop_spectral_radius: ``rho_0`` [-] at that instant (below 1: the loop decays at a small step).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    integrator: str
    max_step_s: float
    at_time_s: float
    start_max_step_s: float
    loop_spectral_radius: float


def nominal_run(scenario, x0, duration: float | None = None) -> dict:
    """The loop with exact sensors and RK4 at a step well inside its open-loop limit, from ``x0``."""
    from coopctrl.integrators.modes import linear_modes
    from coopctrl.scenario.build import build_plant
    from coopctrl.wiring import closed_loop

    rk4 = get_integrator("rk4")
    exact = _exact_sensors(scenario)
    T = scenario.simulation.control_period
    limit = linear_modes(build_plant(exact), x0).predicted_max_step(rk4)
    loop = closed_loop(exact, integrator=rk4, step=min(T, 0.25 * limit) if 0.0 < limit < math.inf else T)
    return loop.run(np.asarray(x0, dtype=float), scenario.simulation.duration if duration is None else duration)


def linearizations(scenario, x0, samples: int = TRAJECTORY_SAMPLES, record: dict | None = None,
                   progress=None) -> list[LoopLinearization]:
    """The loop linearized at the start ``x0`` (``t = 0``, ``I = 0``) and at ``samples`` instants of a
    nominal run (``record``, default :func:`nominal_run`), evenly spread over it."""
    lin = LoopLinearizer(scenario)
    out = [lin.linearize(x0, None, 0.0)]
    if progress:
        progress("linearized the closed loop at t = 0")
    if samples <= 0:
        return out
    rec = nominal_run(scenario, x0) if record is None else record
    n = len(rec["t"])
    if n < 2:
        return out
    integrals = lin.integrals_of(rec)
    for k in sorted(set(np.linspace(0, n - 1, samples + 1).round().astype(int)[1:].tolist())):
        try:
            out.append(lin.linearize(rec["x"][k], integrals[k], float(rec["t"][k])))
        except (ArithmeticError, ValueError) as exc:  # that instant only: said, not hidden
            if progress:
                progress(f"could not linearize the closed loop at t = {float(rec['t'][k]):.3g} s: "
                         f"{str(exc).splitlines()[0][:200]}")
            continue
        if progress:
            progress(f"linearized the closed loop at t = {float(rec['t'][k]):.3g} s")
    return out


def closed_loop_limits(lins, integrators, progress=None) -> dict[str, ClosedLoopLimit]:
    """:class:`ClosedLoopLimit` of each integrator name over the linearizations ``lins``."""
    out = {}
    for name in integrators:
        scheme = get_integrator(name)
        best, at, rho_at, start = math.inf, math.nan, math.nan, math.inf
        for k, L in enumerate(lins):
            h, rho0 = L.max_stable_step(scheme)
            if k == 0:
                start, rho_at = h, rho0
            if h < best:
                best, at, rho_at = h, L.t, rho0
        out[name] = ClosedLoopLimit(name, best, at, start, rho_at)
        if progress:
            shown = "none below T" if best == math.inf else f"{best:.4g} s"
            progress(f"closed-loop limit of {name}: {shown}")
    return out


class ModeProbe:
    """The least stable mode of the start's period map at a step ``h``: a direction to seed a run along,
    and its left eigenvector to read that mode's amplitude back from a run.

    With ``Phi(h) v = mu v`` and ``w^H Phi(h) = mu w^H`` (``w^H v = 1``), the modal amplitude of a
    perturbation ``delta s`` of the loop state is ``a = |w^H delta s|``: on the linear map it is multiplied
    by exactly ``|mu|`` per period, with no beating of the complex pair. Two runs from ``x0`` and from
    ``x0 + size Re(v_x)`` (:meth:`seed`) give ``delta s_k`` at every tick (plant states and the followers'
    integrals, :meth:`LoopLinearizer.integrals_of`), so :meth:`growth_rate` measures how fast the actual
    nonlinear loop amplifies the mode the prediction found.

    Args:
        linearizer: The scenario's :class:`LoopLinearizer`.
        lin: The :class:`LoopLinearization` at the start.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    def __init__(self, linearizer: LoopLinearizer, lin: LoopLinearization):
        self.linearizer = linearizer
        self.lin = lin

    def mode(self, scheme, h: float) -> tuple[np.ndarray, np.ndarray, complex] | None:
        """``(v, w, mu)`` of the least stable mode *the step destabilizes*: right and left eigenvectors
        (``w^H v = 1``) and the eigenvalue of largest modulus among those of ``Phi(h)`` whose modulus exceeds
        that of the nearest eigenvalue of ``Phi(h_0)`` (a step far below every limit, as in
        :meth:`LoopLinearization.max_stable_step`) by more than :data:`MOVED`. The loop's own slow modes (a
        force integral decaying in minutes: ``|mu|`` = 0.99999 per period at any step) are left out: they
        are what the physics does, and a nonlinear run moves their modal amplitude by a few percent, which
        over a short run reads as a growth. ``None`` when the step destabilizes no mode (a dissipative
        scheme, or a step that integrates every mode as the tiny step does)."""
        Phi = self.lin.period_matrix(scheme, period_steps(scheme, h, self.lin.control_period))
        mu, V = np.linalg.eig(Phi)
        mu0 = self._reference(scheme)
        nearest = mu0[np.argmin(np.abs(mu[:, None] - mu0[None, :]), axis=1)]
        moved = np.abs(mu) > np.abs(nearest) + MOVED  # the step made it less stable than the tiny step does
        if not np.any(moved):
            return None
        k = int(np.flatnonzero(moved)[np.argmax(np.abs(mu[moved]))])
        W = np.linalg.inv(V)  # rows: left eigenvectors, normalized so that W V = I
        return V[:, k], W[k].conj(), complex(mu[k])

    def _reference(self, scheme) -> np.ndarray:
        """Eigenvalues of ``Phi(h_0)`` (cached per scheme)."""
        cache = self.__dict__.setdefault("_mu0", {})
        key = getattr(scheme, "name", type(scheme).__name__)
        if key not in cache:
            T = self.lin.control_period
            lam = np.linalg.eigvals(self.lin.A)
            fastest = float(np.max(np.abs(lam))) if lam.size else 0.0
            h0 = min(T, 1e-2 / fastest) if fastest > 0 else T
            cache[key] = self.lin.eigenvalues(scheme, h0)
        return cache[key]

    def seed(self, v: np.ndarray, size: float) -> np.ndarray:
        """A plant-state perturbation along ``Re(v)`` (or ``Im(v)`` when larger), its largest position
        component ``size`` [m, rad]."""
        nx = self.lin.x.size
        nz = nx // 2
        part = v[:nx].real if np.max(np.abs(v[:nz].real)) >= np.max(np.abs(v[:nz].imag)) else v[:nx].imag
        return size / float(np.max(np.abs(part[:nz]))) * part

    def amplitude(self, rec_a: dict, rec_b: dict, w: np.ndarray) -> np.ndarray:
        """``|w^H (s_b - s_a)|`` at each tick both runs recorded."""
        n = min(len(rec_a["t"]), len(rec_b["t"]))
        nx = self.lin.x.size
        integrals = self.linearizer.integrals_of
        ds = np.concatenate([rec_b["x"][:n] - rec_a["x"][:n],
                             integrals(_head(rec_b, n)) - integrals(_head(rec_a, n))], axis=1)
        return np.abs(ds @ w.conj()) if ds.shape[1] == w.size else np.abs(ds[:, :nx] @ w[:nx].conj())

    @staticmethod
    def growth(a: np.ndarray, windows: int = 10) -> float:
        """``max_j mean(log a over window j) - log a_0`` [-]: how far the modal amplitude rose above its
        seeded value ``a_0`` (the two runs differ by exactly the seed at the first tick), on the log-means
        over ``windows`` equal windows after it (so that no single tick decides); ``0`` when too short."""
        n = len(a) - 1
        if n < windows or not a[0] > 0.0:
            return 0.0
        w = n // windows
        with np.errstate(divide="ignore"):
            la = np.log(np.maximum(a[1:1 + w * windows], 1e-300)).reshape(windows, w).mean(axis=1)
        return float(np.max(la) - math.log(a[0]))

    @staticmethod
    def growth_rate(t: np.ndarray, a: np.ndarray, windows: int = 10, least: int = 3) -> float:
        """Largest growth rate [1/s] of ``a(t)``: the log-mean of ``a`` over ``windows`` equal windows, and the
        steepest slope between two windows at least ``least`` windows apart (0 when too few ticks)."""
        n = min(len(t), len(a))
        if n < 2 * windows:
            return 0.0
        w = n // windows
        with np.errstate(divide="ignore"):
            la = np.log(np.maximum(a[:w * windows], 1e-300)).reshape(windows, w).mean(axis=1)
        tc = t[:w * windows].reshape(windows, w).mean(axis=1)
        best = -math.inf
        for i in range(windows):
            for j in range(i + least, windows):
                best = max(best, (la[j] - la[i]) / (tc[j] - tc[i]))
        return best


def _head(rec: dict, n: int) -> dict:
    return {"t": rec["t"][:n], "F_commanded": rec["F_commanded"][:n], "F_measured": rec["F_measured"][:n]}
