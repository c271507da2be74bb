"""The CAN bus's own health, apart from the boards': its state, its error
frames and traffic from other nodes (docs/protocol.md, "The bus's own
health").

* **State.** python-can's ``bus.state`` (``can.BusState``): ACTIVE,
  PASSIVE (error-passive: the controller has seen many errors and may no
  longer signal them) or ERROR (taken as bus-off: the controller has left
  the bus).  An interface that does not report one (python-can's
  ``BusABC.state``, always ACTIVE) is not asked.  SocketCAN reports the
  same in its error frames' class bits instead
  (``CAN_ERR_BUSOFF``; ``CAN_ERR_CRTL`` with the RX/TX passive bits), which
  are read on a SocketCAN bus only: other interfaces' error frames (the fake
  boards' corrupted frames on ``udp_multicast``) keep whatever id they had.
  Bus-off raises BusFaultError: the host can no longer send.
* **Error frames** (``is_error_frame``) are counted as ``error_frames``, not
  as CRC errors: CAN's CRC is checked by the controller, and an error frame
  may be any of the bus's errors.  A storm of them is the controller's to
  judge (error-passive, bus-off: the state above); they are not foreign
  frames, so that a lossy bus in a simulation running faster than real time
  is not taken for a flood.
* **Foreign frames**: frames no board of this protocol sends and no host of
  ours -- undecodable ones, another session's.  Counted per
  window of ``FLOOD_WINDOW_S`` of the link's clock; more than
  ``FLOOD_FRAMES_PER_S`` of them a second is a flood or a babbling node, and
  raises BusFaultError naming the identifier that sent most of them.  The
  protocol's own traffic is at most 21 frames a 20 ms tick (1 050 frames/s,
  section 8's budget), so the limit is twice the bus's whole legitimate load.
"""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

import can

from stairbot.drivers.link import BusFaultError

if TYPE_CHECKING:
    from stairbot.drivers.can_link import CanStats

FLOOD_WINDOW_S = 0.25
FLOOD_FRAMES_PER_S = 2000

# SocketCAN's error frame: class bits in the id, controller status in data[1]
# (linux/can/error.h).
CAN_ERR_CRTL = 0x004
CAN_ERR_BUSOFF = 0x040
CAN_ERR_RESTARTED = 0x100
CAN_ERR_CRTL_PASSIVE = 0x10 | 0x20  # RX and TX error-passive
CAN_ERR_CRTL_ACTIVE = 0x40


class BusState(IntEnum):
    """The bus state as a figure of the link health (``bus_state``)."""

    ACTIVE = 0
    PASSIVE = 1
    BUS_OFF = 2


_FROM_PYTHON_CAN = {can.BusState.ACTIVE: BusState.ACTIVE, can.BusState.PASSIVE: BusState.PASSIVE,
                    can.BusState.ERROR: BusState.BUS_OFF}


def frame_name(frame: can.Message) -> str:
    """A frame's identifier as a person reads it: 0x000 (11-bit), 0x1FFC0000
    (29-bit)."""
    width = 8 if frame.is_extended_id else 3
    return f"id 0x{frame.arbitration_id:0{width}X}"


def socketcan_errors(bus: object) -> bool:
    """Whether ``bus``'s error frames carry SocketCAN's error classes in their
    id (linux/can/error.h): a ``SocketcanBus``, or a bus that says so with a
    ``socketcan_errors`` attribute (a test double)."""
    return bool(getattr(bus, "socketcan_errors", type(bus).__name__ == "SocketcanBus"))


class BusWatch:
    """The bus's state and its foreign frames, for one link: figures in
    ``stats`` (a CanStats: ``bus_state``, ``bus_passive``, ``error_frames``,
    ``foreign``, ``flood_id``, ``flood_per_s``) and BusFaultError when the
    bus is off or flooded."""

    def __init__(self, stats: CanStats, error_classes: bool = False) -> None:
        self.stats = stats
        self.error_classes = error_classes  # error frames in SocketCAN's layout
        self._window_start = float("-inf")
        # (id, its name, what it is) -> frames this window
        self._counts: dict[tuple[int, str, str], int] = {}
        self._total = 0
        self.last_flood: str | None = None

    # -- the state ---------------------------------------------------------------
    def read_state(self, bus: can.BusABC) -> None:
        """Take the interface's ``bus.state``, if it reports one (not
        ``BusABC``'s, which always says ACTIVE); BusFaultError on bus-off."""
        if getattr(type(bus), "state", None) is can.BusABC.state:
            return  # no state of its own: its error frames may tell (error_frame)
        try:
            state = bus.state
        except (NotImplementedError, AttributeError, can.CanError):
            return
        if state is None:
            return
        self.set_state(_FROM_PYTHON_CAN.get(state, BusState.ACTIVE),
                       f"the CAN interface reports bus state {getattr(state, 'name', state)}")

    def set_state(self, state: BusState, source: str) -> None:
        st = self.stats
        if state == BusState.PASSIVE and st.bus_state != BusState.PASSIVE:
            st.bus_passive += 1
        st.bus_state = int(state)
        if state == BusState.BUS_OFF:
            raise BusFaultError(f"the CAN bus is off ({source}: this host's controller has "
                                "left the bus after too many errors and can send nothing)")

    def error_frame(self, frame: can.Message) -> None:
        """Count an error frame and read its SocketCAN class bits (on a bus
        whose error frames have them)."""
        self.stats.error_frames += 1
        cls = frame.arbitration_id if self.error_classes else 0
        ctrl = frame.data[1] if len(frame.data) > 1 else 0
        if cls & CAN_ERR_BUSOFF:
            self.set_state(BusState.BUS_OFF, "an error frame says bus-off")
        elif cls & CAN_ERR_CRTL and ctrl & CAN_ERR_CRTL_PASSIVE:
            self.set_state(BusState.PASSIVE, "an error frame says error-passive")
        elif cls & CAN_ERR_RESTARTED or (cls & CAN_ERR_CRTL and ctrl & CAN_ERR_CRTL_ACTIVE):
            self.set_state(BusState.ACTIVE, "an error frame says error-active")

    # -- foreign frames ------------------------------------------------------------
    def foreign(self, frame: can.Message, what: str, now: float) -> None:
        """Count a frame from another node (``what`` it is: malformed,
        another session's...); BusFaultError the moment this window's count
        passes the flood limit."""
        self.stats.foreign += 1
        if now - self._window_start >= FLOOD_WINDOW_S:
            self._window_start, self._counts, self._total = now, {}, 0
        key = (frame.arbitration_id, frame_name(frame), what)
        self._counts[key] = self._counts.get(key, 0) + 1
        self._total += 1
        if self._total == int(FLOOD_FRAMES_PER_S * FLOOD_WINDOW_S) + 1:
            (frame_id, name, kind), n = max(self._counts.items(), key=lambda kv: kv[1])
            rate = self._total / FLOOD_WINDOW_S
            self.stats.flood_id = frame_id
            self.stats.flood_per_s = int(rate)
            self.last_flood = (
                f"a flood on the CAN bus: {self._total} frames from another node within "
                f"{FLOOD_WINDOW_S * 1e3:.0f} ms (at least {rate:.0f}/s; this protocol's own "
                f"traffic is at most 1050/s, the limit {FLOOD_FRAMES_PER_S}/s), {n} of them "
                f"{name} ({kind})")
            raise BusFaultError(self.last_flood)

    def trouble(self) -> str | None:
        """The bus's trouble, for a lost link's message: error-passive, a
        flood seen, foreign frames in the present window; None if none."""
        parts = []
        if self.stats.bus_state == BusState.PASSIVE:
            parts.append("the CAN bus is error-passive")
        if self.last_flood is not None:
            parts.append(self.last_flood)
        elif self._total:
            (_, name, kind), n = max(self._counts.items(), key=lambda kv: kv[1])
            parts.append(f"{self._total} frames from other nodes on the CAN bus lately, "
                         f"{n} of them {name} ({kind})")
        return "; ".join(parts) or None
