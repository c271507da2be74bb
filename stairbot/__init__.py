"""stairbot: host software for a three-segment stair-climbing robot.

The core (this package, apart from the ``drivers``, ``fakes`` and ``console``
subpackages that install from their own top-level folders) is pure Python: it
imports nothing of textual, pymunk, serial or can.
"""

__version__ = "0.1.0"
