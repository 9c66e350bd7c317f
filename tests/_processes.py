"""Process-tree helpers shared by the signal tests (tests/test_reliability.py, tests/test_fuzz.py)."""

from __future__ import annotations

import time

import psutil


def descendants(pid: int) -> list[psutil.Process]:
    """Every process below ``pid`` (workers, resource trackers), or none if it is gone."""
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def command_line(process: psutil.Process) -> str:
    """``process``'s command line, or "" once it has exited: a child that has just ended is a zombie
    until its parent reaps it, and psutil then raises ZombieProcess (a NoSuchProcess) for its command
    line. A process tree sampled while it changes meets such children."""
    try:
        return " ".join(process.cmdline())
    except (psutil.NoSuchProcess, psutil.AccessDenied):
        return ""


def still_alive(processes, patience_s: float = 30.0) -> list[int]:
    """Those of ``processes`` still running (not zombies) after up to ``patience_s`` [s]."""
    deadline = time.monotonic() + patience_s
    while True:
        alive = []
        for p in processes:
            try:
                if p.status() != psutil.STATUS_ZOMBIE:
                    alive.append(p.pid)
            except psutil.NoSuchProcess:
                pass
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.1)
