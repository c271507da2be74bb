"""Where a server of stairbot's listens: ``[HOST:]PORT`` parsed and checked
before the server starts, each problem one InputError naming the option
(``--serve``, ``--foxglove``) and what is allowed.  HOST is 127.0.0.1 unless
given: only this machine can connect.  Standard library only."""

from __future__ import annotations

import errno
import ipaddress
import socket

from stairbot.errors import InputError

DEFAULT_HOST = "127.0.0.1"


def parse_bind(text: str, option: str, *, any_port: bool = False) -> tuple[str, int]:
    """``PORT``, ``HOST:PORT`` or ``[IPv6]:PORT`` as (host, port); the host is
    127.0.0.1 when not given.  ``any_port``: PORT 0 is allowed (the system
    picks a free port).  Raises InputError naming ``option``."""
    host, sep, port_text = text.rpartition(":")
    if not sep:
        host = DEFAULT_HOST
    elif host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    elif ":" in host:
        raise bad(option, text, "write an IPv6 address in brackets: [::1]:8000")
    if not host:
        raise bad(option, text, "HOST is empty; give HOST:PORT or PORT alone (host 127.0.0.1)")
    lowest = 0 if any_port else 1
    if not port_text.isdigit() or not lowest <= int(port_text) <= 65535:
        raise bad(option, text, f"PORT must be a number from {lowest} to 65535"
                  + (" (0: any free port)" if any_port else "") + f", not {port_text!r}")
    if any(ch.isspace() or ch in "/?#@[]" for ch in host):
        raise bad(option, text, f"HOST {host!r} is not an address or a host name")
    return host, int(port_text)


def bad(option: str, text: str, problem: str) -> InputError:
    """The InputError for ``option``'s value ``text``."""
    return InputError(option, None, f"{text!r}: {problem}")


def shown(host: str, port: int) -> str:
    """``host:port`` as a URL writes it (an IPv6 address in brackets)."""
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def check_listen(host: str, port: int, option: str) -> None:
    """InputError unless a server can listen on (host, port) now: the name
    resolves, the address is this machine's, the port is free and allowed."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                                   flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise bad(option, shown(host, port), f"cannot resolve HOST: {exc}") from None
    family, type_, proto, _, address = infos[0]
    with socket.socket(family, type_, proto) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as servers do
        try:
            sock.bind(address)
        except OSError as exc:
            reason = {errno.EADDRINUSE: "the port is in use",
                      errno.EADDRNOTAVAIL: "the address is not one of this machine's",
                      errno.EACCES: "not allowed to listen there (ports below 1024 need root)",
                      }.get(exc.errno or 0, exc.strerror or str(exc))
            raise bad(option, shown(host, port), f"cannot listen: {reason}") from None


def is_loopback(host: str) -> bool:
    """Whether ``host`` is this machine alone: a loopback address or ``localhost``."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def is_unspecified(host: str) -> bool:
    """Whether ``host`` means every interface (0.0.0.0, ::)."""
    try:
        return ipaddress.ip_address(host).is_unspecified
    except ValueError:
        return False
