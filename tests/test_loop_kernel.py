"""The compiled tick (coopctrl/loop/kernel.py) allocates nothing per tick (issue 10).

numba's runtime counts its allocations (``NUMBA_NRT_STATS=1``; ``rtsys.get_allocation_stats``).
The tick's work arrays are made once per run, in Python (``kernel.tick_workspace``), and the kernel
runs without numba's runtime (``_nrt=False``): a call of ``run_ticks``, whatever its number of ticks,
allocates nothing, and neither do the functions it calls. That the counter counts is checked on a
compiled function that does allocate. Deterministic: no timing is involved.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# scenes covering the kernel's branches: square spatial arms (the carry), redundant arms with the
# torque-limit rows (iiwa), square arms with torque-limit rows, and the planar loop with noisy,
# quantized sensors (the measured-state terms)
CASES = [
    ("spatial_two_puma_carry", {}),
    ("three_iiwa_tray", {}),
    ("heavy_payload_torque_limits", {}),
    ("planar_two_arm_lift", {"sensors.forces.noise_std": 0.05, "sensors.joints.noise_std": 1e-5,
                             "sensors.joints.quantization": 1e-6}),
]

_SCRIPT = """
import json, sys
from pathlib import Path
import coopctrl
from coopctrl.loop import kernel as K
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop
import numpy as np
from numba import njit
from numba.core.runtime import rtsys

allocating = njit(lambda n: np.empty(n))
allocating(3)  # compiled (and numba's runtime started) before counting
a0 = rtsys.get_allocation_stats().alloc
allocating(3)
probe = rtsys.get_allocation_stats().alloc - a0  # the counter is on: its allocation counted

kernel = K.run_ticks
counts = []

def counted(*args):
    a0 = rtsys.get_allocation_stats().alloc
    kernel(*args)
    counts.append(rtsys.get_allocation_stats().alloc - a0)

K.run_ticks = counted
out = {{"probe": probe}}
for name, overrides in json.loads(sys.argv[1]):
    scenario = coopctrl.load_scenario(Path({root!r}) / "scenarios" / (name + ".toml"), overrides)
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    T = scenario.simulation.control_period
    loop.run(x0, 10 * T)  # compile or load the kernel
    res = []
    for ticks in (100, 200):
        counts.clear()
        rec = loop.run(x0, ticks * T)
        res.append((rec["status"], len(rec["t"]), list(counts)))
    out[name] = res
print(json.dumps(out))
"""


def test_a_tick_of_the_compiled_loop_allocates_nothing():
    env = dict(os.environ, NUMBA_NRT_STATS="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", _SCRIPT.format(root=str(ROOT)), json.dumps(CASES)], env=env,
                         capture_output=True, text=True, timeout=1200)
    assert run.returncode == 0, run.stderr[-3000:]
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["probe"] >= 1, result["probe"]  # the counter counts a compiled np.empty
    for name, _ in CASES:
        (status_n, ticks_n, calls_n), (status_2n, ticks_2n, calls_2n) = result[name]
        assert (status_n, status_2n) == ("ok", "ok"), (name, result[name])
        assert (ticks_n, ticks_2n) == (101, 201), (name, result[name])  # t = 0 .. duration
        # the same kernel calls (one: the run's ticks in one chunk; the kernel is loaded without a call), none
        # allocating
        assert len(calls_n) == len(calls_2n) == 1, (name, calls_n, calls_2n)
        assert calls_n == calls_2n == [0], f"{name}: allocations per kernel call {calls_n} (N ticks) vs {calls_2n} (2N ticks)"
