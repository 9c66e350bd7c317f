"""The allocation-free right-hand side (issue 10 part 6): ``rhs_into`` with one preallocated workspace.

* It gives the results of the kernels as they were before the workspace (frozen verbatim in
  ``tests/_rhs_reference.py``), on seeded random states of plants with every arm kind (Puma 560,
  planar 3R, contact point, the Panda / UR5e / iiwa14 general chains), m = 1..4, planar and
  spatial, every element and damping form, mobile and immobile; with a workspace that starts as
  NaN and is reused across plants' states (nothing stale is read).
* ``control_terms_into`` gives what ``plant.control_terms`` gives; ``rhs_into_packed`` and
  ``control_terms_packed`` (the arrays by name, ``plant_args``) give the same bits as the unpacked entry points.
* Called 10^4 times inside a numba loop, neither allocates: numba's NRT allocation counters (on
  with ``NUMBA_NRT_STATS=1``, so checked in a subprocess) count the same allocations for 10 calls
  as for 10^4 + 10.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import _rhs_reference as ref
from plants.arms import iiwa14, panda, planar3r, puma560, ur5e
from plants.cooperative import ContactPoint, CooperativePlant
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.frames import rotation_zyx

ROOT = Path(__file__).resolve().parent.parent

#: new vs old: the same floating-point operations in the same order, so the results are expected to
#: be bitwise equal; the bound allows for a compiler that reorders nothing but still differs in
#: the last bit of one rounding (relative 1e-14 of the largest entry, the issue's bound).
REL_TOL = 1e-14

#: Arm mixes per (space, m): every arm kind appears.
SPATIAL_MIXES = {
    1: ("iiwa14",),
    2: ("puma560", "panda"),
    3: ("ur5e", "contact", "puma560"),
    4: ("panda", "iiwa14", "contact", "ur5e"),
}
PLANAR_MIXES = {1: ("planar3r",), 2: ("planar3r", "contact"), 3: ("contact", "planar3r", "planar3r"),
                4: ("planar3r", "contact", "planar3r", "contact")}


def _T(xyz, A):
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(np.asarray(A, dtype=float))
    T[:3, 3] = xyz
    return T


def _spatial_arm(kind, k, m):
    phi = 2 * np.pi * k / m
    base = _T([0.8 * np.cos(phi), 0.8 * np.sin(phi), 0.0], [phi + np.pi, 0.0, 0.0])
    if kind == "contact":
        return ContactPoint("spatial", name=f"arm{k}")
    if kind == "puma560":
        return puma560(base=base, motor_inertia=True, viscous_friction=True)
    return {"panda": panda, "ur5e": ur5e, "iiwa14": iiwa14}[kind](base=base)


def random_plant(space, m, seed, unloaded_state="mobile"):
    """A plant with the arm mix of ``m``, random node poses, one spring object-contact per arm
    (elements and damping forms alternating) and a spring between consecutive contacts."""
    rng = np.random.default_rng(seed)
    p = 6 if space == "spatial" else 3
    kinds = (SPATIAL_MIXES if space == "spatial" else PLANAR_MIXES)[m]
    Y_ref = rng.normal(0.0, 0.3, (m + 1, p))
    if space == "spatial":
        arms = [_spatial_arm(kind, k, m) for k, kind in enumerate(kinds)]
        nodes = [Node(2.0, (0.02, 0.025, 0.03), name="object")]
        nodes += [Node(0.3, (1e-3, 1.2e-3, 1.4e-3), name=f"nodes[{k + 1}]") for k in range(m)]
    else:
        arms = [ContactPoint("planar", name=f"arm{k}") if kind == "contact"
                else planar3r(base=(-0.6 + 0.4 * k, 0.0, 0.3 * k)) for k, kind in enumerate(kinds)]
        nodes = [Node(2.0, (0.02,), name="object")] + [Node(0.3, (1e-3,), name=f"nodes[{k + 1}]") for k in range(m)]
    springs = []
    for k in range(m):
        springs.append(Interconnection((0, k + 1), stiffness=2e4, torsion=200.0, damping=60.0, torsion_damping=0.5,
                                       element=("offset", "central")[k % 2],
                                       damping_form=("frame_invariant", "book")[(k // 2) % 2]))
    for k in range(1, m):
        springs.append(Interconnection((k, k + 1), stiffness=5e3, torsion=50.0, damping=10.0, torsion_damping=0.2,
                                       element="offset"))
    elastic = ElasticSystem(space, nodes, springs, Y_ref, 9.81, unloaded_state)
    return CooperativePlant(elastic, arms, leader=0)


def random_state(plant, rng):
    x = rng.normal(0.0, 0.5, plant.state_size)
    x[plant.nz - plant.p:plant.nz] = rng.normal(0.0, 0.3, plant.p)  # object pose away from theta = +-pi/2
    tau = rng.normal(0.0, 5.0, plant.input_size)
    return np.ascontiguousarray(x), tau


def _nan_fill(ws):
    for arr in ws:
        if isinstance(arr, tuple):
            _nan_fill(arr)
        else:
            arr[...] = np.nan


CASES = [(space, m, state) for space in ("spatial", "planar") for m in (1, 2, 3, 4)
         for state in ("mobile", "immobile")]


@pytest.mark.parametrize("space,m,unloaded_state", CASES)
def test_rhs_into_equals_the_kernel_before_the_workspace(space, m, unloaded_state):
    plant = random_plant(space, m, seed=10 * m + (space == "planar"), unloaded_state=unloaded_state)
    old = ref.spatial_rhs_old if space == "spatial" else ref.planar_rhs_old
    fn, args = plant.kernel_into
    ws = plant.workspace()
    _nan_fill(ws)  # whatever the workspace holds before a call must not matter
    rng = np.random.default_rng(1000 + m)
    checked = 0
    for _ in range(6):
        x, tau = random_state(plant, rng)
        want = old(x, tau, *args)
        st_old = args[-1].copy()
        dx = np.full_like(x, np.nan)
        fn(x, tau, *args, ws, dx)
        assert args[-1][0] == st_old[0] and args[-1][1] == st_old[1]
        if st_old[0] != 0:
            continue  # a random posture at an arm's Euler singularity: both report it
        assert np.max(np.abs(dx - want)) <= REL_TOL * max(1.0, np.max(np.abs(want)))
        # the thin wrappers (plant.rhs, plant.kernel) give the same
        np.testing.assert_allclose(plant.rhs(0.0, x, tau), want, rtol=0, atol=REL_TOL * max(1.0, np.max(np.abs(want))))
        checked += 1
    assert checked >= 4


@pytest.mark.parametrize("space,m", [("spatial", 2), ("spatial", 4), ("planar", 3)])
def test_control_terms_into_equals_control_terms(space, m):
    plant = random_plant(space, m, seed=77 + m)
    fn, args = plant.control_kernel_into
    cws = plant.control_workspace()
    rng = np.random.default_rng(5)
    for _ in range(3):
        x, _tau = random_state(plant, rng)
        ct = plant.control_terms(x)
        fn(x, *args, cws)  # the same workspace reused: every term is rewritten
        assert args[-1][0] == 0
        got = dict(Y=cws.ws.Y, dY=cws.ws.dY, H=cws.ws.H, h=cws.ws.h, J=cws.ws.J, Jdq=cws.ws.Jdq, W=cws.W,
                   w_free=cws.w_free, S=cws.S, Fw=cws.Fw)
        for name, arr in got.items():
            np.testing.assert_array_equal(arr, getattr(ct, name), err_msg=name)
        # S and Fw as the plant's own contact-wrench query computes them (independent loop)
        np.testing.assert_allclose(cws.Fw, plant.contact_wrenches(x), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("space,m,unloaded_state", [("spatial", 2, "mobile"), ("spatial", 3, "immobile"),
                                                    ("planar", 3, "mobile")])
def test_packed_entry_points_equal_the_unpacked_ones(space, m, unloaded_state):
    """``rhs_into_packed`` / ``control_terms_packed`` (the plant's arrays by name, ``plant_args``) call the same
    kernels with the same arrays: the same bits, and the same status."""
    plant = random_plant(space, m, seed=41 + m, unloaded_state=unloaded_state)
    fn, args = plant.kernel_into
    cfn, cargs = plant.control_kernel_into
    kernels = sys.modules[fn.py_func.__module__]
    P, status = plant.plant_args, args[-1]
    assert len(P) == len(args) - 1 and all(a is b for a, b in zip(P, args))  # the raw kernels' arrays, by name
    rng = np.random.default_rng(9)
    for _ in range(3):
        x, tau = random_state(plant, rng)
        want, got = np.full_like(x, np.nan), np.full_like(x, np.nan)
        fn(x, tau, *args, plant.workspace(), want)
        st = status.copy()
        kernels.rhs_into_packed(x, tau, P, status, plant.workspace(), got)
        np.testing.assert_array_equal(status, st)
        np.testing.assert_array_equal(got, want)
        c_want, c_got = plant.control_workspace(), plant.control_workspace()
        cfn(x, *cargs, c_want)
        kernels.control_terms_packed(x, P, status, c_got)
        for name in ("W", "w_free", "S", "Fw"):
            np.testing.assert_array_equal(getattr(c_got, name), getattr(c_want, name), err_msg=name)
        np.testing.assert_array_equal(c_got.ws.J, c_want.ws.J)


_ALLOC_SCRIPT = textwrap.dedent("""
    import sys
    import numpy as np
    from numba import njit
    from numba.core.runtime import rtsys
    sys.path.insert(0, {tests!r})
    from test_rhs_workspace import random_plant, random_state

    @njit
    def loop_rhs(fn, x, tau, args, ws, dx, reps):
        for _ in range(reps):
            fn(x, tau, *args, ws, dx)

    @njit
    def loop_ct(fn, x, args, cws, reps):
        for _ in range(reps):
            fn(x, *args, cws)

    for space, m in (("spatial", 2), ("spatial", 4), ("planar", 3)):
        plant = random_plant(space, m, seed=3)
        x, tau = random_state(plant, np.random.default_rng(0))
        fn, args = plant.kernel_into
        ws, dx = plant.workspace(), np.empty_like(x)
        cfn, cargs = plant.control_kernel_into
        cws = plant.control_workspace()
        for loop, call in ((loop_rhs, lambda r: loop_rhs(fn, x, tau, args, ws, dx, r)),
                           (loop_ct, lambda r: loop_ct(cfn, x, cargs, cws, r))):
            call(1)  # compile
            a0 = rtsys.get_allocation_stats().alloc
            call(10)
            a1 = rtsys.get_allocation_stats().alloc
            call(10010)
            a2 = rtsys.get_allocation_stats().alloc
            print(space, m, loop.__name__, a1 - a0, a2 - a1, int(args[-1][0]))
""")


def test_rhs_into_and_control_terms_into_allocate_nothing_in_a_numba_loop():
    env = dict(os.environ, NUMBA_NRT_STATS="1", PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    script = _ALLOC_SCRIPT.format(tests=str(ROOT / "tests"))
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    rows = [line.split() for line in out.stdout.strip().splitlines()]
    assert len(rows) == 6, out.stdout
    for space, m, loop, few, many, status in rows:
        assert status == "0", (space, m, loop)
        # the allocations of one call from Python (unboxing, the loop's own frame) are the same for
        # 10 and for 10010 calls in the loop: none happens per call
        assert int(many) == int(few), f"{loop} ({space}, m = {m}): {few} allocations for 10 calls, {many} for 10010"


@pytest.mark.parametrize("m,unloaded_state", [(2, "mobile"), (3, "immobile"), (4, "mobile")])
def test_rhs_from_terms_equals_the_rhs(m, unloaded_state):
    """``rhs_from_terms_into`` (a closed-loop tick's first right-hand side of the period, finished from
    the control terms at the same state) performs the operations of ``rhs_into`` in the same order:
    the same bits and the same status, for seeded states of spatial plants of every arm kind; and the
    control terms it reads are left as they were (the controllers read them)."""
    plant = random_plant("spatial", m, seed=71 + m, unloaded_state=unloaded_state)
    fn, args = plant.kernel_into
    kernels = sys.modules[fn.py_func.__module__]
    P, status = plant.plant_args, args[-1]
    assert len(P) == len(args) - 1 and all(a is b for a, b in zip(P, args))  # the raw kernels' arrays, by name
    rng = np.random.default_rng(17)
    for _ in range(3):
        x, tau = random_state(plant, rng)
        want, got = np.full_like(x, np.nan), np.full_like(x, np.nan)
        fn(x, tau, *args, plant.workspace(), want)
        st = status.copy()
        cws = plant.control_workspace()
        kernels.control_terms_packed(x, P, status, cws)
        before = [np.array(a, copy=True) for a in (cws.ws.Y, cws.ws.H, cws.ws.J, cws.W, cws.w_free, cws.S, cws.Fw)]
        kernels.rhs_from_terms_into(x, tau, P, status, cws, got)
        np.testing.assert_array_equal(status, st)
        np.testing.assert_array_equal(got, want)
        after = (cws.ws.Y, cws.ws.H, cws.ws.J, cws.W, cws.w_free, cws.S, cws.Fw)
        for a, b in zip(before, after):
            np.testing.assert_array_equal(a, b)
