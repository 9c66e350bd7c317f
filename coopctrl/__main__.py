"""``python -m coopctrl``: the command line (:func:`coopctrl.cli.console_main`)."""

import sys

try:
    from coopctrl.cli import console_main
except KeyboardInterrupt:  # Ctrl-C during start-up: nothing was written yet
    sys.exit(130)

if __name__ == "__main__":
    console_main()
