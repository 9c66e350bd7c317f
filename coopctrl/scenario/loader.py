"""Loading a :class:`Scenario` from TOML, with dotted-path overrides.

The raw TOML dict is checked key by key against the dataclass tree (an unknown key at any depth
is an error naming its path), overrides are applied to the raw dict, and the dataclasses then
check their fields. Every failure is a one-line :class:`~coopctrl.errors.ScenarioError`.
"""

from __future__ import annotations

import copy
import re
import tomllib
from dataclasses import MISSING as NO_DEFAULT
from dataclasses import fields, is_dataclass
from pathlib import Path
from typing import Any, Mapping

from coopctrl.errors import ScenarioError
from coopctrl.scenario.arm import MODEL_SPACES, ArmConfig
from coopctrl.scenario.checks import MISSING, field_scope, join_path
from coopctrl.scenario.controllers import ControllersConfig, FollowerControllerConfig, LeaderControllerConfig
from coopctrl.scenario.library import builtin_path
from coopctrl.scenario.load_distribution import LoadDistributionConfig
from coopctrl.scenario.object_config import ObjectConfig
from coopctrl.scenario.scenario import Scenario, default_arms, default_object_pose, default_trajectory
from coopctrl.scenario.scene import SceneConfig
from coopctrl.scenario.scene_file import read_scene_table
from coopctrl.scenario.sensors import CHANNELS as SENSOR_CHANNELS
from coopctrl.scenario.sensors import SensorsConfig
from coopctrl.scenario.simulation import SimulationConfig
from coopctrl.scenario.spring import SpringConfig
from coopctrl.scenario.text import MAX_DEPTH, MAX_TEXT, check_text, check_tree, printable
from coopctrl.scenario.trajectory import TrajectoryConfig, ViaPoint

#: Sections of each dataclass: a dataclass (a TOML table) or a one-element list (an array of tables).
SECTIONS: dict[type, dict[str, Any]] = {
    Scenario: {
        "scene": SceneConfig,
        "object": ObjectConfig,
        "arms": [ArmConfig],
        "springs": [SpringConfig],
        "trajectory": TrajectoryConfig,
        "load_distribution": LoadDistributionConfig,
        "controllers": ControllersConfig,
        "sensors": SensorsConfig,
        "simulation": SimulationConfig,
    },
    TrajectoryConfig: {"via": [ViaPoint]},
    ControllersConfig: {"leader": LeaderControllerConfig, "followers": FollowerControllerConfig},
    SensorsConfig: dict(SENSOR_CHANNELS),
}

#: Fields that are not keys of the file.
_NOT_KEYS = {Scenario: {"source"}}


def _keys(cls: type) -> list[str]:
    keys = _KEYS.get(cls)
    if keys is None:
        skip = _NOT_KEYS.get(cls, set())
        keys = _KEYS[cls] = [f.name for f in fields(cls) if f.init and f.name not in skip]
    return list(keys)


#: Each section class's file keys (:func:`_keys`), once per class.
_KEYS: dict = {}


def _where(path: str) -> str:
    return f"[{path}]" if path else "the top level"


# ---------------------------------------------------------------------- building
def build_section(cls: type, data: Any, path: str = ""):
    """Build the dataclass ``cls`` from the TOML table ``data`` found at ``path``."""
    if not isinstance(data, Mapping):
        raise ScenarioError(path, data, f"a table of the keys {', '.join(_keys(cls))}")
    keys = _keys(cls)
    for key, value in data.items():
        if key not in keys:
            raise ScenarioError(join_path(path, key), value, f"no unknown key: the keys of {_where(path)} are {', '.join(keys)}")
    kwargs: dict[str, Any] = {}
    for f in fields(cls):
        if f.name not in keys:
            continue
        if f.name not in data:
            if f.default is NO_DEFAULT and f.default_factory is NO_DEFAULT:
                raise ScenarioError(join_path(path, f.name), MISSING, "a value: this key is required")
            continue
        value = data[f.name]
        sub = SECTIONS.get(cls, {}).get(f.name)
        sub_path = join_path(path, f.name)
        if isinstance(sub, list):
            if not isinstance(value, list):
                raise ScenarioError(sub_path, value, f"a list of tables ([[{sub_path}]] or [{{...}}, ...])")
            value = tuple(build_section(sub[0], item, f"{sub_path}[{k}]") for k, item in enumerate(value))
        elif sub is not None:
            value = build_section(sub, value, sub_path)
        kwargs[f.name] = value
    with field_scope(path):
        return cls(**kwargs)


#: Sections a scene file must have: the built-in default scene (``coopctrl run`` without a file,
#: ``Scenario()``) supplies its own arms and a 0.1 m lift, but a file that leaves them out would
#: silently get planar arms or a lift the user never asked for.
REQUIRED_IN_FILE = ("arms", "trajectory")


def _check_file_sections(raw: Mapping) -> None:
    """Refuse a scene file without ``[[arms]]`` or ``[trajectory]``, saying what it has."""
    wrote = ", ".join(k for k in raw) or "nothing (the file is empty)"
    scene = raw.get("scene") if isinstance(raw.get("scene"), Mapping) else {}
    space = scene.get("space", "planar")
    if "arms" not in raw:
        models = " or ".join(repr(m) for m, spaces in MODEL_SPACES.items() if space in spaces) or "..."
        raise ScenarioError("arms", MISSING, f"at least 2 [[arms]] tables (model = {models}) in a {space} scene file; "
                            f"the file has no [[arms]] (it sets: {wrote}); `coopctrl run` without a file runs the "
                            "built-in default scene")
    if "trajectory" not in raw:
        raise ScenarioError("trajectory", MISSING, "a [trajectory] with via = [{time = 0.0, pose = [...]}, ...] "
                            f"(the object's start pose and its motion); the file has none (it sets: {wrote})")


def scenario_from_dict(
    data: Mapping,
    *,
    source: str | None = None,
    overrides: Mapping[str, Any] | None = None,
    file: bool = False,
) -> Scenario:
    """Build a :class:`Scenario` from a TOML-shaped dict, after applying ``overrides``.

    ``file=True`` applies the rules of a scene file: ``[[arms]]`` and ``[trajectory]`` are
    required (:data:`REQUIRED_IN_FILE`). Without it, absent sections take the built-in default
    scene's (``scenario_from_dict({})`` is ``Scenario()``).
    """
    try:
        check_tree(data)  # before any recursive copy: bounded depth, safe strings
        raw = copy.deepcopy(dict(data))
        if overrides:
            apply_overrides(raw, overrides)
            check_tree(raw)
        if file:
            _check_file_sections(raw)
        if "source" in raw:
            raise ScenarioError("source", raw["source"], f"no unknown key: the keys of the top level are {', '.join(_keys(Scenario))}")
        scenario = build_section(Scenario, raw)
    except ScenarioError as err:
        if source and not err.source:
            raise ScenarioError(err.path, err.value, err.allowed, source) from None
        raise
    if source is not None:
        object.__setattr__(scenario, "source", str(source))
    return scenario


def load_scenario(path: str | Path | None, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Load, override and check a scenario file.

    Args:
        path: Path of a ``.toml`` file (it must have ``[[arms]]`` and ``[trajectory]``), the name
            of a built-in scene (``"spatial_two_puma_carry"``, see ``coopctrl list``), or ``None``
            for the built-in default scene. A file is read only if it is a regular file of at most
            :data:`~coopctrl.scenario.scene_file.MAX_SCENE_BYTES` bytes.
        overrides: Dotted path (``"simulation.integrator"``, ``"springs[0].stiffness"``,
            ``"arms[1].grasp"``) to value. A string value is read as a TOML value if it parses
            (``"1e6"`` is a float, ``"[0, 0.1, 0]"`` a list), else kept as a bare string.

    Raises:
        ScenarioError: Missing, unreadable, oversized or non-regular file, TOML syntax error, nesting
            deeper than :data:`~coopctrl.scenario.text.MAX_DEPTH`, unknown key or override path, a
            string with a control character, or any invalid field (the message names its dotted path).
        TypeError: ``path`` or ``overrides`` of another type (the message names the argument).
    """
    from coopctrl.arguments import overrides_or_none, path_or_none

    path_or_none("path", path, "the path of a scenario .toml file or a shipped scene's name (a str or pathlib.Path), or None")
    overrides_or_none("overrides", overrides)
    if path is None:
        return scenario_from_dict({}, overrides=overrides)
    if isinstance(path, str) and not Path(path).exists():
        path = builtin_path(path) or path  # a built-in scene by name, as the command line takes it
    source = str(path)
    data = read_scene_table(path)  # bounded, regular files only, every string checked
    return scenario_from_dict(data, source=source, overrides=overrides, file=True)


# ---------------------------------------------------------------------- overrides
_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")


def parse_override_value(text: Any) -> Any:
    """Read a CLI string as a TOML value (``1e6``, ``[0, 0.1, 0]``, ``true``, ``"x"``, ``{...}``);
    a string that is not TOML (``rk4``) is kept as is. Non-strings are returned unchanged.

    Raises:
        ScenarioError: (path ``""``) a value nested deeper than the TOML parser can recurse.
    """
    if not isinstance(text, str):
        return text
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ScenarioError("", text[:32] + "...", f"a value nested at most {MAX_DEPTH} levels deep") from None


def parse_override_path(path: str) -> list[str | int]:
    """Split ``"springs[0].stiffness"`` into ``["springs", 0, "stiffness"]``."""
    tokens: list[str | int] = []
    allowed = "a dotted path like simulation.integrator or springs[0].stiffness"
    if not isinstance(path, str) or not path:
        raise ScenarioError(printable(str(path)), path, allowed)
    if len(path) > MAX_TEXT:
        raise ScenarioError(printable(path[:32]) + "...", path[:32] + "...", f"{allowed}, at most {MAX_TEXT} characters")
    for part in path.split("."):
        match = _PART.match(part.strip(" "))
        if not match:
            raise ScenarioError(printable(path), path, allowed)
        tokens.append(match.group(1))
        tokens.extend(int(i) for i in re.findall(r"\[(\d+)\]", match.group(2)))
    return tokens


def _default_list(raw: dict, name: str, cls: type) -> list:
    """The raw default of a list that is absent from the file, so that an override can index it."""
    if name == "arms":
        return [_plain(a) for a in default_arms()]
    if name == "springs":
        arms = raw.get("arms")
        m = len(arms) if isinstance(arms, list) else len(default_arms())
        return [{"pair": [0, k]} for k in range(1, m + 1)]
    if name == "via":
        scene = raw.get("scene") if isinstance(raw.get("scene"), dict) else {}
        space = scene.get("space", "planar")
        space = space if space in ("planar", "spatial") else "planar"
        obj = raw.get("object") if isinstance(raw.get("object"), dict) else {}
        pose = obj.get("pose", default_object_pose(space))
        try:
            return _plain(default_trajectory(tuple(pose), space))["via"]
        except (TypeError, ValueError, IndexError):
            return []
    return []


def _plain(value):
    if is_dataclass(value):
        return {f.name: _plain(getattr(value, f.name)) for f in fields(value) if getattr(value, f.name) is not None}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def apply_overrides(raw: dict, overrides: Mapping[str, Any]) -> dict:
    """Apply dotted-path overrides to the raw TOML dict in place (and return it).

    Each path is checked against the scenario schema: an unknown key is a ScenarioError naming
    the override's path. A missing list (``arms``, ``springs``, ``trajectory.via``) is first
    filled with its default so that it can be indexed; index ``len`` appends a new table.
    """
    for path, value in overrides.items():
        tokens = parse_override_path(path)
        if isinstance(value, str):
            check_text(path, value)
        try:
            value = parse_override_value(value)
        except ScenarioError as err:
            raise ScenarioError(path, err.value, err.allowed) from None
        cls: Any = Scenario
        node: Any = raw
        walked = ""
        root = raw
        for pos, token in enumerate(tokens):
            last = pos == len(tokens) - 1
            if isinstance(token, int):
                walked_next = f"{walked}[{token}]"
                if not isinstance(cls, list) or not isinstance(node, list):
                    raise ScenarioError(path, value, f"a path without an index after {walked} (not a list)")
                if token > len(node):
                    raise ScenarioError(path, value, f"an index <= {len(node)} in {walked} (it has {len(node)} entries; {len(node)} appends one)")
                if token == len(node):
                    node.append({})
                if last:
                    node[token] = value
                    break
                cls, node, walked = cls[0], node[token], walked_next
                if not isinstance(node, dict):
                    raise ScenarioError(path, value, f"a path into a table, but {walked} is {node!r}")
                continue
            if isinstance(cls, list) or not is_dataclass(cls):
                raise ScenarioError(path, value, f"a path that stops at {walked} (it has no key {token!r})")
            keys = _keys(cls)
            if token not in keys:
                raise ScenarioError(path, value, f"a known key: the keys of {_where(walked)} are {', '.join(keys)}")
            walked = join_path(walked, token)
            if last:
                node[token] = value
                break
            sub = SECTIONS.get(cls, {}).get(token)
            if token not in node:
                node[token] = _default_list(root, token, sub[0]) if isinstance(sub, list) else {}
            child = node[token]
            if sub is None:
                raise ScenarioError(path, value, f"a path that stops at {walked} (it is a value, not a table)")
            if isinstance(sub, list) and not isinstance(child, list):
                raise ScenarioError(walked, child, "a list of tables")
            if not isinstance(sub, list) and not isinstance(child, dict):
                raise ScenarioError(walked, child, "a table")
            cls, node = sub, child
    return raw
