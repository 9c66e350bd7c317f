"""A finished run saturated on most ticks is a failure with its cause (issue 45 item 1;
coopctrl.analysis.instability). The unstable-gain causes are in tests/test_gain_stability.py."""

from __future__ import annotations

import coopctrl.analysis.instability as instability
from coopctrl import cli


def test_saturated_run_names_the_torque_limit(capsys, monkeypatch):
    """The carry sent to an out-of-reach waypoint (--no-preflight): the arms cannot follow and the torques
    saturate on 1064 of 2501 ticks (42 %: an ok run with a warning at the default share). With the share
    lowered to 25 % the same run fails (exit 1), naming the joint's torque limit, not a gain."""
    monkeypatch.setattr(instability, "SATURATED_SHARE", 0.25)
    code = cli.main(["run", "spatial_two_puma_carry", "-q", "--no-preflight", "--set",
                     "trajectory.via[1].pose=[0.0,0.15,1.5,0.3,0.0,0.0]", "--set", "simulation.duration=2.5"])
    err = capsys.readouterr().err
    assert code == 1, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("coopctrl: diverged: not controlled: the commanded torques were clipped at tau_max on ")
    assert "cause: the torque limit arms[" in line and "unstable gain" not in line
