"""Check a Dask scheduler address before a sweep hands it to ``distributed.Client``.

A client given an unroutable address waits out its whole connect timeout and ends in a
``TimeoutError``; given a port where another server answers (an HTTP server, say), it can wait for
a handshake that never comes. :func:`check_scheduler` settles both within
:data:`colonsim.limits.SCHEDULER_CHECK_S` seconds with the standard library only: the address must
parse, a TCP connection must open, and what answers must greet the way a Dask scheduler does (it
sends its handshake frame unprompted, a little-endian byte count followed by a frame count;
other servers wait for a request or greet in text).
"""

from __future__ import annotations

import re
import socket
import struct
import time

from colonsim.errors import ColonsimError
from colonsim.limits import SCHEDULER_CHECK_S

_ADDRESS = re.compile(r"^(?:(?P<scheme>[a-z]+)://)?(?P<host>\[[0-9a-fA-F:]+\]|[A-Za-z0-9.\-_]+):(?P<port>\d{1,5})/?$")
_START = "start one with `dask scheduler` on that machine and workers with `dask worker {} --nthreads 1`"


def _fail(address, problem) -> ColonsimError:
    return ColonsimError(f"Dask scheduler {address}: {problem}; {_START.format(address)}")


def parse_scheduler(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of ``tcp://HOST:PORT`` (or ``HOST:PORT``, or ``tls://HOST:PORT``)."""
    match = _ADDRESS.match(str(address).strip())
    if not match or match["scheme"] not in (None, "tcp", "tls") or not 0 < int(match["port"]) < 65536:
        raise ColonsimError(f"--scheduler {address!r} is not a scheduler address; give tcp://HOST:PORT "
                            "(the address `dask scheduler` prints, port 8786 by default)")
    return match["scheme"] or "tcp", match["host"].strip("[]"), int(match["port"])


def _looks_like_dask(greeting: bytes) -> bool:
    """Whether ``greeting`` starts as Dask's TCP framing: uint64 byte count, uint64 frame count."""
    if len(greeting) < 16:
        return False
    total, frames = struct.unpack("<QQ", greeting[:16])
    return 0 < frames < 1000 and 8 < total < 1 << 24


def check_scheduler(address: str, timeout_s: float = SCHEDULER_CHECK_S):
    """Refuse, in one line and within ``timeout_s`` seconds, an address where no Dask scheduler answers.

    Raises
    ------
    ColonsimError
        A malformed address, a host that does not resolve, a connection refused or timed out, or a
        server that does not greet like a Dask scheduler (TLS addresses: the connection only).
    """
    scheme, host, port = parse_scheduler(address)
    deadline = time.monotonic() + timeout_s
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise _fail(address, f"the host {host!r} is unknown ({getattr(exc, 'strerror', None) or exc})") from None
    try:
        sock = socket.create_connection(infos[0][4][:2], timeout=max(0.1, deadline - time.monotonic()) / 2)
    except TimeoutError:
        raise _fail(address, f"no answer within {timeout_s / 2:g} s (unroutable, or a firewall drops the "
                             "connection)") from None
    except OSError as exc:
        raise _fail(address, f"cannot connect ({exc.strerror or exc})") from None
    with sock:
        if scheme == "tls":
            return
        greeting = b""
        try:
            while len(greeting) < 16 and time.monotonic() < deadline:
                sock.settimeout(max(0.05, min(3.0, deadline - time.monotonic())))
                chunk = sock.recv(16 - len(greeting))
                if not chunk:
                    break
                greeting += chunk
        except (TimeoutError, OSError):
            pass
    if not _looks_like_dask(greeting):
        heard = f"it answered {greeting[:12]!r}" if greeting else "it sent no Dask greeting"
        raise _fail(address, f"something listens there but is not a Dask scheduler ({heard})")
