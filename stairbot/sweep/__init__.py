"""Sweeps: many generated cases over stair geometry, start pose, sensors, faults
and robot config, each run on the simulated robot and judged against the
robot's published limits (``stairbot sweep SPEC.toml``; docs/envelope.md).

* ``spec``     the spec file: axes, distributions, verdict rules (SpecError)
* ``cases``    case index -> scenario and config TOML, validated up front
* ``verdict``  the rules that turn a run's result into a verdict
* ``worker``   runs one case in-process (what an executor calls)
* ``execute``  process pool or Dask, durable JSONL results, resume, Ctrl-C
* ``report``   verdict table, worst cases, heat maps (terminal and PNG)
* ``coverage`` the margins' distribution and each axis's coverage in the report
* ``objective`` what a search minimises: a margin, or the least normalised one
* ``search``   ``--search N``: Optuna's TPE chooses the cases (``search_run``: the command)
"""
