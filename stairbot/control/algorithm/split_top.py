"""Ascent 8 on a split pair: ascent 7 found no tab (one front sensor at least
read nothing ahead), and now one reads a distance and the other "nothing
ahead".

Two things read so.  A riser about LENGTH_OF_INFINITY away, which one beam
reaches and the other not (the ir robot, LENGTH_OF_INFINITY 0.75 m, on a
0.9 m tread): the ascent goes on, and the descent of this step reads its
tab standing here, or finds its edge by the back pair alone.  Or no riser
at all: the nearer beam's cone grazing a side wall beside an open top (a
second flight climbed a few degrees askew towards the landing's far wall,
which runs on past its top).  Both beams on one riser read no further
apart than the robot standing MAX_SQUARE_YAW_RAD askew of it allows
(:func:`~stairbot.control.algorithm.squaring.one_riser`, 58 mm on the
reference robot); a nearer reading more than that short of
LENGTH_OF_INFINITY is not of the riser the other beam misses.  Where ascent
3 of this step measured no riser ahead either (``length_of_next_step`` is
None: the drives onto the step went by turns, as onto the top), that is the
top: the descent begins here, as from any top.  Going on, the next
calibration took the wall for the riser and turned towards it until the
robot met it (docs/envelope.md, "Quarter-turn landings")."""

from __future__ import annotations

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.modes import AscentEnd
from stairbot.control.algorithm.phase import NO_MOTION, Step, Tick, go, stay
from stairbot.control.algorithm.squaring import one_riser
from stairbot.control.algorithm.texts import ascent as say
from stairbot.control.algorithm.work import WaitWork
from stairbot.hardware import FRONT_SENSORS

TAB_WAIT_S = 1.0
"""Ascent 8: how long the robot stands for a tab ascent 7 found not
measurable while the pair does not read "nothing ahead" either."""


def tab_again(t: Tick, w: WaitWork) -> Step | None:
    """Ascent 7 found no tab and the pair does not read "nothing ahead" now:
    stand up to TAB_WAIT_S for the pair to read it (kept), or both nothing
    (the top: ascent 8 itself decides it).  Still split after it: the top
    where the nearer beam reads no riser (:func:`beside_the_top`); otherwise
    go on, and descent 1 finds this step's edge by the back pair alone.  The
    split reading is not otherwise taken for the top: one sensor reading a
    little long, the robot askew at the flight's side, would then end the
    ascent, and coming down the step it stands on from there tips the robot
    back.  None: go on."""
    ctx, cfg = t.ctx, t.cfg
    i = ctx.number_of_steps - 1
    if not 0 <= i < len(ctx.tab_length_to_edge) or ctx.tab_length_to_edge[i] is not None:
        return None
    if motion.measurable(t.snap, cfg):
        tab = ctx.tab_length_to_edge[i] = motion.mean_distance(t.snap)
        t.say(say.tab_read_standing(i, tab), index=i, tab_length_to_edge=tab)
        return None
    if w.still_since is None:
        w.still_since = t.snap.time_s
    if t.snap.time_s - w.still_since < TAB_WAIT_S:
        return stay(NO_MOTION)
    sfr, sfl = motion.pair(t.snap)
    near = beside_the_top(t)
    if near is not None:
        ctx.ascent_end = AscentEnd.TOP_REACHED
        t.say(say.top_beside(ctx.number_of_steps, near, sfr.distance_m, sfl.distance_m,
                             one_riser(cfg), TAB_WAIT_S), ascent_end="top_reached")
        return go("top_reached")
    t.say(say.tab_not_measured(i, sfr.distance_m, sfl.distance_m, TAB_WAIT_S))
    return None  # the phase goes on this tick


def beside_the_top(t: Tick) -> str | None:
    """The sensor (its name) that reads a distance while its partner reads
    "nothing ahead", where that reading is more than one riser's spread
    short of LENGTH_OF_INFINITY and ascent 3 of this step measured no riser
    ahead: it sees no riser, and nothing ahead is the top.  None otherwise."""
    ctx, cfg = t.ctx, t.cfg
    if ctx.length_of_next_step is not None:
        return None  # a riser measured: going on, the descent of this step finds its edge
    pair = motion.pair(t.snap)
    for i, sid in enumerate(FRONT_SENSORS):
        seen, partner = pair[i], pair[1 - i]
        if (seen.ok and not motion.far(seen, cfg) and motion.far(partner, cfg)
                and cfg.LENGTH_OF_INFINITY - seen.distance_m > one_riser(cfg)):
            return sid.value
    return None
