"""``python -m tests.fuzz``: the full fuzz campaign (see ``runner.main``)."""

import sys

from .runner import main

sys.exit(main())
