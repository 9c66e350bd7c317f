"""Input/output helpers: atomic file writing and a small TOML writer."""

from coopctrl.io.atomic import atomic_write
from coopctrl.io.toml_writer import dumps_toml

__all__ = ["atomic_write", "dumps_toml"]
