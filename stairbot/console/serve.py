"""``stairbot console --serve [HOST:]PORT``: the operator console in a browser.

textual-serve (the extra ``stairbot[serve]``) runs a web server; each browser
tab that opens the page gets a console of its own: a ``stairbot console``
process with the options given here, which textual-serve starts through the
shell (so the command is quoted here, every word) and drives over a
websocket.  A tab closed mid-run ends its console, which stops the robot on
the way out, as quitting does.

The server listens on 127.0.0.1 unless HOST says otherwise.  It answers only
requests addressed to it by an IP address, ``localhost`` or this machine's
name (a web page that points another name at this address gets no page), and
opens a console only for the page it served itself: a websocket whose Origin
is another site (any page the operator has open may try
``ws://127.0.0.1:PORT/ws``) is refused, so no other site can press keys.
"""

from __future__ import annotations

import argparse
import ipaddress
import shlex
import socket
import sys
from typing import Any
from urllib.parse import urlsplit

from stairbot import listen
from stairbot.errors import InputError

OPTION = "--serve"
EXTRA_HINT = ("`stairbot console --serve` needs the extra stairbot[serve]: "
              "pip install 'stairbot[serve]'")


def parse_bind(text: str) -> tuple[str, int]:
    """``PORT``, ``HOST:PORT`` or ``[IPv6]:PORT`` as (host, port); the host is
    127.0.0.1 when not given.  Raises InputError naming ``--serve``."""
    return listen.parse_bind(text, OPTION)


def check_listen(host: str, port: int) -> None:
    """InputError unless a server can listen on (host, port) now: the name
    resolves, the address is this machine's, the port is free and allowed."""
    listen.check_listen(host, port, OPTION)


def served_argv(args: argparse.Namespace) -> list[str]:
    """The console each browser tab runs: this Python, the console's options as
    given (``--flag=value``, so a value starting with ``-`` stays a value)."""
    argv = [sys.executable, "-m", "stairbot", "console",
            f"--robot={args.robot}", f"--speed={args.speed or '1x'}"]
    for flag in ("scenario", "config", "record"):
        value = getattr(args, flag)
        if value is not None:
            argv.append(f"--{flag}={value}")
    return argv


def shell_command(argv: list[str]) -> str:
    """``argv`` as one POSIX shell command line (textual-serve runs it with
    ``sh -c``): every word quoted."""
    return shlex.join(argv)


def allowed_hosts() -> set[str]:
    """Host names a request may address this server by (besides IP literals)."""
    names = {"localhost", socket.gethostname().lower(), socket.getfqdn().lower()}
    return {n for n in names if n}


def _host_name(netloc: str) -> str:
    """The host of ``host[:port]`` / ``[v6][:port]``, lower case."""
    return (urlsplit(f"//{netloc}").hostname or "").lower()


def host_allowed(host_header: str, names: set[str]) -> bool:
    """Whether a request's Host header names this machine: an IP address,
    ``localhost`` or one of ``names`` (not a name a web page chose)."""
    name = _host_name(host_header)
    if not name:
        return False
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return name in names
    return True


def same_origin(origin: str | None, host_header: str) -> bool:
    """Whether a websocket's Origin is the page this server served."""
    if not origin:
        return False
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and parts.netloc.lower() == host_header.lower()


def serve(args: argparse.Namespace, host: str, port: int) -> int:
    """Serve the console on (host, port) until Ctrl-C or SIGTERM; returns 0.
    Raises InputError when textual-serve is missing or (host, port) cannot be
    listened on."""
    try:
        from aiohttp import web
        from textual_serve.server import Server
    except ImportError:
        raise InputError("--serve", None, EXTRA_HINT) from None
    check_listen(host, port)
    names = allowed_hosts()

    class ConsoleServer(Server):
        """textual-serve's server, answering only this machine's names and
        same-origin websockets, and giving the page the address it was asked
        by (its own default, http://HOST:PORT, is useless for 0.0.0.0)."""

        async def handle_index(self, request: web.Request) -> Any:
            if not host_allowed(request.host, names):
                raise web.HTTPForbidden(text=f"stairbot: no console for host {request.host!r}")
            # handle_index reads public_url before its first await: no other
            # request can change it in between.
            self.public_url = f"{request.scheme}://{request.host}"
            return await super().handle_index(request)

        async def handle_websocket(self, request: web.Request) -> Any:
            if not (host_allowed(request.host, names)
                    and same_origin(request.headers.get("Origin"), request.host)):
                raise web.HTTPForbidden(text="stairbot: a console only for its own page")
            return await super().handle_websocket(request)

        async def on_startup(self, app: web.Application) -> None:
            shown = f"[{host}]" if ":" in host else host
            print(f"stairbot console: serving http://{shown}:{port}/ -- each browser tab "
                  f"opens a console of its own; Ctrl-C stops the server", flush=True)

    argv = served_argv(args)
    server = ConsoleServer(shell_command(argv), host=host, port=port, title="stairbot console")
    server.serve()
    return 0
