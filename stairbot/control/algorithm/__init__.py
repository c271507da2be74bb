"""The seed's algorithm: phases, the transition table, the controller.

Pure Python, driven only by snapshots and their times; see docs/algorithm.md.
"""

# The phases' records are bound to the Phase enum when the table is imported:
# first, so that no module of the package finds them unbound.
from stairbot.control.algorithm import table as table
