"""coopctrl/io/atomic_dir.py: a folder replaced in one step, or left as it was."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import coopctrl.io.atomic_dir as atomic_dir
from coopctrl.io.atomic import remove_pending
from coopctrl.io.atomic_dir import atomic_directory, remove_stale


def _tree(d):
    return {str(p.relative_to(d)): p.read_text() for p in sorted(d.rglob("*")) if p.is_file()}


def _write_old(target):
    target.mkdir()
    (target / "a.txt").write_text("old a")
    (target / "gone.txt").write_text("only in the old one")


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "rename-aside"])
def test_replaces_the_whole_folder(tmp_path, monkeypatch, exchange):
    if not exchange:
        monkeypatch.setattr(atomic_dir, "exchange_directories", lambda a, b: False)
    target = tmp_path / "out"
    _write_old(target)
    with atomic_directory(target) as folder:
        assert folder.parent == tmp_path and folder.name.startswith(".out.coopctrl-")
        (folder / "a.txt").write_text("new a")
        assert _tree(target) == {"a.txt": "old a", "gone.txt": "only in the old one"}  # untouched until the end
    assert _tree(target) == {"a.txt": "new a"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_an_exception_leaves_the_old_folder_and_nothing_else(tmp_path):
    target = tmp_path / "out"
    _write_old(target)
    with pytest.raises(KeyboardInterrupt):
        with atomic_directory(target) as folder:
            (folder / "a.txt").write_text("half")
            raise KeyboardInterrupt
    assert _tree(target) == {"a.txt": "old a", "gone.txt": "only in the old one"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_new_folder_and_its_parents_are_created(tmp_path):
    target = tmp_path / "a" / "b" / "out"
    with atomic_directory(target) as folder:
        (folder / "x").write_text("1")
    assert _tree(target) == {"x": "1"}


def test_a_symbolic_link_keeps_pointing_at_the_replaced_folder(tmp_path):
    real = tmp_path / "real"
    _write_old(real)
    link = tmp_path / "link"
    link.symlink_to(real)
    with atomic_directory(link) as folder:
        (folder / "a.txt").write_text("new a")
    assert link.is_symlink() and _tree(link) == {"a.txt": "new a"}


def test_temporary_folders_of_dead_writers_are_removed(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    pid = int(dead.stdout)  # a process that has exited (its id is not reused within this test)
    stale = tmp_path / f".out.coopctrl-{pid}-abc.tmp"
    stale.mkdir()
    alive = tmp_path / f".out.coopctrl-{os.getppid()}-abc.tmp"  # a live process's work is left alone
    alive.mkdir()
    assert remove_stale(tmp_path / "out") == [str(stale)]
    assert not stale.exists() and alive.exists()


def test_remove_pending_removes_a_folder_in_progress(tmp_path):
    target = tmp_path / "out"
    with pytest.raises(RuntimeError):
        with atomic_directory(target) as folder:
            (folder / "x").write_text("1")
            assert str(folder) in remove_pending()  # what the command line does on SIGTERM
            assert not folder.exists()
            raise RuntimeError("stopped")
    assert list(tmp_path.iterdir()) == []
