"""A Python-level network guard for executed notebooks.

``install()`` replaces name resolution and socket connection with versions that refuse every
address except loopback and Unix sockets, so a notebook that tries to download something fails
at once with a clear ``ConnectionRefusedError`` instead of hanging or silently depending on the
network. It is installed in every kernel the course tooling starts (through an IPython startup
file). It guards Python code only: a C extension that opens its own sockets is not stopped, which
is why the grader adds OS-level limits on top (see ``robocourse.grading``).
"""
from __future__ import annotations

import ipaddress
import socket

__all__ = ["install", "is_loopback_host", "NetworkDisabledError"]

_LOCAL_NAMES = {"localhost", "localhost.localdomain", "ip6-localhost", ""}


class NetworkDisabledError(ConnectionRefusedError):
    """Raised when code tries to reach a non-loopback address while the guard is installed."""


def is_loopback_host(host: object) -> bool:
    """Return whether ``host`` (a name, an address string or bytes) is a loopback address."""
    if host is None:
        return True
    if isinstance(host, bytes):
        host = host.decode(errors="replace")
    host = str(host).strip("[]").lower()
    if host in _LOCAL_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.split("%")[0]).is_loopback
    except ValueError:
        return False


def _refuse(host: object) -> NetworkDisabledError:
    return NetworkDisabledError(
        f"network access is disabled while notebooks run under robokit (tried to reach {host!r}); "
        "the course must work offline"
    )


def install() -> None:
    """Install the guard in this process (idempotent).

    Notes
    -----
    Course convention ("everything runs offline", DESIGN.md); not from a paper.
    """
    if getattr(socket, "_robokit_guarded", False):
        return
    real_getaddrinfo = socket.getaddrinfo
    real_connect = socket.socket.connect
    real_connect_ex = socket.socket.connect_ex
    real_sendto = socket.socket.sendto

    def getaddrinfo(host, *args, **kwargs):
        if not is_loopback_host(host):
            raise _refuse(host)
        return real_getaddrinfo(host, *args, **kwargs)

    def _check(sock, address):
        if sock.family in (socket.AF_INET, socket.AF_INET6) and isinstance(address, tuple):
            if not is_loopback_host(address[0]):
                raise _refuse(address[0])

    def connect(self, address):
        _check(self, address)
        return real_connect(self, address)

    def connect_ex(self, address):
        _check(self, address)
        return real_connect_ex(self, address)

    def sendto(self, data, *args):
        _check(self, args[-1])
        return real_sendto(self, data, *args)

    socket.getaddrinfo = getaddrinfo
    socket.socket.connect = connect
    socket.socket.connect_ex = connect_ex
    socket.socket.sendto = sendto
    socket._robokit_guarded = True
