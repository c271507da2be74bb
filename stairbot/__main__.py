"""``python -m stairbot``: the same command line as the ``stairbot`` script.

Run from the root of a source checkout, Python finds ``./stairbot`` (the core
alone) before the installed package, and the subpackages that install from
their own top-level folders (``stairbot.drivers``, ``.fakes``, ``.console``)
would be missing.  In that one case the checkout's root joins the package's
search path, so the checkout runs whole, as it would once installed.
"""

import sys
from importlib.util import find_spec
from pathlib import Path

import stairbot

_root = Path(stairbot.__file__).resolve().parent.parent
if find_spec("stairbot.fakes") is None and all(
        (_root / name / "__init__.py").is_file() for name in ("drivers", "fakes", "console")):
    stairbot.__path__.append(str(_root))

from stairbot.cli import main  # noqa: E402 - after the search path is settled

sys.exit(main())
