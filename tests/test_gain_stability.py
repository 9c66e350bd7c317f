"""Gains the sampled linear model shows unstable are refused (issue 45 item 1;
coopctrl.analysis.gain_stability), and a finished run that saturated on most ticks fails with its cause
(coopctrl.analysis.instability)."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import cli
from coopctrl.analysis.gain_stability import force_loop_map, gain_limit, motion_loop_map, spectral_radius

T = 0.001


def run_cli(args, capsys):
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def sets(**values):
    return [a for k, v in values.items() for a in ("--set", f"{k.replace('__', '.')}={v}")]


def test_motion_loop_map_against_the_discretized_double_integrator():
    """The map is the ZOH sampling of e'' = a under a = -Kp e - Kd e' (exact for a held acceleration):
    against scipy's matrix exponential of the augmented system."""
    from scipy.linalg import expm

    wn, zeta = 40.0, 0.7
    Ac = np.zeros((3, 3))
    Ac[0, 1], Ac[1, 2] = 1.0, 1.0
    G = expm(Ac * T)[:2, :]  # (e, e') from (e, e', a held)
    K = np.array([[1.0, 0.0], [0.0, 1.0], [-wn ** 2, -2 * zeta * wn]])
    assert np.allclose(G @ K, motion_loop_map(wn, zeta, T), rtol=1e-12, atol=1e-15)


def test_the_limit_is_the_stability_boundary():
    """gain_limit returns a stable value with an unstable one within the resolution above it."""
    radius = lambda w: spectral_radius(motion_loop_map(w, 1.0, T))  # noqa: E731
    limit = gain_limit(radius, 1e5)
    assert radius(limit) < 1.0 <= radius(limit * 1.002)
    radius = lambda g: spectral_radius(force_loop_map(g, 0.0, 30.0, 1.0, T))  # noqa: E731
    limit = gain_limit(radius, 1000.0)
    assert radius(limit) < 1.0 <= radius(limit * 1.002)


def test_default_gains_are_stable():
    assert spectral_radius(force_loop_map(0.5, 10.0, 30.0, 1.0, T)) < 1.0
    assert spectral_radius(motion_loop_map(30.0, 1.0, T)) < 1.0


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("values, field", [
    ({"controllers__followers__force_kp": 1000, "controllers__followers__force_ki": 1e6},
     "controllers.followers.force_kp"),
    ({"controllers__leader__natural_frequency": 1e5}, "controllers.leader.natural_frequency"),
])
def test_unstable_gain_is_bad_input(command, values, field, capsys):
    code, out, err = run_cli([command, *sets(**values)], capsys)
    assert code == 2, err
    line = err.strip().splitlines()[-1]
    assert line.startswith(f"coopctrl: error: {field} = ") and "a value below" in line and "Traceback" not in err


@pytest.mark.parametrize("values, named", [
    ({"controllers__followers__force_kp": 1000, "controllers__followers__force_ki": 1e6},
     "unstable gain: controllers.followers.force_kp"),
    ({"controllers__leader__natural_frequency": 1e5}, "unstable gain: controllers.leader.natural_frequency"),
])
def test_unstable_run_fails_with_the_gain_named(values, named, capsys):
    """The issue's runs (``--no-preflight``: the refusal skipped): exit 1, the gain named with its limit; the
    torque saturation it drives is not blamed on the payload."""
    code, out, err = run_cli(["run", "-q", "--no-preflight", *sets(simulation__duration=0.3, **values)], capsys)
    assert code == 1, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("coopctrl: diverged: ") and named in line and "stable limit" in line
    assert "lower the payload" not in line


def test_fuzz_gains_through_check(capsys):
    """Seeded: leader and follower gains drawn log-uniformly over the reference's ranges; ``coopctrl check``
    refuses (exit 2, the controllers.* field named) exactly the draws the sampled model finds unstable and the
    scene's linearized loop confirms, and passes the others (exit 0, or 1 for a task pre-flight finds
    impossible). Even draws come from the gains' lower decades, odd ones from the whole ranges, so that both
    outcomes are met."""
    from coopctrl.analysis.gain_stability import loop_grows, unstable_gain
    from coopctrl.scenario import build, load_scenario

    rng = np.random.default_rng(45)
    seen = set()
    for draw in range(6):
        whole = draw % 2
        values = {"controllers__leader__natural_frequency": float(10 ** rng.uniform(0, 5 if whole else 2)),
                  "controllers__followers__force_kp": float(10 ** rng.uniform(-2, 3 if whole else 0)),
                  "controllers__followers__force_ki": float(10 ** rng.uniform(-1, 6 if whole else 2))}
        code, out, err = run_cli(["check", *sets(**{k: repr(v) for k, v in values.items()})], capsys)
        scene = load_scenario(None, {k.replace("__", "."): v for k, v in values.items()})
        found = unstable_gain(scene)
        refused = found is not None and loop_grows(scene, build.initial_state(scene))
        assert "Traceback" not in err
        if refused:
            assert code == 2 and f"coopctrl: error: {found[0]} = " in err, err
        else:
            assert code in (0, 1), err
        seen.add(refused)
    assert seen == {True, False}
