"""python-can's ``udp_multicast`` bus, kept on this machine's loopback interface.

python-can's own :class:`~can.interfaces.udp_multicast.UdpMulticastBus` binds
``0.0.0.0:PORT`` and joins the group on the interface the routing table
picks, usually the LAN one: any host on the network can send it frames, and a
unicast datagram to any of this host's addresses on PORT is taken as a frame
too.  python-can has no option for the bind address or the interface, so
:class:`LoopbackUdpMulticastBus` is python-can's bus with its socket built
here instead:

* bound to the group address itself (``239.74.163.2:PORT``), so only
  datagrams addressed to the group are taken, never unicast ones;
* the group joined on the loopback interface only (``127.0.0.1``), and on
  Linux ``IP_MULTICAST_ALL`` off, so that the group's datagrams arriving on
  another interface (joined there by some other socket) are not delivered
  here;
* sending out of loopback (``IP_MULTICAST_IF`` ``127.0.0.1``) with the TTL 0
  by default and multicast loop on: the frames reach this machine's other
  processes and no other machine;
* sending from a socket of its own (``127.0.0.1``, a port the kernel picks),
  whose datagrams the receiving socket drops in the kernel (a socket filter on
  their source port): a bus does not hear its own frames, as python-can's
  ``receive_own_messages=False`` means.  Without it every process on the
  group woke for, read and decoded each of its own frames -- 14 of the 17 a
  fake-board process heard each control cycle -- and at x20 scaled real time
  that cost the boards a fifth of a core.

Everything else (frame encoding, timestamps, receiving) is python-can's.
IPv4 groups only: Linux does not deliver IPv6 multicast over ``lo`` (not
even with ``ip link set lo multicast on`` and a multicast route on it), so an
IPv6 group raises CanInitializationError here; ``can_robot`` refuses it with
a RobotUrlError first.  ``can_robot.open_bus`` opens this bus for
``udp_multicast`` unless the URL says ``lan=1``.
"""

from __future__ import annotations

import ctypes
import socket
import struct
import sys
from typing import Any

import can
from can import CanProtocol
from can.interfaces.udp_multicast.bus import (
    SO_TIMESTAMPNS,
    GeneralPurposeUdpMulticastBus,
    UdpMulticastBus,
)
from can.interfaces.udp_multicast.utils import is_msgpack_installed

LOOPBACK_V4 = "127.0.0.1"
# Linux's values; Python's socket module does not export them.
IP_MULTICAST_ALL = getattr(socket, "IP_MULTICAST_ALL", 49)
SO_ATTACH_FILTER = getattr(socket, "SO_ATTACH_FILTER", 26)
_LINUX = sys.platform.startswith("linux")


def _drop_source_port(sock: socket.socket, port: int) -> None:
    """A classic BPF socket filter on ``sock`` (Linux): datagrams whose UDP
    source port is ``port`` are dropped in the kernel, the rest taken whole.
    A UDP socket's filter sees the datagram from its UDP header on."""
    program = [  # (code, jt, jf, k)
        (0x28, 0, 0, 0),           # ldh [0]: the source port
        (0x15, 0, 1, port),        # jeq #port: next, else skip one
        (0x06, 0, 0, 0),           # ret #0: drop
        (0x06, 0, 0, 0xFFFFFFFF),  # ret #-1: take it all
    ]
    code = b"".join(struct.pack("HBBI", *insn) for insn in program)
    buf = ctypes.create_string_buffer(code)
    sock.setsockopt(socket.SOL_SOCKET, SO_ATTACH_FILTER,
                    struct.pack("HL", len(program), ctypes.addressof(buf)))


class LoopbackMulticast(GeneralPurposeUdpMulticastBus):
    """python-can's multicast socket handler with the socket kept on loopback
    (what and why: the module header)."""

    def __init__(self, group: str, port: int, hop_limit: int, max_buffer: int = 4096) -> None:
        super().__init__(group, port, hop_limit, max_buffer)
        try:
            self._own_sender()
        except can.CanInitializationError:
            self._socket.close()
            raise

    def _create_socket(self, address_family: socket.AddressFamily) -> socket.socket:
        if address_family != socket.AF_INET:
            raise can.CanInitializationError(
                f"udp_multicast group {self.group} is IPv6: only an IPv4 group (such as "
                "239.74.163.2) can be kept on the loopback interface")
        sock = socket.socket(address_family, socket.SOCK_DGRAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if hasattr(socket, "SO_REUSEPORT"):  # several processes on one group and port
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            self._keep_on_loopback(sock)
            try:
                sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
                self.timestamp_nanosecond = True
            except OSError:  # python-can then asks the kernel per datagram
                self.timestamp_nanosecond = False
        except OSError as error:
            sock.close()
            raise can.CanInitializationError(
                f"cannot keep udp_multicast group {self.group} on the loopback interface: "
                f"{error}") from error
        return sock

    def _keep_on_loopback(self, sock: socket.socket) -> None:
        sock.bind((self.group, self.port))
        if _LINUX:
            sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
        loopback = socket.inet_aton(LOOPBACK_V4)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, loopback)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.hop_limit)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                        socket.inet_aton(self.group) + loopback)


    def _own_sender(self) -> None:
        """The socket this bus sends from (see the module header); on Linux
        the receiving socket drops what it sends."""
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind((LOOPBACK_V4, 0))
            if sock.getsockname()[1] == self.port:  # the group's port: others' source too
                sock.close()
                sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                sock.bind((LOOPBACK_V4, 0))
            loopback = socket.inet_aton(LOOPBACK_V4)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, loopback)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.hop_limit)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            if _LINUX:
                _drop_source_port(self._socket, sock.getsockname()[1])
        except OSError as error:
            sock.close()
            raise can.CanInitializationError(
                f"cannot open a sending socket for udp_multicast group {self.group} on "
                f"the loopback interface: {error}") from error
        self._sender = sock

    def send(self, data: bytes, timeout: float | None = None) -> None:
        """python-can's send, from this bus's own sending socket."""
        if timeout != self._last_send_timeout:
            self._last_send_timeout = timeout
            self._sender.settimeout(timeout)
        try:
            if self._sender.sendto(data, self._send_destination) < len(data):
                raise TimeoutError
        except TimeoutError:
            raise can.CanTimeoutError() from None
        except OSError as error:
            raise can.CanOperationError("failed to send via socket") from error

    def shutdown(self) -> None:
        self._sender.close()
        super().shutdown()


class LoopbackUdpMulticastBus(UdpMulticastBus):
    """:class:`~can.interfaces.udp_multicast.UdpMulticastBus` on loopback only.

    Takes python-can's arguments, with ``hop_limit`` 0 by default.  Raises
    CanInitializationError when the socket cannot be kept on loopback."""

    def __init__(self, channel: str = UdpMulticastBus.DEFAULT_GROUP_IPv4, port: int = 43113,
                 hop_limit: int = 0, receive_own_messages: bool = False, fd: bool = True,
                 **kwargs: Any) -> None:
        # What UdpMulticastBus.__init__ does, minus opening python-can's own
        # socket (on every interface) only to close it again.
        is_msgpack_installed()
        if receive_own_messages:
            raise can.CanInterfaceNotImplementedError(
                "receiving own messages is not yet implemented")
        self._multicast = LoopbackMulticast(channel, port, hop_limit)
        can.BusABC.__init__(self, channel, **kwargs)
        self._can_protocol = CanProtocol.CAN_FD if fd else CanProtocol.CAN_20
        self.channel_info = f"udp_multicast {channel} port {port} on loopback"
