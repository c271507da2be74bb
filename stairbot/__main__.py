"""``python -m stairbot``: the same command line as the ``stairbot`` script."""

import sys

from stairbot.cli import main

sys.exit(main())
