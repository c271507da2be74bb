"""A run: the loop that reads, ticks, commands and advances (``runner``),
the robot opened by URL (``robots``), the journal a run keeps and reads
back (``journal``, ``journal_read``, ``journaled``), what a resume checks
(``resume``), and the names of the files it writes (``paths``).  It builds
on the control package; the drivers and fakes plug in by URL."""
