"""stairbot: host software for a three-segment stair-climbing robot.

The rooms, one folder each:

* ``stairbot.control.algorithm``  the seed's phases, transitions and controller (pure Python)
* ``stairbot.drivers``    board protocol, serial and CAN transports (pyserial, python-can)
* ``stairbot.fakes``      the pymunk simulation and the fake boards
* ``stairbot.console``    the Textual operator console

and at the top: config, scenarios, the hardware interface, the run loop, the
CLI and events.  The core (everything but drivers, fakes and console) imports
nothing of textual, pymunk, serial or can.
"""

__version__ = "0.1.0"

from stairbot import compiled as _compiled

_compiled.guard()  # before any compiled module is imported: a stale one runs as Python
