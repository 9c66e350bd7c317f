"""Loops built with probes (:mod:`coopctrl.controllers.probes`) for the tuning code: the scenario's
closed loop with its leader and followers wrapped, so test signals enter the loop ``coopctrl run`` runs.
"""

from __future__ import annotations

from coopctrl.controllers.probes import FollowerProbe, LeaderProbe, probe_errors

__all__ = ["FollowerProbe", "LeaderProbe", "probe_errors", "probed_closed_loop"]


def probed_closed_loop(scenario):
    """``(loop, leader_probe, follower_probes)``: the scenario's closed loop built with its leader and
    every follower wrapped by a probe (:func:`coopctrl.wiring.closed_loop` with ``controllers``); a run's
    follower errors: :func:`probe_errors`."""
    from coopctrl.wiring import closed_loop

    def wrap(leader, followers):
        return (leader if isinstance(leader, LeaderProbe) else LeaderProbe(leader),
                {i: c if isinstance(c, FollowerProbe) else FollowerProbe(c) for i, c in followers.items()})

    loop = closed_loop(scenario, controllers=wrap)
    return loop, loop.leader, loop.followers
