"""``python -m coopctrl``: the command line (:func:`coopctrl.cli.main`)."""

import sys

try:
    from coopctrl.cli import main
except KeyboardInterrupt:  # Ctrl-C during start-up: nothing was written yet
    sys.exit(130)

if __name__ == "__main__":
    sys.exit(main())
