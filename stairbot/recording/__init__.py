"""Recording a run (``--record FILE``: MCAP or JSON lines) and plotting one
(``stairbot plot``).  The Foxglove SDK, the ``mcap`` reader and matplotlib
are imported only by the modules that need them, and only when used."""
