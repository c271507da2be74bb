"""Issue 35, a connection manager: ``u`` lists the robots this machine
offers -- running fake boards, serial ports, CAN buses, the simulation, the
URLs opened before -- and Enter on one opens it as a typed URL would be.
A source that fails (pyserial, python-can, a corrupt file) is a line on the
screen, never a traceback nor an empty manager."""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import can
import pytest
from lockstep_boards import lockstep_boards
from pilot import banner, press, ready, type_into, until
from serial.tools import list_ports
from textual.widgets import Input, OptionList

from stairbot.console import connections, recent
from stairbot.console.app import build_app
from stairbot.console.connect_screen import ConnectScreen
from stairbot.console.help import HelpScreen
from stairbot.fakes import registry


@pytest.fixture
def own_dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    return tmp_path


async def open_manager(pilot: Any) -> ConnectScreen:
    await press(pilot, "u")
    await until(pilot, lambda: isinstance(pilot.app.screen, ConnectScreen)
                and pilot.app.screen.listing is not None, "the manager's list")
    screen = pilot.app.screen
    assert isinstance(screen, ConnectScreen)
    return screen


def highlighted_url(screen: ConnectScreen) -> str | None:
    robots = screen.query_one(OptionList)
    if robots.highlighted is None:
        return None
    return screen.urls.get(robots.get_option_at_index(robots.highlighted).id or "")


async def highlight(pilot: Any, screen: ConnectScreen, url: str) -> None:
    """Move the list's cursor with the arrow keys to the row of ``url``."""
    for key in ("up", "down"):
        for _ in range(len(screen.urls) + 1):
            if highlighted_url(screen) == url:
                return
            await press(pilot, key)
    raise AssertionError(f"no row of {url}")


def notes(screen: ConnectScreen) -> str:
    return str(screen.query_one("#connect-notes").render())


def test_running_fake_boards_are_listed_and_their_row_opens_them(own_dirs: Path) -> None:
    with lockstep_boards(own_dirs) as boards:
        async def go() -> None:
            app = build_app(speed="max")
            async with app.run_test(size=(100, 30)) as pilot:
                await ready(pilot)
                screen = await open_manager(pilot)
                listing = screen.listing
                assert listing is not None
                fake = listing.group("Fake boards")
                assert [e.url for e in fake] == [boards.url]
                assert f"pid {boards.proc.pid}" in fake[0].description
                assert f"motor board serial {boards.motor_serial}" in fake[0].description
                assert [e.url for e in listing.group("Simulation")] == ["sim://"]
                assert highlighted_url(screen) == "sim://"  # the robot open now
                await highlight(pilot, screen, boards.url)
                await press(pilot, "enter")
                await until(pilot, lambda: len(app.screen_stack) == 1, "the manager closes")
                await app.workers.wait_for_complete()
                await until(pilot, lambda: "READY" in banner(app), "the boards are ready")
                assert app.url == boards.url
                assert app.engine.session is not None and not app.engine.in_process
                # the URL opened is remembered, newest first
                screen = await open_manager(pilot)
                assert screen.listing is not None
                assert [e.url for e in screen.listing.group("Recent")] == [boards.url, "sim://"]
                assert highlighted_url(screen) == boards.url
                await press(pilot, "escape")
                await until(pilot, lambda: len(app.screen_stack) == 1, "closed")
                assert app.url == boards.url  # Escape changed nothing
        asyncio.run(go())
    assert boards.returncode == 0
    assert not list((own_dirs / "run" / "stairbot" / "fake-boards").glob("*.json"))


def test_a_registry_entry_whose_process_is_gone_is_not_listed(own_dirs: Path) -> None:
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    folder = registry.registry_dir()
    folder.mkdir(parents=True)
    entry = {"url": "serial:///dev/pts/999", "pid": gone.pid, "proc_start": None,
             "started": 1.0, "wire": "serial", "scenario": "default", "config": "reference",
             "serials": "motor board serial 1"}
    (folder / f"{gone.pid}.json").write_text(json.dumps(entry))
    # this process's pid, but started at another time: a pid reused
    reused = {**entry, "url": "serial:///dev/pts/998", "pid": os.getpid(), "proc_start": 1}
    (folder / f"{os.getpid()}.json").write_text(json.dumps(reused))
    (folder / "junk.json").write_text("{not json")
    listing = connections.gather(sim="the simulation")
    assert listing.group("Fake boards") == []
    assert not (folder / f"{gone.pid}.json").exists()  # cleaned
    assert not (folder / f"{os.getpid()}.json").exists()
    assert any("junk.json ignored" in p for p in listing.problems)
    # a live one is listed
    with registry.registered("serial:///dev/pts/997", wire="serial", scenario="default",
                             config="reference", serials="motor board serial 2") as path:
        assert path is not None and path.exists()
        listing = connections.gather(sim="the simulation")
        assert [e.url for e in listing.group("Fake boards")] == ["serial:///dev/pts/997"]
    assert not path.exists()


def test_failing_serial_and_can_listing_leave_a_usable_manager(
        own_dirs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_ports() -> list[Any]:
        raise OSError(5, "Input/output error")

    def no_buses(**_: Any) -> list[Any]:
        raise RuntimeError("driver exploded")

    monkeypatch.setattr(list_ports, "comports", no_ports)
    monkeypatch.setattr(can, "detect_available_configs", no_buses)

    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = await open_manager(pilot)
            said = notes(screen)
            assert "serial ports: cannot list them: OSError" in said
            assert "cannot look for buses: RuntimeError: driver exploded" in said
            assert screen.listing is not None
            assert screen.listing.group("Serial ports") == []
            assert screen.listing.group("CAN buses") == []
            assert [e.url for e in screen.listing.group("Simulation")] == ["sim://"]
            # still usable: F5 looks again, a URL typed opens, a bad one is a message
            await press(pilot, "f5")
            await until(pilot, lambda: screen.listing is not None, "looked again")
            await type_into(pilot, "bogus://nowhere")
            await until(pilot, lambda: "unknown scheme 'bogus'" in banner(app), "the message")
            await app.workers.wait_for_complete()
            assert app.url == "sim://" and app.engine.session is not None  # kept
    asyncio.run(go())


def test_a_corrupt_recent_file_is_said_and_replaced(own_dirs: Path) -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            path = recent.recent_path()
            assert json.loads(path.read_text()) == {"urls": ["sim://"]}
            path.write_bytes(b"\x00\xff not json")
            screen = await open_manager(pilot)
            assert "recent URLs ignored" in notes(screen)
            assert screen.listing is not None and screen.listing.group("Recent") == []
            await highlight(pilot, screen, "sim://")
            await press(pilot, "enter")  # opens: the list is written anew
            await until(pilot, lambda: len(app.screen_stack) == 1, "closed")
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "READY" in banner(app), "reopened")
            assert json.loads(path.read_text()) == {"urls": ["sim://"]}
    asyncio.run(go())


def test_over_the_manager_space_stops_and_letters_run_no_command(own_dirs: Path) -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = await open_manager(pilot)
            top = app.top_shown
            await press(pilot, "p", "t", "question_mark", "s")
            await pilot.pause(0.1)
            assert app.screen is screen and app.top_shown == top
            assert not any(isinstance(s, HelpScreen) for s in app.screen_stack)
            assert not app.engine.running
            await press(pilot, "space")
            await until(pilot, lambda: app.state.view().status.estopped, "the stop")
            assert app.screen is screen  # the manager stays; the robot is stopped
    asyncio.run(go())


def test_the_recent_list_keeps_the_newest_ten_once_each(tmp_path: Path) -> None:
    path = tmp_path / "recent.json"
    for i in range(12):
        assert recent.remember(f"serial:///dev/ttyUSB{i}", path) is None
    assert recent.remember("serial:///dev/ttyUSB5", path) is None
    urls, problem = recent.load(path)
    assert problem is None
    assert urls[0] == "serial:///dev/ttyUSB5" and len(urls) == recent.MAX_RECENT
    assert urls.count("serial:///dev/ttyUSB5") == 1
    assert "serial:///dev/ttyUSB1" not in urls  # the oldest went
    assert [p.name for p in tmp_path.iterdir()] == ["recent.json"]  # no temporary left


def test_one_can_interface_failing_costs_only_its_own_entries(
        own_dirs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def detect(interfaces: list[str]) -> list[dict[str, Any]]:
        (name,) = interfaces
        if name == "pcan":
            raise OSError("PCANBasic library not found")
        if name == "socketcan":
            return [{"interface": "socketcan", "channel": "vcan0"}]
        if name == "udp_multicast":
            return [{"interface": "udp_multicast", "channel": "ff15::1"},
                    {"interface": "udp_multicast", "channel": "239.74.163.2"}]
        return []

    listing = connections.gather(sim="the simulation", detect=detect)
    assert [e.url for e in listing.group("CAN buses")] == [
        "can://socketcan/vcan0", "can://udp_multicast/239.74.163.2"]
    (problem,) = [p for p in listing.problems if p.startswith("CAN")]
    assert problem == "CAN: pcan: cannot look for buses: OSError: PCANBasic library not found"
    skipped = "\n".join(listing.skipped)
    assert "udp_multicast ff15::1: an IPv6 group" in skipped
    assert "virtual: a bus inside one process" in skipped


def test_r_looks_again_from_the_list_and_is_a_letter_in_the_field(
        own_dirs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    looks: list[str] = []
    real = connections.gather

    def counted(**kwargs: Any) -> connections.Listing:
        looks.append(kwargs["sim"])
        return real(**kwargs)

    monkeypatch.setattr(connections, "gather", counted)

    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = await open_manager(pilot)
            assert len(looks) == 1
            await press(pilot, "r")
            await until(pilot, lambda: len(looks) == 2 and screen.listing is not None,
                        "looked again")
            field = screen.query_one("#url", Input)
            field.focus()
            await until(pilot, lambda: screen.focused is field, "the field focused")
            await press(pilot, "end", "r")
            await pilot.pause(0.1)
            assert len(looks) == 2 and field.value == "sim://r"
            await press(pilot, "escape")
            await until(pilot, lambda: len(app.screen_stack) == 1, "closed")
            assert app.url == "sim://"
    asyncio.run(go())


@pytest.mark.parametrize("started", [1e300, float("nan"), -5.0])
def test_a_registry_entry_with_an_impossible_start_is_a_line_not_an_empty_manager(
        own_dirs: Path, started: float) -> None:
    # a live pid (this process's), start time not known: the entry is believed
    # but for its start, which no time of day can show
    folder = registry.registry_dir()
    folder.mkdir(parents=True)
    entry = {"url": "serial:///dev/pts/996", "pid": os.getpid(), "proc_start": None,
             "started": started, "wire": "serial", "scenario": "default",
             "config": "reference", "serials": "motor board serial 3"}
    (folder / "odd.json").write_text(json.dumps(entry))
    listing = connections.gather(sim="the simulation", comports=lambda: [],
                                 detect=lambda **_: [])
    assert listing.group("Fake boards") == []
    assert [e.url for e in listing.group("Simulation")] == ["sim://"]
    assert any("odd.json ignored" in p and "started" in p for p in listing.problems)


def test_a_fifo_in_the_registry_is_a_line_and_never_holds_the_look(own_dirs: Path) -> None:
    # opened blocking, a FIFO waits for a writer: the manager looked forever
    # and the console, quitting, waited for the look
    folder = registry.registry_dir()
    folder.mkdir(parents=True)
    os.mkfifo(folder / "pipe.json")
    looked: list[connections.Listing] = []
    worker = threading.Thread(target=lambda: looked.append(connections.gather(
        sim="the simulation", comports=lambda: [], detect=lambda **_: [])), daemon=True)
    worker.start()
    worker.join(timeout=30)  # only stops a broken test: the look never waits on anyone
    if not looked:
        with open(folder / "pipe.json", "w"):  # let the blocked look go
            pass
        raise AssertionError("the look waited on the FIFO")
    assert any("pipe.json ignored: not a regular file" in p for p in looked[0].problems)
    assert [e.url for e in looked[0].group("Simulation")] == ["sim://"]


def test_a_registry_full_of_junk_says_how_many_problems_it_cannot_show(
        own_dirs: Path) -> None:
    folder = registry.registry_dir()
    folder.mkdir(parents=True)
    for n in range(20):
        (folder / f"junk{n:02}.json").write_text("{not json")

    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = await open_manager(pilot)
            shown = notes(screen).splitlines()
            assert len(shown) == 4
            assert "junk00.json ignored" in shown[0]
            assert shown[-1] == "... and 17 more problems like these"
            box = screen.query_one("#connect-notes")
            rows = [strip.text for strip in box.render_lines(box.content_region.reset_offset)]
            assert rows[-1].strip() == shown[-1], rows  # the count is on screen, not cut
    asyncio.run(go())


def test_enter_on_an_empty_url_field_says_why_and_keeps_the_manager(own_dirs: Path) -> None:
    """Issue 35's closing note: an empty field and Enter closed the manager
    without a word."""
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = await open_manager(pilot)
            await type_into(pilot, "   ")
            await pilot.pause(0.2)
            assert app.screen is screen  # still open
            why = str(screen.query_one("#connect-why").render())
            assert why == "enter a URL or pick one from the list"
            assert screen.query_one("#connect-why").display
            assert app.url == "sim://"
            field = screen.query_one(Input)
            assert field.has_focus  # typing goes on where it was
            await press(pilot, "x")
            await until(pilot, lambda: not screen.query_one("#connect-why").display,
                        "the line goes once something is typed")
            assert app.screen is screen and field.value.strip() == "x"
    asyncio.run(go())


def test_a_look_that_ends_as_the_manager_closes_is_dropped(own_dirs: Path) -> None:
    """The manager closed (Enter on a URL) while its look ran, and the look's
    answer came back while the closing screen had lost its widgets but not
    yet left the app: the list it would fill was gone, the worker failed and
    took the console down with it (CI, after session 46)."""
    release = threading.Event()

    def slow_gather(**_: Any) -> connections.Listing:
        release.wait(timeout=30)  # only stops a broken test
        return connections.Listing()

    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            screen = ConnectScreen(app.url, "the simulation", gather=slow_gather)
            app.push_screen(screen)
            await until(pilot, lambda: app.screen is screen, "the manager")
            await screen.query_one("#connect").remove()  # closing: its widgets go first
            screen.dismiss(None)  # off the stack now; detached at the loop's next turn
            assert screen.is_attached
            screen._show(connections.Listing())  # the look's answer, in between
            release.set()
            await pilot.pause(0.2)
            assert app.is_running and app.screen is not screen
            await press(pilot, "s")  # the console still runs
            await until(pilot, lambda: app.engine.running or "ENDED" in banner(app), "a run")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())
