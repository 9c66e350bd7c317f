"""The built-in scenes (``*.toml``), shipped as the package data of ``coopctrl.scenarios``.

``pyproject.toml`` maps the package ``coopctrl.scenarios`` to this folder, so that an installed
wheel carries the scenes; :mod:`coopctrl.scenario.library` finds them (here in a checkout, through
:mod:`importlib.resources` once installed). This file holds no code.
"""
