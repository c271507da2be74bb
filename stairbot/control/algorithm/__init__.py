"""The seed's algorithm: phases, the transition table, the controller.

Pure Python, driven only by snapshots and their times; see docs/algorithm.md.
"""
