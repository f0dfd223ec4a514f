"""The viewer's defences on the network: who may connect, and one line for what goes wrong.

**Origin and Host.** Any web page the user visits can open ``ws://127.0.0.1:PORT`` (a browser
lets a page of any origin open a websocket anywhere), and a DNS-rebinding page reaches it under
its own host name. So every request to the viewer's port must name, in its ``Host`` header, the
address it came in on (or, on a loopback address, ``localhost``, ``127.0.0.1`` or ``[::1]``; or
the host name it was told to serve on) with that port; and a request that carries an ``Origin``
(a browser always sends one on a websocket) must come from a page of such an address. A request
without ``Origin`` (a script, ``curl``: not a browser page) or without ``Host`` is let in: it is
no web page's doing. Refused requests get ``403`` and one warning line.

**One line.** A bad frame from a client (not msgpack, an unknown message, a text frame), an
error in a GUI callback, or any other error on the server's thread is a warning of one line on
stderr, never a traceback; the client that sent it is dropped, the server serves on.

Viser 1.1.1 has no hook for either: :func:`guarded_serve` wraps
``websockets.asyncio.server.serve`` while a :class:`viser.ViserServer` is built (under a lock,
put back after), adding the check to the ``process_request`` viser passes and giving the
server a logger of our own; :func:`start` fails closed if viser did not call it.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import http
import ipaddress
import logging
import socket
import sys
import threading
from typing import Any, Callable, Iterator
from urllib.parse import urlsplit

from replay.viewer.markup import clean

LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARDS = frozenset({"0.0.0.0", "::"})
MESSAGE_CHARS = 200  # of an exception's text in a warning line

log = logging.getLogger("replay.viewer.server")
_serve_lock = threading.Lock()


class _Stderr(logging.Handler):
    """``warning: viewer: ...`` on the stderr of the moment (pytest swaps it), one line."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            sys.stderr.write(f"warning: viewer: {clean(record.getMessage(), 1000)}\n")
            sys.stderr.flush()
        except Exception:  # noqa: BLE001 - a closed stderr is no reason to fail
            pass


def _setup_log() -> None:
    if not log.handlers:
        log.addHandler(_Stderr())
        log.setLevel(logging.WARNING)
        log.propagate = False


def describe(exc: BaseException) -> str:
    """``Type: message`` of an exception, one line, shortened."""
    text = clean(str(exc), MESSAGE_CHARS)
    return f"{exc.__class__.__name__}: {text}" if text else exc.__class__.__name__


class _WebsocketLog(logging.Logger):
    """The websocket server's own logger: its errors become one line (a client's bad frame
    surfaces as "connection handler failed"); a bare TCP connect or a request that is not
    HTTP ("opening handshake failed") is not worth a line; debug and info are dropped."""

    def __init__(self) -> None:
        super().__init__("replay.viewer.websocket", logging.WARNING)

    def handle(self, record: logging.LogRecord) -> None:
        if record.levelno < logging.WARNING:
            return
        message = record.getMessage()
        if message == "opening handshake failed":
            return
        exc = record.exc_info[1] if record.exc_info else None
        if message == "connection handler failed" and exc is not None:
            log.warning("dropped a client after an error in its message (%s)", describe(exc))
        elif exc is not None:
            log.warning("websocket: %s (%s)", message, describe(exc))
        else:
            log.warning("websocket: %s", message)


_WS_LOG = _WebsocketLog()


def _loop_error(loop: asyncio.AbstractEventLoop, context: dict) -> None:
    """The server loop's exception handler (e.g. a client's GUI update whose value does not
    cast): one line."""
    exc = context.get("exception")
    what = describe(exc) if exc is not None else clean(context.get("message", "?"))
    log.warning("error on the server's thread, ignored (%s)", what)


def _host_name(value: str) -> str:
    """A host name or address as compared: lower case, no IPv6 brackets, IPv4 for a mapped
    IPv6 address."""
    name = value.strip().lower().strip("[]")
    try:
        ip = ipaddress.ip_address(name)
    except ValueError:
        return name
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        ip = ip.ipv4_mapped
    return str(ip)


def is_ip(name: str) -> bool:
    """Whether ``name`` is an IP address (v4 or v6), not a host name."""
    try:
        ipaddress.ip_address(name)
        return True
    except ValueError:
        return False


def allowed_names(served: str, local_ip: str) -> set[str]:
    """The host names a request to ``local_ip`` (where it came in) may use, for a server told to
    serve on ``served``: that address and name (``0.0.0.0`` too: the URL printed for it), the
    loopback names on a loopback address, and on a wildcard address the machine's own name."""
    names = {_host_name(local_ip), _host_name(served)} - {""}
    ip = _host_name(local_ip)
    if ip in LOOPBACK_NAMES or (is_ip(ip) and ipaddress.ip_address(ip).is_loopback):
        names |= LOOPBACK_NAMES
    if _host_name(served) in WILDCARDS:
        names.add(socket.gethostname().lower())  # the machine's own name, not a stranger's
    return names


def refusal(served: str, local: tuple, headers: Any) -> str:
    """Why a request with these ``headers``, come in at ``local`` (address, port, ...), is
    refused; "" if it is not."""
    names = allowed_names(served, str(local[0]))
    port = int(local[1])
    for name in ("Host", "Origin"):
        if len(headers.get_all(name)) > 1:
            return f"several {name} headers"
    host = headers.get("Host")
    if host is not None:
        try:
            parts = urlsplit(f"//{host}")
            ok = _host_name(parts.hostname or "") in names and (parts.port or 80) == port
        except ValueError:
            ok = False
        if not ok:
            return f"Host {clean(host, 80)!r} is not this viewer's address"
    origin = headers.get("Origin")
    if origin is not None:
        try:
            parts = urlsplit(origin)
            ok = (
                parts.scheme == "http"  # the viewer serves no https
                and _host_name(parts.hostname or "") in names
                and (parts.port or 80) == port
            )
        except ValueError:
            ok = False
        if not ok:
            return f"a page of origin {clean(origin, 80)!r} is not this viewer's page"
    return ""


def _checked(served: str, inner: Callable | None) -> Callable:
    """A ``process_request`` that refuses a foreign Host or Origin, else asks ``inner``."""

    def process_request(connection, request):
        why = refusal(served, connection.local_address, request.headers)
        if why:
            log.warning("refused a connection: %s", why)
            return connection.respond(http.HTTPStatus.FORBIDDEN, "Forbidden\n")
        return inner(connection, request) if inner is not None else None

    return process_request


@contextlib.contextmanager
def guarded_serve(served: str) -> Iterator[list[int]]:
    """While a Viser server is built: its websocket server checks Host and Origin and logs one
    line for an error. Yields a list that holds how many servers were guarded."""
    import websockets.asyncio.server as ws_server

    _setup_log()
    guarded: list[int] = []
    with _serve_lock:
        original = ws_server.serve

        @functools.wraps(original)
        def serve(handler, *args, **kw):
            kw["process_request"] = _checked(served, kw.get("process_request"))
            kw["logger"] = _WS_LOG
            asyncio.get_running_loop().set_exception_handler(_loop_error)
            guarded.append(1)
            return original(handler, *args, **kw)

        ws_server.serve = serve  # type: ignore[misc,assignment]
        try:
            yield guarded
        finally:
            ws_server.serve = original  # type: ignore[misc]


def safe(callback: Callable[[Any], None]) -> Callable[[Any], None]:
    """A GUI callback whose error (a value no browser of ours would send) is one warning
    line, not a traceback from Viser's thread pool."""

    @functools.wraps(callback)
    def run(event: Any) -> None:
        try:
            callback(event)
        except Exception as exc:  # noqa: BLE001
            log.warning("ignored a GUI update (%s)", describe(exc))

    return run
