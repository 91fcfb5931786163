"""``python -m orchestrator``: the ``mechcosim`` command."""

import sys

from orchestrator.entry import main

sys.exit(main())
