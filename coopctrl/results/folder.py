"""A result folder (``coopctrl run --out DIR``): written as one unit, reopened only when consistent.

Written (:func:`write_result_folder`) into a sibling temporary folder that then replaces ``DIR`` in
one step (:mod:`coopctrl.io.atomic_dir`): ``result.npz``, ``result.csv``, ``summary.json``, the PNG
plots, ``replay.html``, ``scenario.toml`` and, for arms read from your own URDF files, a copy of each
file (and of the mesh files it names, when they are at hand) under ``robots/arm<i>/``, named by
``scenario.toml`` relative to the folder. So the folder alone reopens (``coopctrl view DIR``) and reruns
(``coopctrl run DIR/scenario.toml``), wherever the scene's own folder went.

``result.npz`` holds the SHA-256 of ``scenario.toml``. :func:`open_result_folder` refuses (exit 2) a
folder whose ``scenario.toml`` was changed after the run, whose ``result.npz`` is damaged, or whose
data contradict its status (an ``ok`` run with non-finite data).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from coopctrl.io.atomic_dir import atomic_directory
from coopctrl.io.console import writing
from coopctrl.io.npz_reader import DamagedFileError

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: The saved scenario's name in a result folder.
SCENARIO_NAME = "scenario.toml"
#: The sub-folder holding copies of the scene's own URDF files.
ROBOTS = "robots"
#: Largest ``scenario.toml`` read back [B].
MAX_SCENARIO_BYTES = 16 * 2**20
#: Per-sample arrays checked for finite values when a result says ``ok``.
FINITE_WHEN_OK = ("t", "x", "tau", "Y0", "Y0_nominal", "F_measured", "F_commanded", "F_external", "F_internal")
#: Of those, the load distribution's split, which a passive run (controllers off: its energy is recorded)
#: does not have (NaN by design).
SPLIT_ARRAYS = ("F_commanded", "F_external", "F_internal")


def sha256_of(path: Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ---------------------------------------------------------------------- writing
def _mesh_files(urdf: Path) -> list[tuple[str, Path]]:
    """``(filename attribute, file)`` of the ``<mesh>`` elements of ``urdf`` whose files exist here
    (other URI schemes and missing files are left as they are)."""
    from defusedxml import ElementTree

    from coopctrl.replay.urdf_visuals import resolve_mesh  # a mesh is found as the replay finds it

    try:
        tree = ElementTree.parse(urdf)
    except Exception:  # noqa: BLE001 - the arm was built from it: a file the build accepted
        return []
    found = []
    for mesh in tree.getroot().iter("mesh"):
        name = mesh.get("filename") or ""
        if "://" in name and not name.startswith(("file://", "package://")):
            continue
        path = resolve_mesh(name, urdf)
        if path.is_file():
            found.append((name, path))
    return found


def _copy_urdf(source: Path, into: Path) -> Path:
    """Copy ``source`` and its mesh files into the folder ``into``; returns the copied URDF. Mesh names
    relative to the URDF and inside its folder keep their place; others (absolute, ``file://``, or
    reaching above the URDF's folder, ``package://``) are copied to ``meshes/`` and renamed in the copy."""
    into.mkdir(parents=True, exist_ok=True)
    target = into / source.name
    renamed = {}
    for k, (name, path) in enumerate(_mesh_files(source)):
        relative = os.path.normpath(name) if "://" not in name and not os.path.isabs(name) else None
        if relative is not None and not relative.startswith(".."):
            place = into / relative
        else:
            place = into / "meshes" / f"{k}_{path.name}"
            renamed[name] = f"meshes/{k}_{path.name}"
        place.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, place)
    if not renamed:
        shutil.copyfile(source, target)
        return target
    from defusedxml import ElementTree

    tree = ElementTree.parse(source)
    for mesh in tree.getroot().iter("mesh"):
        if mesh.get("filename") in renamed:
            mesh.set("filename", renamed[mesh.get("filename")])
    tree.write(target, encoding="utf-8", xml_declaration=True)
    return target


def portable_scenario(scenario, folder: Path):
    """``scenario`` with each ``model = "urdf"`` arm's file copied into ``folder/robots/arm<i>/`` and
    named relative to ``folder`` (its ``source`` becomes ``folder/scenario.toml``). A scenario without
    such arms is returned as it is."""
    arms = list(scenario.arms)
    changed = False
    for i, arm in enumerate(arms):
        if arm.model != "urdf":
            continue
        source = Path(arm.urdf_path(scenario.source))
        copied = _copy_urdf(source, folder / ROBOTS / f"arm{i + 1}")
        arms[i] = replace(arm, urdf=copied.relative_to(folder).as_posix())
        changed = True
    if not changed:
        return scenario
    return replace(scenario, arms=tuple(arms), source=str(folder / SCENARIO_NAME))


def write_result_folder(result: "SimulationResult", scenario, directory: str | Path) -> Path:
    """Write the whole result folder ``directory`` as one unit (module docstring); returns it.

    Raises:
        ValueError: ``directory`` holds files that a run does not write (they would be lost).
        OutputWriteError: the system refused a write (a full disk): it names the file and the cause.
            ``directory`` is then as it was before (an earlier result stays whole).
    """
    from coopctrl.io.output_folder import RESULT_FOLDER, check_output_folder
    from coopctrl.replay import write_replay

    final = Path(directory)
    check_output_folder(final, RESULT_FOLDER)  # nothing else in it is lost when it is replaced
    with writing(str(final)), atomic_directory(final) as folder:
        with writing(str(final / ROBOTS)):
            saved = portable_scenario(scenario, folder)
        with writing(str(final / "replay.html")):
            write_replay(result, saved, folder)  # replay.html and scenario.toml
        with writing(str(final / SCENARIO_NAME)):
            digest = sha256_of(folder / SCENARIO_NAME)
        stamped = replace(result, scenario_sha256=digest)
        stamped.save(folder)
        with writing(str(final / "*.png")):
            stamped.plot(folder)
    return final


# ---------------------------------------------------------------------- reading
def _refuse(path: Path, problem: str, fix: str) -> DamagedFileError:
    return DamagedFileError(path, problem, fix, what="is inconsistent")


def read_saved_scenario(directory: Path):
    """``DIR/scenario.toml``, loaded, and the SHA-256 of its bytes."""
    from coopctrl.cli._core import UsageError
    from coopctrl.scenario import load_scenario

    saved = directory / SCENARIO_NAME
    if not saved.is_file():
        raise UsageError(f"{saved} is missing or not a regular file: give the scenario the result ran with, "
                         "--scenario FILE [--set ...]")
    if saved.stat().st_size > MAX_SCENARIO_BYTES:
        raise _refuse(saved, f"{saved.stat().st_size} bytes, more than a scenario's {MAX_SCENARIO_BYTES}",
                      "rerun `coopctrl run SCENARIO --out DIR`")
    digest = sha256_of(saved)
    return load_scenario(saved), digest


def check_consistent(result: "SimulationResult", directory: Path, digest: str | None) -> None:
    """Refuse a result that contradicts itself or its saved scenario (module docstring).

    Args:
        result: The loaded result.
        directory: Its folder (for messages).
        digest: SHA-256 of the ``scenario.toml`` it is drawn with, or ``None`` for a scenario given
            explicitly (``--scenario``), which is not compared.
    """
    npz = directory / "result.npz"
    rerun = f"rerun `coopctrl run {directory / SCENARIO_NAME} --out {directory}`"
    if digest is not None:
        if not result.scenario_sha256:
            from coopctrl.io.console import visible

            print(f"coopctrl: warning: {visible(npz)} holds no digest of its scenario (saved by SimulationResult.save or "
                  f"an older coopctrl): {visible(directory / SCENARIO_NAME)} is taken as it is", file=sys.stderr)
        elif result.scenario_sha256 != digest:
            raise _refuse(directory / SCENARIO_NAME,
                          f"its SHA-256 {digest[:12]}... differs from the {result.scenario_sha256[:12]}... recorded in "
                          f"{npz}: it was changed after the run",
                          f"restore it, draw with --scenario FILE, or {rerun}")
    t = result.t
    if t.size and (not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0)):
        raise _refuse(npz, "its times t are not finite and increasing", rerun)
    if result.status == "ok":
        passive = result.energy is not None
        for name in FINITE_WHEN_OK:
            if passive and name in SPLIT_ARRAYS:
                continue
            value = getattr(result, name)
            bad = ~np.isfinite(value.reshape(value.shape[0], -1)).all(axis=1) if value.size else np.zeros(0, bool)
            if bad.any():
                when = float(t[int(np.argmax(bad))]) if t.size else 0.0
                raise _refuse(npz, f"its status is 'ok' but {name} is not finite from t = {when:.6g} s on "
                              "(a run with such data has diverged)", rerun)


def open_result_folder(directory: str | Path, scenario=None):
    """``(result, scenario, digest)`` of a result folder, checked (:func:`check_consistent`).

    Args:
        directory: The folder of ``coopctrl run --out``.
        scenario: The scenario to draw it with, or ``None`` for the folder's own ``scenario.toml``.

    Raises:
        UsageError: no ``result.npz`` or ``scenario.toml`` there (exit 2).
        DamagedFileError: a damaged or inconsistent file (exit 2, naming it and the fix).
    """
    from coopctrl.cli._core import UsageError
    from coopctrl.results.simulation_result import SimulationResult
    from coopctrl.results.storage import RERUN

    directory = Path(directory)
    npz = directory / "result.npz"
    if not npz.is_file():
        raise UsageError(f"DIR = {str(directory)!r} is invalid: expected a directory with result.npz as a regular "
                         "file (written by `coopctrl run SCENARIO --out DIR`)")
    digest = None
    if scenario is None:
        scenario, digest = read_saved_scenario(directory)
    try:
        result = SimulationResult.load(directory)
    except OSError as err:
        raise _refuse(npz, f"cannot be read ({err.strerror or type(err).__name__})", RERUN) from None
    check_consistent(result, directory, digest)
    expected = sum(scenario.dof_per_arm) * 2 + 2 * scenario.pose_size
    if result.scenario != scenario.name or result.x.shape[1] != expected:
        raise UsageError(f"--scenario = {scenario.name!r} is invalid: expected the scenario of the result "
                         f"({result.scenario!r}, state size {result.x.shape[1]})")
    return result, scenario, digest


def rewrite_replay(result: "SimulationResult", scenario, directory: str | Path) -> Path:
    """Write ``directory/replay.html`` again, atomically; the folder's other files (its
    ``scenario.toml`` above all) stay as the run wrote them, whatever scenario the page is drawn with."""
    import tempfile

    from coopctrl.io.atomic import _PENDING
    from coopctrl.replay import write_replay

    final = Path(directory)
    page = final / "replay.html"
    with writing(str(page)):
        scratch = tempfile.mkdtemp(dir=final, prefix=".coopctrl-view.", suffix=".tmp")
        _PENDING.add(scratch)
        try:
            write_replay(result, scenario, scratch)
            os.replace(Path(scratch) / "replay.html", page)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
            _PENDING.discard(scratch)
    return page
