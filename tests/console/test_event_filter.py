"""Issue 35, "an event log filter (errors, warnings, phases, link) and
search": e steps the event list through its filters, / searches its text;
the title says what is filtered and how many of the events kept it lists."""

from __future__ import annotations

import asyncio

from pilot import answer_prompt, press, ready, until

from stairbot.console.app import build_app
from stairbot.console.widgets.event_log import EventLog
from stairbot.events import Event, EventKind

EVENTS = [
    Event(1.0, EventKind.PHASE, "ascent 3 — lift segment 1"),
    Event(2.0, EventKind.LINK, "link: +1 retries"),
    Event(3.0, EventKind.WARNING, "SFR reads 3 cm long"),
    Event(4.0, EventKind.ERROR, "tilt limit: motors held"),
    Event(5.0, EventKind.INFO, "note about the lift"),
]


def listed(log: EventLog) -> str:
    return "\n".join(strip.text for strip in log.lines)


def test_e_filters_the_events_by_kind_and_slash_searches_them() -> None:
    async def go() -> None:
        app = build_app(url="sim://")
        async with app.run_test(size=(120, 40)) as pilot:
            await ready(pilot)
            for event in EVENTS:
                app.state.on_event(event)
            log = app.log_panel
            await until(pilot, lambda: "tilt limit" in listed(log), "every event listed")
            total = len(log._kept)
            steps = {"errors": ["tilt limit"], "warnings": ["SFR reads", "tilt limit"],
                     "phases": ["lift segment 1"], "link": ["+1 retries"]}
            for kinds, wanted in steps.items():
                await press(pilot, "e")
                await until(pilot, lambda k=kinds: log.kinds == k, kinds)
                text = listed(log)
                assert all(w in text for w in wanted), (kinds, text)
                others = [e.message for e in EVENTS if not any(w in e.message for w in wanted)]
                assert not any(m in text for m in others), (kinds, text)
                assert f"{kinds} only" in str(log.border_title)
                assert f"{len(wanted)} of {total}" in str(log.border_title)
            await press(pilot, "e")  # after the last: every event again
            await until(pilot, lambda: log.kinds == "all", "all")
            assert str(log.border_title) == "events"
            await answer_prompt(pilot, "slash", "LIFT")
            await until(pilot, lambda: log.search == "LIFT", "the search")
            text = listed(log)
            assert "lift segment 1" in text and "note about the lift" in text
            assert "tilt limit" not in text and "SFR reads" not in text
            assert "holding 'LIFT'" in str(log.border_title)
            app.state.on_event(Event(6.0, EventKind.INFO, "another lift event"))
            app.state.on_event(Event(7.0, EventKind.INFO, "unrelated"))
            await until(pilot, lambda: "another lift event" in listed(log), "new ones too")
            assert "unrelated" not in listed(log)
            await answer_prompt(pilot, "slash", "")
            await until(pilot, lambda: "unrelated" in listed(log), "every event again")
    asyncio.run(go())
