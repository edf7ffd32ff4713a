"""``python -m navlab.cli``: the ``navlab`` command."""

import sys

from navlab.cli import main

if __name__ == "__main__":
    sys.exit(main())
