"""A sweep's worker reuses one built loop for the runs that differ only in the noise seed
(coopctrl.sweep.reuse), and its rows stay bit for bit those of a fresh ``simulate()`` (issue 18).

In-process (``execute_run`` as ``--jobs 1`` calls it), on the planar lift shortened to 0.15 s, with
noise on every sensor so that the seed changes the run.
"""

from __future__ import annotations

import pytest

import coopctrl.simulator
import coopctrl.wiring
from coopctrl.sweep import TIMING_COLUMNS, SweepGrid, execute_run, plan_sweep, reuse, simulate_run
from coopctrl.sweep.results import METRICS
from test_cli import REPO

LIFT = REPO / "scenarios" / "planar_two_arm_lift.toml"
NOISY = {"simulation.duration": "0.15", "sensors.forces.noise_std": "0.5", "sensors.joints.noise_std": "1e-4",
         "sensors.object.noise_std": "1e-4"}
# the seed varies slowest: the runs of one seed go through both loops before the next seed reuses them
GRID = ["simulation.seed=3,8", "controllers.followers.force_ki=10,40"]


@pytest.fixture(scope="module")
def plan():
    return plan_sweep(LIFT, SweepGrid.parse(GRID), NOISY)


def _metrics(row: dict) -> dict:
    return {m.key: row[m.key] for m in METRICS if m.key not in TIMING_COLUMNS}


def test_a_reused_loop_gives_the_row_of_a_fresh_simulate_bit_for_bit(plan, monkeypatch):
    builds = []
    real = coopctrl.wiring.closed_loop  # the one builder (coopctrl.simulator.closed_loop is the same function)
    monkeypatch.setattr(coopctrl.wiring, "closed_loop", lambda scenario, **kw: builds.append(1) or real(scenario, **kw))
    reuse.clear()
    rows = [execute_run(simulate_run, run) for run in plan.runs]  # run 2 and 3 reuse the loops of 0 and 1
    again = execute_run(simulate_run, plan.runs[0])  # back to seed 3 on a loop that ran seed 8 last
    assert len(builds) == 2  # one loop per force_ki: the seed is a run input
    monkeypatch.setattr(coopctrl.wiring, "closed_loop", real)
    for run, row in zip(plan.runs, rows):
        fresh = coopctrl.simulator.simulate(run.scenario()).summary()
        assert row["status"] == fresh["status"] == "ok", row["reason"]
        # bit for bit (==, no tolerance): the same ticks on the same inputs give the same floats
        assert _metrics(row) == {k: fresh[k] for k in _metrics(row)}, run.columns
        assert row["follower_force_error_rms_N"] is not None and row["object_position_error_rms_m"] is not None
    assert _metrics(again) == _metrics(rows[0])
    # the seed reaches the reused loop: the force noise changes the force error of the same loop
    assert rows[0]["follower_force_error_rms_N"] != rows[2]["follower_force_error_rms_N"]


def test_the_key_of_a_loop_drops_the_seed_only(plan):
    seed3_ki10, seed3_ki40, seed8_ki10 = (plan.runs[i].scenario() for i in (0, 1, 2))
    assert reuse.loop_key(seed3_ki10) == reuse.loop_key(seed8_ki10)
    assert reuse.loop_key(seed3_ki10) != reuse.loop_key(seed3_ki40)
    assert reuse.loop_key(seed8_ki10).simulation.seed == 0 and seed8_ki10.simulation.seed == 8
