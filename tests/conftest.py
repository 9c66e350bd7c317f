"""The suite's hooks: before a distributed run of the whole suite (``pytest -n``, which
``pyproject.toml``'s ``addopts`` asks for), compile the closed loop's kernels of both spaces on every
worker's core (``tests/_warm_kernels.py``), when the kernel cache lacks any of them.

Without it each test worker compiles, on an empty cache, the same kernels as the other at the same time:
the two cores of the CI machine would do the same minutes of compiling twice. A run of chosen tests (any
path or ``-k`` on the command line), a serial run (``-n 0``) and a warm cache skip it: a test compiles what
it needs on first use, as a user's run does. A warm-up that fails is reported and the run goes on (the
tests that need those kernels then show the failure).

pytest's closing "N passed in T s" counts from the end of the session's start, so it leaves the warm-up out:
a run that warmed up also prints its whole time, the warm-up in it, just before that line."""

from __future__ import annotations

import time

import pytest

import _warm_kernels

#: Seconds the warm-up may take (both spaces' kernels compiled in about five minutes on a slow 2-core
#: machine; the limit only stops a hung one).
WARM_TIMEOUT_S = 3600


def _whole_suite(config) -> bool:
    """Whether this run is the distributed run of the whole suite, in the controller process."""
    if hasattr(config, "workerinput"):  # an xdist worker
        return False
    if not getattr(config.option, "numprocesses", None) or getattr(config.option, "dist", "no") == "no":
        return False
    whole = config.args_source is pytest.Config.ArgsSource.TESTPATHS  # no path given: pyproject's testpaths
    return whole and not config.option.keyword and not config.option.markexpr


def _cold_spaces() -> list[str]:
    from coopctrl.loop.startup import FAMILIES, SPACES, KernelKind, is_cold

    return [s for s in SPACES if any(is_cold(KernelKind(s, f)) for f in FAMILIES)]


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    config = session.config
    if not _whole_suite(config):
        return
    spaces = _cold_spaces()
    if not spaces:
        return
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    say = (lambda text: reporter.write_line(text)) if reporter is not None else print
    jobs = max(1, int(getattr(config.option, "numprocesses", 1) or 1))
    say(f"compiling the kernels of {' and '.join(spaces)} scenes before the workers start, {jobs} processes:")
    t0 = time.perf_counter()
    _warm_kernels.warm(spaces, jobs=jobs, timeout_s=WARM_TIMEOUT_S, say=say)
    warm_s = time.perf_counter() - t0
    say(f"kernels compiled in {warm_s:.0f} s")
    _WARM_UP.update(began=t0, seconds=warm_s)


#: The warm-up of this run, if one ran: when it began (``time.perf_counter``) and how long it took [s].
_WARM_UP: dict = {}


def pytest_terminal_summary(terminalreporter):
    """pytest's own "in N s" counts from the end of the session's start, after the warm-up: the whole, said
    once more with the warm-up in it."""
    if _WARM_UP:
        whole = time.perf_counter() - _WARM_UP["began"]
        terminalreporter.write_line(f"the whole run took {whole:.1f} s, the kernels' warm-up ({_WARM_UP['seconds']:.0f} s) "
                                    "included (pytest's figure below leaves it out)")
