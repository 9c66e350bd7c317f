"""The optional MuJoCo dependency: imported lazily, and a missing one named with the extra that installs it."""

from __future__ import annotations

from coopctrl.errors import CoopctrlError

#: The pip command that installs MuJoCo for coopctrl (the ``mujoco`` extra of ``pyproject.toml``).
INSTALL_HINT = "pip install 'coopctrl[mujoco]'"


class MujocoMissing(CoopctrlError, ImportError):
    """MuJoCo (the ``mujoco`` package) is not installed; the message names the extra that installs it.

    Attributes:
        cause: The import error's own message.
    """

    def __init__(self, cause: str):
        self.cause = cause
        super().__init__(f"plant 'mujoco' needs the MuJoCo Python package, which is not installed ({cause}); "
                         f"install it with {INSTALL_HINT}")


def import_mujoco():
    """The ``mujoco`` module; :class:`MujocoMissing` (exit 2 from the command line) when it cannot be imported."""
    try:
        import mujoco
    except ImportError as exc:
        raise MujocoMissing(str(exc) or type(exc).__name__) from None
    return mujoco
