"""stairbot: host software for a three-segment stair-climbing robot.

The core (this package, apart from the ``drivers``, ``fakes`` and ``console``
subpackages that install from their own top-level folders) is pure Python: it
imports nothing of textual, pymunk, serial or can.
"""

from pathlib import Path as _Path

__version__ = "0.1.0"

# Imported from the root of a source checkout (``python -c``, ``python -m``
# there), Python finds ``./stairbot`` -- the core alone -- before the installed
# package, and the subpackages that live in their own top-level folders would
# be missing.  In that one case the checkout's root joins the package's search
# path, so the checkout imports whole, as it does once installed.  An installed
# wheel has no such sibling folders: nothing changes there.
_root = _Path(__file__).resolve().parent.parent
if all((_root / _name / "__init__.py").is_file() for _name in ("drivers", "fakes", "console")):
    __path__.append(str(_root))  # noqa: F821 - the package's own __path__
del _Path, _root
