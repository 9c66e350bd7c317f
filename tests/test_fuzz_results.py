"""Damaged, inconsistent and unwritable result folders (issue 22): every example of the issue, then a
seeded fuzz of damaged copies of one short result, and full disks on a small tmpfs (as root).

One result is made (``planar_two_arm_lift``, 0.05 s); every case damages a copy of it and calls
``coopctrl view`` in this process. A damaged folder is bad input: exit 2 and one line naming the file
and what is wrong, never an internal error; a damage that changes nothing readable may exit 0.
"""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _quick_plots import quick_plots, stub_plots  # noqa: F401  (quick_plots: autouse, the plots stubbed)

from coopctrl import cli

SEED = 20261222
SHORT = ["--set", "simulation.duration=0.05"]


def run_cli(args, capsys):
    """``coopctrl ARGS`` in this process: (exit code, stdout, stderr)."""
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and "internal error" not in err, err
    assert len(lines) == 1, err
    return lines[0]


@pytest.fixture(scope="module")
def result_dir(tmp_path_factory):
    """One short result folder, written by ``coopctrl run --out``."""
    import coopctrl.results.plots as plots

    out = tmp_path_factory.mktemp("base") / "r"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plots, "plot_result", stub_plots)
        assert cli.main(["run", "planar_two_arm_lift", *SHORT, "-q", "--out", str(out)]) == 0
    return out


@pytest.fixture
def copy(result_dir, tmp_path):
    def make(name: str = "copy") -> Path:
        target = tmp_path / name
        shutil.copytree(result_dir, target)
        return target
    return make


def rewrite_npz(path: Path, change) -> None:
    """Rewrite ``path``'s entries through ``change(name, bytes) -> bytes | None`` (None drops it)."""
    with zipfile.ZipFile(path) as source:
        entries = [(info.filename, source.read(info)) for info in source.infolist()]
    with zipfile.ZipFile(path, "w") as target:
        for name, data in entries:
            data = change(name, data)
            if data is not None:
                target.writestr(name, data)


def assert_refused(capsys, directory: Path, *needles: str) -> str:
    code, out, err = run_cli(["view", directory], capsys)
    line = one_line(err)
    assert code == 2 and out == "", err
    for needle in needles:
        assert needle in line, line
    return line


# ---------------------------------------------------------------------- the examples
def test_the_undamaged_copy_is_drawn(copy, capsys):
    d = copy()
    (d / "replay.html").unlink()
    code, out, err = run_cli(["view", d], capsys)
    assert code == 0, err
    assert (d / "replay.html").is_file() and "replay written to" in out


def test_truncated_npz(copy, capsys):
    d = copy()
    data = (d / "result.npz").read_bytes()
    (d / "result.npz").write_bytes(data[: len(data) // 2])
    assert_refused(capsys, d, "result.npz", "damaged")


def test_empty_npz(copy, capsys):
    d = copy()
    (d / "result.npz").write_bytes(b"")
    assert_refused(capsys, d, "result.npz", "empty")


def test_bit_flipped_npz(copy, capsys):
    d = copy()
    data = bytearray((d / "result.npz").read_bytes())
    with zipfile.ZipFile(d / "result.npz") as z:  # inside the compressed data of x.npy
        info = z.getinfo("x.npy")
    data[info.header_offset + 30 + len(info.filename) + info.compress_size // 2] ^= 0x10
    (d / "result.npz").write_bytes(bytes(data))
    assert_refused(capsys, d, "result.npz", "x.npy")


def test_unknown_entry(copy, capsys):
    d = copy()
    rewrite_npz(d / "result.npz", lambda name, data: data)
    with zipfile.ZipFile(d / "result.npz", "a") as z:
        z.writestr("payload.npy", b"\x93NUMPY")
    assert_refused(capsys, d, "result.npz", "unknown entry 'payload.npy'")


def test_missing_entry(copy, capsys):
    d = copy()
    rewrite_npz(d / "result.npz", lambda name, data: None if name == "tau.npy" else data)
    assert_refused(capsys, d, "result.npz", "'tau.npy' is missing")


def test_header_claiming_149_gib_is_refused_before_any_allocation(copy, capsys, monkeypatch):
    d = copy()
    shape = np.load(d / "result.npz")["x"].shape

    def huge(name, data):
        return data.replace(repr(shape).encode(), b"(5000000, 4000)") if name == "x.npy" else data

    rewrite_npz(d / "result.npz", huge)

    def no_allocation(*args, **kwargs):
        raise AssertionError("numpy.ndarray allocated from a header")
    monkeypatch.setattr(np.lib.format, "read_array", no_allocation)  # the reader never trusts numpy's reader
    line = assert_refused(capsys, d, "result.npz", "x.npy", "149 GiB")
    assert "holds" in line


def test_nan_state_after_5_ms_with_status_ok(copy, capsys):
    from coopctrl.results import SimulationResult
    from dataclasses import replace

    d = copy()
    result = SimulationResult.load(d)
    x = result.x.copy()
    x[result.t > 0.005 - 1e-9] = np.nan  # t > 5 ms, at 1 ms ticks (the half tick absorbs rounding)
    replace(result, x=x).save(d)  # the saved scenario digest is kept: only the data lie
    line = assert_refused(capsys, d, "result.npz", "'ok'", "x is not finite from t = 0.005")
    assert "rerun" in line


def test_scenario_edited_after_the_run(copy, capsys):
    d = copy()
    text = (d / "scenario.toml").read_text()
    (d / "scenario.toml").write_text(text.replace("[object]", "[object]\n# edited", 1))
    line = assert_refused(capsys, d, "scenario.toml", "changed after the run")
    assert "rerun" in line


def test_out_whose_result_npz_is_a_directory_is_refused_before_simulating(tmp_path, capsys, monkeypatch):
    (tmp_path / "d" / "result.npz").mkdir(parents=True)
    monkeypatch.setattr(cli.run, "simulate_function", lambda: pytest.fail("simulated before checking --out"))
    code, out, err = run_cli(["run", "planar_two_arm_lift", "--out", tmp_path / "d"], capsys)
    line = one_line(err)
    assert code == 2 and "--out" in line and "'result.npz' is not a regular file" in line


def test_out_holding_other_files_is_refused_and_kept(tmp_path, capsys, monkeypatch):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "notes.txt").write_text("mine")
    monkeypatch.setattr(cli.run, "simulate_function", lambda: pytest.fail("simulated before checking --out"))
    code, _, err = run_cli(["run", "planar_two_arm_lift", "--out", tmp_path / "d"], capsys)
    assert code == 2 and "'notes.txt'" in one_line(err)
    assert (tmp_path / "d" / "notes.txt").read_text() == "mine"


def test_full_stdout_is_a_failure_naming_it(copy, capsys, monkeypatch):
    d = copy()
    with open("/dev/full", "w") as full:
        monkeypatch.setattr(sys, "stdout", full)
        code = cli.main(["view", str(d)])
    line = one_line(capsys.readouterr().err)
    assert code == 1 and line == ("coopctrl: failed: no space left on device writing standard output "
                                  "(the replay itself was written whole)")


def test_ascii_stdout_and_a_non_ascii_out_path(tmp_path, capsys, monkeypatch):
    buffer = io.BytesIO()
    ascii_out = io.TextIOWrapper(buffer, encoding="ascii")
    monkeypatch.setattr(sys, "stdout", ascii_out)
    out = tmp_path / "r\u00e9sultat"
    code = cli.main(["run", "planar_two_arm_lift", *SHORT, "--out", str(out)])
    ascii_out.flush()
    printed = buffer.getvalue().decode("ascii")
    assert code == 0, capsys.readouterr().err
    assert f"outputs written to {tmp_path}/r\\xe9sultat" in printed  # escaped, not an error
    assert (out / "result.npz").is_file()


def test_ascii_stdout_process(result_dir, tmp_path):
    """The same through a real process with LANG=C and PYTHONIOENCODING=ascii (``view``: no simulation)."""
    d = tmp_path / "\u00e9t\u00e9"
    shutil.copytree(result_dir, d)
    repo = Path(__file__).resolve().parent.parent
    env = {**os.environ, "LANG": "C", "LC_ALL": "C", "PYTHONIOENCODING": "ascii",
           "PYTHONPATH": str(repo) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.run([sys.executable, "-m", "coopctrl", "view", os.fsencode(d)], capture_output=True, env=env,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert b"\\xe9t\\xe9/replay.html" in proc.stdout


# ---------------------------------------------------------------------- seeded fuzz
def _damage(rng, d: Path) -> str:
    """One seeded damage of ``d/result.npz``; returns its description."""
    path = d / "result.npz"
    data = bytearray(path.read_bytes())
    kind = ("truncate", "flip", "drop", "zero")[rng.integers(4)]
    if kind == "truncate":
        at = int(rng.integers(0, len(data)))
        path.write_bytes(bytes(data[:at]))
        return f"truncated at {at}"
    if kind == "flip":
        at, bit = int(rng.integers(0, len(data))), int(rng.integers(8))
        data[at] ^= 1 << bit
        path.write_bytes(bytes(data))
        return f"bit {bit} of byte {at} flipped"
    if kind == "zero":
        at = int(rng.integers(0, len(data)))
        size = int(rng.integers(1, 64))
        data[at:at + size] = bytes(len(data[at:at + size]))
        path.write_bytes(bytes(data))
        return f"{size} bytes zeroed at {at}"
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
    gone = names[int(rng.integers(len(names)))]
    rewrite_npz(path, lambda name, payload: None if name == gone else payload)
    return f"{gone} dropped"


def test_fuzz_damaged_result_folders(copy, capsys):
    rng = np.random.default_rng(SEED)
    outcomes = []
    for k in range(24):
        d = copy(f"fuzz{k}")
        what = _damage(rng, d)
        code, out, err = run_cli(["view", d], capsys)
        if code == 0:  # harmless (a byte of a zip field nobody reads, an optional entry): the page is drawn
            assert (d / "replay.html").is_file(), what
            assert err.strip() == "" or err.startswith("coopctrl: warning"), (what, err)
        else:
            line = one_line(err)
            assert code == 2, (what, err)
            assert str(d / "result.npz") in line or str(d / "scenario.toml") in line, (what, line)
        outcomes.append((what, code))
    print("damage cases (what, exit code):", outcomes)
    assert sum(code == 2 for _, code in outcomes) >= len(outcomes) // 2, outcomes  # most damages are seen


# ---------------------------------------------------------------------- full disks
@pytest.fixture
def small_disk(tmp_path):
    """A tmpfs of ``size`` mounted at ``tmp_path/disk`` (root only); unmounted at the end."""
    if not sys.platform.startswith("linux") or os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("a full disk needs a small tmpfs: mount -t tmpfs needs root on Linux")
    mounted = []

    def mount(size_bytes: int) -> Path:
        place = tmp_path / "disk"
        place.mkdir()
        proc = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size_bytes}", "tmpfs", str(place)],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            pytest.skip(f"mount -t tmpfs refused here: {proc.stderr.strip()}")
        mounted.append(place)
        return place

    yield mount
    for place in mounted:
        subprocess.run(["umount", str(place)], capture_output=True)


def _tree(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def test_full_disk_names_the_file_and_keeps_the_old_result(result_dir, small_disk, capsys):
    size = sum(p.stat().st_size for p in result_dir.rglob("*") if p.is_file())
    disk = small_disk(int(size * 1.4) // 4096 * 4096)  # room for the old result, not for a second one
    target = disk / "r"
    shutil.copytree(result_dir, target)
    before = _tree(target)
    code, out, err = run_cli(["run", "planar_two_arm_lift", *SHORT, "--set", "simulation.seed=1", "-q",
                              "--out", target], capsys)
    line = one_line(err)
    assert code == 1 and line.startswith("coopctrl: failed: no space left on device writing ")
    assert str(target) in line
    assert _tree(target) == before  # the old result, whole
    assert sorted(p.name for p in disk.iterdir()) == ["r"]  # no temporary folder left


def test_full_disk_on_a_new_folder_leaves_nothing(small_disk, capsys):
    disk = small_disk(64 * 1024)
    code, _, err = run_cli(["run", "planar_two_arm_lift", *SHORT, "-q", "--out", disk / "new"], capsys)
    assert code == 1 and "no space left on device writing" in one_line(err)
    assert list(disk.iterdir()) == []
