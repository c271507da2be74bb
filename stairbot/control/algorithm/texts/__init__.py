"""The texts the phases emit, in one place: one function per message, taking
the figures and returning the string (an INFO event's message, an error's or
an end's reason, the reason a phase change gives).  One module per flow
(calibration, ascent, descent, landing), and ``shared`` for the phases every
flow uses (a reading drive, the standing rule, the stability check); the
phases' logic calls them and keeps the figures it passes to ``say`` as data.
The controller's own messages (faults, holds, the sensor hold) are its own.
"""
