"""Benchmark of the compiled load-distribution QP (Goldfarb-Idnani, the C++ core's) beside the libraries.

Problems (each a sequence of 1 kHz ticks, solved in order, so the warm starts see what they
see in the loop):

- ``two-Puma carry``: the QP sequence of ``spatial_two_puma_carry`` (n = 12, the wrench balance, no
  inequality family) as the compiled tick assembles it, recorded on the reference path
  (``solver="proxsuite"``, where the kernel hands each tick's QP to Python);
- ``m = 2, 3, 4`` (``--arms``): spatial arms with all three inequality families (min grip 2 N, friction
  mu = 1.0 with 4 facets about normals tilted up, torque limits at 80 % of the largest torque of
  the split without torque limits, 6-joint arms) along a smooth trajectory of the object (it
  turns, its load changes a little each step). Torque limits bind at every tick, the friction
  pyramid at about 70 % of the ticks for m = 2; every tick is feasible.

Columns, all medians in one run [us per solve]:

- ``compiled, from Python``: the core's ``gi_solve`` (``coopctrl._core``) called from Python, warm started, each
  call timed (nanobind's conversion of the arrays included: the compiled tick calls the solver without it);
- ``proxsuite``: one persistent ``dense.QP`` updated in place and warm started (as
  ``ProxsuiteSolver``), eps_abs 1e-9, each ``update + solve`` timed;
- ``daqp``, ``quadprog``: their native Python calls, each timed (they build the problem every call);
- the ratios of the libraries to the compiled QP, and the largest force difference to proxsuite [N].

Run: ``python benchmarks/bench_compiled_qp.py [--steps N] [--arms 2 3 4] [--quick]``
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from coopctrl.load_distribution import LoadDistribution, LoadDistributionConfig, LoadDistributionProblem  # noqa: E402
from coopctrl._core import gi_solve  # noqa: E402
from coopctrl.load_distribution.goldfarb_idnani import SOLVED, gi_workspace  # noqa: E402

TOL = 1e-9
MAX_ITER = 1000


class Sequence:
    """A recorded sequence of QPs of one shape: ``P`` (n, n), ``g`` (S, n), ``M`` (S, rows, n),
    ``lo``, ``hi`` (S, rows), ``n_eq``."""

    def __init__(self, name, P, g, M, lo, hi, n_eq):
        self.name, self.P, self.g, self.M, self.lo, self.hi, self.n_eq = name, P, g, M, lo, hi, n_eq

    @property
    def steps(self):
        return self.g.shape[0]


def record_carry() -> Sequence:
    """The QP sequence of a closed-loop run of ``spatial_two_puma_carry``, as the compiled tick assembles
    it: recorded on the reference path (``solver = "proxsuite"``, eps_abs 1e-9), whose kernel stops at
    every tick's assembled QP for the backend (the compiled path solves inside the kernel, out of
    Python's reach). The answers differ from the compiled solver's by less than 1e-6 N, so the
    sequence is the compiled path's up to that."""
    import coopctrl
    from coopctrl.load_distribution.load_distribution import LoadDistribution

    rec = []
    original = LoadDistribution.solve_assembled

    def recording(self, r_contacts):
        problem = self.problem
        rec.append((problem.P.copy(), problem.g.copy(), problem.M.copy(), problem.lo.copy(), problem.hi.copy(),
                    problem.dims[1]))
        return original(self, r_contacts)

    LoadDistribution.solve_assembled = recording
    try:
        sc = coopctrl.load_scenario(ROOT / "scenarios" / "spatial_two_puma_carry.toml",
                                    {"load_distribution.solver": "proxsuite", "load_distribution.eps_abs": "1e-9"})
        result = coopctrl.simulate(sc)
    finally:
        LoadDistribution.solve_assembled = original
    assert result.status == "ok", result.reason
    assert len(rec) > 1000, len(rec)  # one QP per tick of the 2.5 s run
    P = rec[0][0]
    assert all(np.array_equal(r[0], P) for r in rec)
    return Sequence("two-Puma carry (m=2, no ineq.)", P, np.array([r[1] for r in rec]), np.array([r[2] for r in rec]),
                    np.array([r[3] for r in rec]), np.array([r[4] for r in rec]), rec[0][5])


def trajectory_problems(m: int, steps: int, seed: int = 0) -> Sequence:
    """Spatial, all three inequality families, along a smooth 1 kHz trajectory (see the docstring)."""
    rng = np.random.default_rng(seed)
    J0 = [rng.normal(size=(6, 6)) * 0.4 for _ in range(m)]
    b0 = [rng.normal(size=6) * 2.0 for _ in range(m)]
    ang = 2 * np.pi * np.arange(m) / m
    rho = 0.3 * np.stack([np.cos(ang), np.sin(ang), np.zeros(m)], axis=1)
    mass = 8.0
    base = dict(min_grip=2.0, friction_coefficient=1.0, squeeze=10.0)
    pb = LoadDistributionProblem(LoadDistributionConfig(torque_limits=True, **base), "spatial", m)
    tau_max = None
    out = []
    for s in range(steps):
        t = s * 1e-3
        a = 0.5 * math.sin(2 * np.pi * 0.5 * t)
        c, sn = math.cos(a), math.sin(a)
        R = np.array([[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]])
        r0 = np.array([0.1 * t, 0.0, 0.5])
        r = r0 + rho @ R.T
        # inward and tilted up: the contacts hold the object partly from below
        normals = -(rho @ R.T) / np.linalg.norm(rho, axis=1, keepdims=True) + np.array([0.0, 0.0, 0.8])
        w = np.array([2.0 * math.sin(3 * t), 1.0, mass * 9.81 + 5.0 * math.sin(2 * t), 0.3, -0.2, 0.5 * math.cos(t)])
        J = [Ji * (1.0 + 0.05 * math.sin(t + i)) for i, Ji in enumerate(J0)]
        if tau_max is None:
            ld = LoadDistribution(LoadDistributionConfig(**base), "spatial", m)
            F = ld.solve(r, r0, w, normals=normals).F
            tau_max = [0.8 * np.max(np.abs(J[i].T @ F[i] + b0[i])) * np.ones(6) for i in range(m)]
        pb.update(r, r0, w, normals, J, b0, tau_max)
        out.append((pb.g.copy(), pb.M.copy(), pb.lo.copy(), pb.hi.copy()))
    return Sequence(f"m = {m}, spatial, grip+friction+torque", pb.P.copy(), np.array([o[0] for o in out]),
                    np.array([o[1] for o in out]), np.array([o[2] for o in out]), np.array([o[3] for o in out]), pb.k)


def bench_python(seq: Sequence):
    """Median [us] of the core's warm-started solves called from Python; the answers and iterations."""
    n, rows = seq.P.shape[0], seq.M.shape[1]
    ws = gi_workspace(n, rows)
    x, z = np.zeros(n), np.zeros(rows)
    times, X, iters = [], np.zeros((seq.steps, n)), np.zeros(seq.steps, np.int64)
    for s in range(seq.steps):
        g, M, lo, hi = (np.ascontiguousarray(a[s]) for a in (seq.g, seq.M, seq.lo, seq.hi))
        t0 = time.perf_counter()
        st, it = gi_solve(seq.P, g, M, lo, hi, seq.n_eq, x, z, ws, s == 0, TOL, MAX_ITER)
        times.append(time.perf_counter() - t0)
        assert st == SOLVED, st
        X[s], iters[s] = x, it
    return float(np.median(times)) * 1e6, X, iters


def bench_proxsuite(seq: Sequence):
    import proxsuite

    px = proxsuite.proxqp
    k = seq.n_eq
    n, n_in = seq.P.shape[0], seq.M.shape[1] - k
    qp = px.dense.QP(n, k, n_in)
    s = qp.settings
    s.eps_abs, s.eps_rel, s.verbose = 1e-9, 0.0, False
    s.initial_guess = px.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
    times, X = [], np.zeros((seq.steps, n))
    C = l = u = None
    for i in range(seq.steps):
        M, lo, hi = seq.M[i], seq.lo[i], seq.hi[i]
        if n_in:
            C, l, u = M[k:], lo[k:], hi[k:]
        t0 = time.perf_counter()
        if i == 0:
            qp.init(seq.P, seq.g[i], M[:k], lo[:k], C, l, u)
        else:
            qp.update(g=seq.g[i], A=M[:k], b=lo[:k], C=C, l=l, u=u)
        qp.solve()
        times.append(time.perf_counter() - t0)
        X[i] = qp.results.x
    return float(np.median(times)) * 1e6, X


def bench_daqp(seq: Sequence):
    import daqp

    k = seq.n_eq
    sense = np.zeros(seq.M.shape[1], dtype=np.int32)
    sense[:k] = 5
    times = []
    for i in range(seq.steps):
        t0 = time.perf_counter()
        up = np.where(np.isfinite(seq.hi[i]), seq.hi[i], 1e30)
        low = np.where(np.isfinite(seq.lo[i]), seq.lo[i], -1e30)
        daqp.solve(seq.P, seq.g[i], seq.M[i], up, low, sense)
        times.append(time.perf_counter() - t0)
    return float(np.median(times)) * 1e6


def bench_quadprog(seq: Sequence):
    import quadprog

    k = seq.n_eq
    times = []
    for i in range(seq.steps):
        M, lo, hi = seq.M[i], seq.lo[i], seq.hi[i]
        t0 = time.perf_counter()
        lf, uf = np.isfinite(lo[k:]), np.isfinite(hi[k:])
        C = np.vstack((M[:k], M[k:][lf], -M[k:][uf])).T
        b = np.concatenate((lo[:k], lo[k:][lf], -hi[k:][uf]))
        quadprog.solve_qp(seq.P, -seq.g[i], C, b, k)
        times.append(time.perf_counter() - t0)
    return float(np.median(times)) * 1e6


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000, help="ticks per m-sequence (1 ms each)")
    ap.add_argument("--arms", type=int, nargs="+", default=[2, 3, 4], help="arm counts of the m-sequences")
    ap.add_argument("--quick", action="store_true", help="a short smoke run: 300 ticks")
    args = ap.parse_args(argv)
    if args.quick:
        args.steps = 300
    if args.steps < 1:
        ap.error(f"--steps {args.steps}: must be an integer >= 1")
    if any(m < 2 for m in args.arms):
        ap.error(f"--arms {' '.join(map(str, args.arms))}: arm counts must be integers >= 2")
    print("command:", " ".join([pathlib.Path(sys.executable).name] + sys.argv))
    seqs = [record_carry()] + [trajectory_problems(m, args.steps) for m in args.arms]
    print(f"median us per solve (eps_abs / tol 1e-9), {args.steps} ticks per m-sequence, "
          f"{seqs[0].steps} ticks of the carry")
    head = (f"{'problem':<40} | {'n':>2} | {'rows':>4} | {'compiled Py':>11} | "
            f"{'proxsuite':>9} | {'daqp':>6} | {'quadprog':>8} | {'prox/comp':>9} | {'daqp/comp':>9} | "
            f"{'qp/comp':>7} | {'iters':>9} | {'max |dF| vs prox':>16}")
    print(head)
    print("-" * len(head))
    for seq in seqs:
        py_us, X, iters = bench_python(seq)
        px_us, Xp = bench_proxsuite(seq)
        dq_us = bench_daqp(seq)
        qp_us = bench_quadprog(seq)
        it = f"{np.mean(iters):.2f}/{int(iters.max())}"
        print(f"{seq.name:<40} | {seq.P.shape[0]:>2} | {seq.M.shape[1]:>4} | {py_us:>8.2f} us | "
              f"{px_us:>6.1f} us | {dq_us:>3.1f} us | {qp_us:>5.1f} us | {px_us / py_us:>8.1f}x | "
              f"{dq_us / py_us:>8.1f}x | {qp_us / py_us:>6.1f}x | {it:>9} | {np.abs(X - Xp).max():>14.2e} N")
    print("iters = mean/max additions+drops per solve of the warm-started compiled QP")


if __name__ == "__main__":
    main()
