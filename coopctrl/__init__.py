"""coopctrl: the control layer over the elastic cooperative plant (:mod:`plants`).

Public API (notebooks and outside checks use these names):

- :func:`load_scenario` - a validated scenario from a TOML file (plus ``--set``-style overrides);
- :func:`simulate` - run a scenario's closed loop and get a :class:`SimulationResult`;
- :class:`Controller` - the scenario's control layer as one object, stepped from your own loop with a
  :class:`Measurement` (``docs/controller.md``).

Each public function checks its arguments once per call, before any long work, and raises
``TypeError`` (wrong kind) or ``ValueError`` (wrong value) with one line naming the argument, its value
and what is allowed (:mod:`coopctrl.arguments`). Heavy modules are imported lazily so that
``coopctrl --help`` stays fast.
"""

from __future__ import annotations

__all__ = ["load_scenario", "simulate", "SimulationResult", "Controller", "Measurement"]


def load_scenario(path=None, overrides=None):
    """A validated :class:`~coopctrl.scenario.Scenario` from ``path`` (None: the default scene), with
    ``overrides`` (dotted path -> value, ``{"simulation.duration": 0.5}``); see
    :func:`coopctrl.scenario.load_scenario`."""
    from coopctrl.scenario import load_scenario as _load

    return _load(path, overrides)


def simulate(scenario, progress: bool = False):
    """Run the closed loop of ``scenario`` (a :class:`~coopctrl.scenario.Scenario`, from
    :func:`load_scenario`); returns a :class:`~coopctrl.results.SimulationResult`."""
    from coopctrl.simulator import simulate as _simulate

    return _simulate(scenario, progress=progress)


def __getattr__(name):
    if name == "SimulationResult":
        from coopctrl.results import SimulationResult

        return SimulationResult
    if name in ("Controller", "Measurement"):
        import coopctrl.controller as controller

        return getattr(controller, name)
    raise AttributeError(name)
