"""Controller gains as a scenario takes them: ``--set`` overrides, a TOML fragment, or a new file.

Only the fields that exist in ``[controllers]`` (:mod:`coopctrl.scenario.controllers`) can be
held; a field left at ``None`` keeps the scene's value.
"""

from __future__ import annotations

import math
import re
import shlex
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from coopctrl.errors import ScenarioError

#: Gains field -> dotted scenario path.
SCENARIO_PATHS = {
    "leader_natural_frequency": "controllers.leader.natural_frequency",
    "leader_damping_ratio": "controllers.leader.damping_ratio",
    "follower_force_loop": "controllers.followers.force_loop",
    "follower_force_kp": "controllers.followers.force_kp",
    "follower_force_ki": "controllers.followers.force_ki",
    "follower_natural_frequency": "controllers.followers.natural_frequency",
    "follower_damping_ratio": "controllers.followers.damping_ratio",
}

#: Fields that may be zero (the others must be > 0).
_NONNEGATIVE = {"follower_force_kp", "follower_force_ki"}


@dataclass(frozen=True)
class Gains:
    """Controller gains (docs/model.md s.6); ``None`` = unchanged.

    Attributes:
        leader_natural_frequency: Leader tracking ``omega_n`` in [rad/s] (``K_p = omega_n^2``).
        leader_damping_ratio: Leader tracking ``zeta`` [-] (``K_d = 2 zeta omega_n``).
        follower_force_loop: Close the followers' force loops.
        follower_force_kp: Followers' force-loop proportional gain [-].
        follower_force_ki: Followers' force-loop integral gain in [1/s].
        follower_natural_frequency: Followers' motion loop ``omega_n`` in [rad/s].
        follower_damping_ratio: Followers' motion loop ``zeta`` [-].

    Example:
        >>> Gains(leader_natural_frequency=60.0).as_overrides()
        {'controllers.leader.natural_frequency': 60.0}
    """

    leader_natural_frequency: float | None = None
    leader_damping_ratio: float | None = None
    follower_force_loop: bool | None = None
    follower_force_kp: float | None = None
    follower_force_ki: float | None = None
    follower_natural_frequency: float | None = None
    follower_damping_ratio: float | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            path = SCENARIO_PATHS[f.name]
            if f.name == "follower_force_loop":
                if not isinstance(value, bool):
                    raise ScenarioError(path, value, "true or false")
                continue
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            if not ok or value < 0 or (value == 0 and f.name not in _NONNEGATIVE):
                raise ScenarioError(path, value, "a finite number " + (">= 0" if f.name in _NONNEGATIVE else "> 0"))
            object.__setattr__(self, f.name, float(value))

    @classmethod
    def from_scenario(cls, scenario) -> "Gains":
        """Every gain of ``scenario``."""
        c = scenario.controllers
        return cls(c.leader.natural_frequency, c.leader.damping_ratio, c.followers.force_loop, c.followers.force_kp,
                   c.followers.force_ki, c.followers.natural_frequency, c.followers.damping_ratio)

    def __or__(self, other: "Gains") -> "Gains":
        """These gains with ``other``'s set fields on top."""
        if not isinstance(other, Gains):
            return NotImplemented
        return Gains(**{f.name: getattr(other, f.name) if getattr(other, f.name) is not None else getattr(self, f.name)
                        for f in fields(self)})

    # ------------------------------------------------------------------ outputs
    def as_overrides(self) -> dict:
        """``{dotted path: value}`` of the set fields, for ``load_scenario(path, overrides)``."""
        return {SCENARIO_PATHS[f.name]: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    def as_set_options(self) -> "SetOptions":
        """The ``--set`` options of the set fields: a list for ``subprocess`` / ``cli.main``
        (``["--set", "controllers.leader.natural_frequency=60.0", ...]``) that prints as the
        text to paste after ``coopctrl run SCENARIO`` (``--set controllers.leader.natural_frequency=60.0 ...``)."""
        out = SetOptions()
        for path, value in self.as_overrides().items():
            out += ["--set", f"{path}={_toml_value(value)}"]
        return out

    def as_toml(self) -> str:
        """The ``[controllers.leader]`` / ``[controllers.followers]`` tables of the set fields."""
        from coopctrl.io import dumps_toml

        tables: dict = {}
        for path, value in self.as_overrides().items():
            _, section, key = path.split(".")
            tables.setdefault(section, {})[key] = value
        return "\n".join(f"[controllers.{section}]\n{dumps_toml(values)}" for section, values in tables.items())

    def apply(self, scenario):
        """``scenario`` with these gains (validated like ``--set``)."""
        from coopctrl.scenario.loader import scenario_from_dict

        return scenario_from_dict(scenario.to_dict(), source=scenario.source, overrides=self.as_overrides())

    def write_to(self, scenario_path, out_path) -> Path:
        """Write the scenario file ``scenario_path`` with these gains to ``out_path`` (atomically).

        The file is kept as written, comments (units) included: only the values of the gains
        change, a gain the file did not set is added to its table with its unit as a comment,
        and a missing table is appended. (A file whose gains are inline tables is rewritten by
        :func:`coopctrl.io.dumps_toml` instead, without comments.) The result is checked by
        loading it before it is written. Returns ``out_path``.
        """
        from coopctrl.io import atomic_write, dumps_toml
        from coopctrl.scenario import load_scenario
        from coopctrl.scenario.loader import apply_overrides, scenario_from_dict

        load_scenario(scenario_path)  # the same one-line ScenarioError as `coopctrl run` for a bad file
        text = Path(scenario_path).read_text(encoding="utf-8")
        raw = tomllib.loads(text)
        apply_overrides(raw, self.as_overrides())
        scenario_from_dict(raw, source=str(out_path))
        header = f"# {Path(scenario_path).name} with controller gains from coopctrl.tuning\n"
        edited = _edit_gains(text, self.as_overrides())
        try:
            body = edited if edited is not None and tomllib.loads(edited) == raw else None
        except tomllib.TOMLDecodeError:
            body = None
        if body is None:
            body = dumps_toml(raw)
        out_path = Path(out_path)
        with atomic_write(out_path) as handle:
            handle.write(header + body)
        return out_path


class SetOptions(list):
    """``--set`` options: a list of arguments that prints as a shell command-line fragment."""

    def __str__(self) -> str:
        return " ".join(shlex.quote(a) for a in self)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def _unit(path: str) -> str:
    from coopctrl.scenario.controllers import FollowerControllerConfig, LeaderControllerConfig
    from coopctrl.scenario.schema import spec

    _, section, key = path.split(".")
    cls = LeaderControllerConfig if section == "leader" else FollowerControllerConfig
    return spec(cls, key).get("unit", "")


def _edit_gains(text: str, overrides: dict) -> str | None:
    """``text`` with each ``controllers.<section>.<key>`` of ``overrides`` set in place (its line's
    comment kept; a new key gets its unit as a comment), or ``None`` if the file holds the
    gains in a form this line editor does not handle (inline tables, dotted keys)."""
    lines = text.splitlines()
    header = re.compile(r"^\s*\[\[?\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
    for path, value in overrides.items():
        _, section, key = path.split(".")
        table = f"controllers.{section}"
        start = next((i for i, ln in enumerate(lines) if (m := header.match(ln)) and m.group(1) == table), None)
        new = f"{key} = {_toml_value(value)}"
        unit = _unit(path)
        if start is None:
            if re.search(rf"^\s*(controllers\s*=|{section}\s*=|controllers\.{section}\b)", text, re.M):
                return None
            lines += ["", f"[{table}]", new + (f"  # {unit}" if unit else "")]
            continue
        end = next((i for i in range(start + 1, len(lines)) if header.match(lines[i])), len(lines))
        key_line = re.compile(rf"^(\s*{re.escape(key)}\s*=\s*)([^#]*?)(\s*#.*)?$")
        for i in range(start + 1, end):
            m = key_line.match(lines[i])
            if m:
                comment = m.group(3) or (f"  # {unit}" if unit else "")
                lines[i] = f"{m.group(1)}{_toml_value(value)}{comment}"
                break
        else:
            insert = end
            while insert > start + 1 and not lines[insert - 1].strip():
                insert -= 1
            lines.insert(insert, new + (f"  # {unit}" if unit else ""))
    return "\n".join(lines) + "\n"
