"""``python -m navlab.cli``: the ``navlab`` command."""

import sys

from navlab.cli import main

sys.exit(main())
