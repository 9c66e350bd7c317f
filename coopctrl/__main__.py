"""``python -m coopctrl``: the command line (:func:`coopctrl.cli.main`)."""

import sys

from coopctrl.cli import main

if __name__ == "__main__":
    sys.exit(main())
