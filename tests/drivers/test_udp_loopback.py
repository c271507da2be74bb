"""``can://udp_multicast`` listens on loopback only (issue 11, item 4): the
socket stairbot opens is bound to the group, joined on 127.0.0.1 and sends
out of it with TTL 0; a frame sent to the group from this machine's LAN
address (as another host's would arrive) or unicast to that address is not
taken, while a frame from a bus on loopback is; ``lan=1`` is python-can's
socket, which does take it.

The "other host" is this machine's own non-loopback address: a datagram sent
to the group from it with TTL 0 never reaches the wire, and the kernel loops
it back as received on that interface, where a LAN host's would arrive.  A
witness socket that joined the group there (as python-can's bus does) proves
it arrived; for the unicast one, the kernel's "port unreachable" answer
proves that it arrived and that no socket on this machine took it."""

from __future__ import annotations

import fcntl
import ipaddress
import random
import select
import socket
import struct
import sys
from collections.abc import Iterator
from pathlib import Path

import can
import pytest
from can.interfaces.udp_multicast import UdpMulticastBus
from can.interfaces.udp_multicast.utils import pack_message, unpack_message

from stairbot.drivers.can_robot import open_bus, parse_can_url
from stairbot.drivers.udp_loopback import IP_MULTICAST_ALL, LoopbackUdpMulticastBus

SIOCGIFFLAGS, SIOCGIFADDR = 0x8913, 0x8915
IFF_UP, IFF_MULTICAST = 0x1, 0x1000
IGMP = Path("/proc/net/igmp")

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="reads interfaces and memberships the Linux way")


def lan_address() -> str | None:
    """An IPv4 address of this machine on an interface that is up, carries
    multicast and is not loopback; None when there is none."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _, name in socket.if_nameindex():
            req = struct.pack("256s", name.encode()[:15])
            try:
                flags = struct.unpack_from("H", fcntl.ioctl(s.fileno(), SIOCGIFFLAGS, req), 16)[0]
                addr = socket.inet_ntoa(fcntl.ioctl(s.fileno(), SIOCGIFADDR, req)[20:24])
            except OSError:  # no IPv4 address on it
                continue
            if flags & IFF_UP and flags & IFF_MULTICAST and not ipaddress.ip_address(
                    addr).is_loopback:
                return addr
    return None


def joined_on(group: str) -> set[str]:
    """The interfaces on which some socket on this machine joined ``group``."""
    code = f"{struct.unpack('=I', socket.inet_aton(group))[0]:08X}"
    devices, device = set(), ""
    for line in IGMP.read_text().splitlines()[1:]:
        if line[:1].isdigit():
            device = line.split()[1]
        elif line.split()[:1] == [code]:
            devices.add(device)
    return devices


def frame(data: bytes) -> can.Message:
    return can.Message(arbitration_id=0x0EF, data=data, is_extended_id=False)


@pytest.fixture
def bus_url() -> tuple[str, str, int]:
    group = f"239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"
    port = random.randrange(40000, 60000)
    return f"can://udp_multicast/{group}?port={port}", group, port


@pytest.fixture
def lan() -> str:
    address = lan_address()
    if address is None:
        pytest.skip("this machine has no non-loopback IPv4 address to send from")
    return address


class LanSide:
    """Senders on the LAN address, and a witness: a socket bound to the group
    that joined it on the LAN interface (as python-can's own bus does), to
    prove that what was sent there arrived."""

    def __init__(self, lan: str, group: str, port: int) -> None:
        self.lan, self.group, self.port = lan, group, port
        self.witness = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.witness.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.witness.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        self.witness.bind((group, port))  # so it takes, and competes for, no unicast
        self.witness.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                                socket.inet_aton(group) + socket.inet_aton(lan))
        self.sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sender.bind((lan, 0))
        self.sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(lan))
        self.sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)  # never the wire
        self.sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)

    def send(self, data: bytes) -> None:
        """A frame in python-can's wire format to the group, from the LAN
        address; returns once the witness has it."""
        self.sender.sendto(pack_message(frame(data)), (self.group, self.port))
        assert select.select([self.witness], [], [], 2.0)[0], "the frame did not arrive"
        got, source = self.witness.recvfrom(4096)
        assert source[0] == self.lan and bytes(unpack_message(got).data) == data

    def unicast(self, data: bytes) -> socket.socket:
        """A frame sent to the LAN address itself, from a socket connected
        there: if no socket on this machine takes it, the kernel answers port
        unreachable and that socket's next recv raises ConnectionRefusedError."""
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind((self.lan, 0))
        sock.connect((self.lan, self.port))
        sock.send(pack_message(frame(data)))
        return sock

    def close(self) -> None:
        self.witness.close()
        self.sender.close()


@pytest.fixture
def lan_side(lan: str, bus_url: tuple[str, str, int]) -> Iterator[LanSide]:
    side = LanSide(lan, bus_url[1], bus_url[2])
    yield side
    side.close()


def test_the_bus_is_bound_to_the_group_joined_and_sending_on_loopback_with_ttl_0(
        bus_url: tuple[str, str, int]) -> None:
    url, group, port = bus_url
    bus = open_bus(parse_can_url(url))
    try:
        assert isinstance(bus, LoopbackUdpMulticastBus)
        sock: socket.socket = bus._multicast._socket
        assert sock.getsockname() == (group, port)  # not 0.0.0.0: no unicast
        ip = socket.IPPROTO_IP
        assert socket.inet_ntoa(sock.getsockopt(ip, socket.IP_MULTICAST_IF, 4)) == "127.0.0.1"
        assert sock.getsockopt(ip, socket.IP_MULTICAST_TTL) == 0
        assert sock.getsockopt(ip, socket.IP_MULTICAST_LOOP) == 1
        assert sock.getsockopt(ip, IP_MULTICAST_ALL) == 0  # only its own memberships
        if IGMP.exists():
            assert joined_on(group) == {"lo"}
        assert "on loopback" in bus.channel_info
    finally:
        bus.shutdown()


def test_a_frame_from_another_address_is_not_taken_one_from_loopback_is(
        bus_url: tuple[str, str, int], lan_side: LanSide) -> None:
    bus, peer = open_bus(parse_can_url(bus_url[0])), open_bus(parse_can_url(bus_url[0]))
    try:
        lan_side.send(b"LAN")  # arrived on this machine, from its LAN address
        with lan_side.unicast(b"unicast") as sender:
            sender.settimeout(2.0)
            with pytest.raises(ConnectionRefusedError):  # arrived, and nobody took it
                sender.recv(1)
        peer.send(frame(b"lo"))
        got = bus.recv(timeout=2.0)
        assert got is not None and bytes(got.data) == b"lo"  # the LAN ones queued first: none
        assert bus.recv(timeout=0.2) is None
    finally:
        bus.shutdown()
        peer.shutdown()


def test_lan_1_is_python_cans_socket_and_takes_the_frame_from_the_lan(
        bus_url: tuple[str, str, int], lan_side: LanSide) -> None:
    """The contrast: what every udp_multicast bus did before (bar hop_limit)."""
    bus = open_bus(parse_can_url(bus_url[0] + "&lan=1"))
    try:
        assert type(bus) is UdpMulticastBus
        sock: socket.socket = bus._multicast._socket
        assert sock.getsockname() == ("0.0.0.0", bus_url[2])
        assert sock.getsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL) == 1
        lan_side.send(b"LAN")
        got = bus.recv(timeout=2.0)
        assert got is not None and bytes(got.data) == b"LAN"
        with lan_side.unicast(b"unicast"):
            got = bus.recv(timeout=2.0)
        assert got is not None and bytes(got.data) == b"unicast"
    finally:
        bus.shutdown()


def test_an_ipv6_group_cannot_be_kept_on_loopback() -> None:
    with pytest.raises(can.CanInitializationError, match="IPv6.*IPv4 group"):
        LoopbackUdpMulticastBus("ff15::1", port=random.randrange(40000, 60000))


def test_a_bus_does_not_hear_its_own_frames_every_other_one_does(
        bus_url: tuple[str, str, int]) -> None:
    """python-can's receive_own_messages=False, done in the kernel: a fake
    board process woke for 14 echoes of its own replies each control cycle."""
    bus, peer = open_bus(parse_can_url(bus_url[0])), open_bus(parse_can_url(bus_url[0]))
    try:
        bus.send(frame(b"mine"))
        got = peer.recv(timeout=2.0)
        assert got is not None and bytes(got.data) == b"mine"  # the others hear it
        peer.send(frame(b"yours"))
        got = bus.recv(timeout=2.0)
        assert got is not None and bytes(got.data) == b"yours"  # not b"mine" first
        assert bus.recv(timeout=0.2) is None and peer.recv(timeout=0.2) is None
    finally:
        bus.shutdown()
        peer.shutdown()
