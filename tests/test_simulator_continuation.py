"""A continued run is a result (issue 45 item 9): ``simulate(scenario, state=result.final_state)`` returns a
:class:`SimulationResult` that follows on from the first, bit for bit one run of the summed duration, and
that can be saved, reopened, plotted and continued again."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.results import SimulationResult
from coopctrl.scenario import load_scenario
from coopctrl.simulator import simulate

T = 0.001


def scene(duration):
    return load_scenario(None, {"simulation.duration": duration})


def test_continuation_is_the_run_of_the_summed_duration(tmp_path):
    first = simulate(scene(0.03))
    second = simulate(scene(0.02), state=first.final_state)
    whole = simulate(scene(0.05))
    assert isinstance(second, SimulationResult) and second.status == "ok"
    assert second.t[0] == pytest.approx(first.t[-1] + T, abs=1e-12) and len(second.t) == 20
    joined = np.concatenate([first.x, second.x])
    assert np.array_equal(joined, whole.x)  # the compiled solver's continuation is bit-identical
    assert np.array_equal(np.concatenate([first.tau, second.tau]), whole.tau)
    # a result like any other: saved, reopened, plotted
    second.save(tmp_path / "r")
    back = SimulationResult.load(tmp_path / "r")
    assert np.array_equal(back.t, second.t) and np.array_equal(back.x, second.x) and back.final_state is None
    assert second.plot(tmp_path / "plots")
    third = simulate(scene(0.01), state=second.final_state)  # and continued again from its own end
    assert np.array_equal(third.x, simulate(scene(0.06)).x[51:])


def test_fuzz_split_points():
    """Seeded: a 40-tick run split at random points into two to four continued runs: the joined records are
    the whole run's, bit for bit."""
    rng = np.random.default_rng(4509)
    whole = simulate(scene(0.04))
    for _ in range(2):
        cuts = np.sort(rng.choice(np.arange(2, 38), size=int(rng.integers(1, 4)), replace=False))
        bounds = [0, *cuts.tolist(), 40]
        parts = [simulate(scene(bounds[1] * T))]
        for a, b in zip(bounds[1:-1], bounds[2:]):
            parts.append(simulate(scene((b - a) * T), state=parts[-1].final_state))
        assert np.array_equal(np.concatenate([p.x for p in parts]), whole.x), bounds


def test_state_is_checked():
    with pytest.raises(TypeError, match="state"):
        simulate(scene(0.01), state=np.zeros(18))
