"""Fault corpus, clusters: ``--scheduler`` at an address where no Dask scheduler answers fails in
one line (exit 2) within 10 s, naming the address and how to start a scheduler; nothing is written.

The servers here are real sockets on localhost, stopped by each test: one that refuses, one that
speaks HTTP (and, as HTTP does, waits for a request), one that greets in text (as SSH does), and
a real ``dask scheduler`` for the control.
"""

import http.server
import re
import socket
import subprocess
import sys
import threading
import time

import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.scheduler_address import check_scheduler, parse_scheduler

distributed = pytest.importorskip("distributed")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def http_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()
    thread.join(5)


@pytest.fixture
def text_greeter():
    """A server that greets every connection with a line of text (as SSH and SMTP do)."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen()
    listener.settimeout(0.2)
    stop = threading.Event()

    def serve():
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                continue
            with conn:
                conn.sendall(b"SSH-2.0-OpenSSH_9.6\r\n")
                time.sleep(0.5)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    stop.set()
    thread.join(5)
    listener.close()


def sweep(address, tmp_path, capsys):
    out = tmp_path / "sweep"
    t0 = time.monotonic()
    code = main(["sweep", "--preset", "smoke", "--scheduler", address, "--out", str(out), "--no-progress"])
    elapsed = time.monotonic() - t0
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert code == 2, captured.err
    assert len(err) == 1 and err[0].startswith("colonsim: error: "), err
    assert elapsed < 10, elapsed
    assert not out.exists()  # checked before the sweep folder is made
    return err[0]


def test_a_port_nobody_listens_on(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{free_port()}"
    line = sweep(address, tmp_path, capsys)
    assert f"Dask scheduler {address}: cannot connect" in line and "`dask scheduler`" in line


def test_an_http_server_on_the_port_does_not_hang(http_server, tmp_path, capsys):
    line = sweep(http_server, tmp_path, capsys)
    assert "is not a Dask scheduler (it sent no Dask greeting)" in line and "`dask scheduler`" in line


def test_a_server_that_greets_in_text(text_greeter, tmp_path, capsys):
    line = sweep(text_greeter, tmp_path, capsys)
    assert "is not a Dask scheduler (it answered b'SSH-2.0-Open')" in line


@pytest.mark.parametrize("address", ["not an address", "tcp://host-without-port", "http://127.0.0.1:8786",
                                     "tcp://127.0.0.1:99999", "ucx://127.0.0.1:8786"])
def test_a_non_address(address, tmp_path, capsys):
    line = sweep(address, tmp_path, capsys)
    assert "is not a scheduler address; give tcp://HOST:PORT" in line


def test_an_unknown_host(tmp_path, capsys):
    line = sweep("tcp://no-such-host.invalid:8786", tmp_path, capsys)
    assert "the host 'no-such-host.invalid' is unknown" in line


def test_an_unroutable_address_gives_up_in_time():
    """10.255.255.1 is private and, on most networks, answered by nobody: the connection times out
    (or the network says unreachable at once; behind a proxy that accepts every connection, nothing
    greets); any way, one error within the bound."""
    t0 = time.monotonic()
    with pytest.raises(ColonsimError, match=r"Dask scheduler tcp://10\.255\.255\.1:8786: (no answer|cannot connect|"
                                            r"something listens there but is not a Dask scheduler)"):
        check_scheduler("tcp://10.255.255.1:8786", timeout_s=2.0)
    assert time.monotonic() - t0 < 3.0


def test_parse_scheduler_forms():
    assert parse_scheduler("tcp://10.0.0.5:8786") == ("tcp", "10.0.0.5", 8786)
    assert parse_scheduler("localhost:8786") == ("tcp", "localhost", 8786)
    assert parse_scheduler("tls://[::1]:8786") == ("tls", "::1", 8786)


def test_a_real_scheduler_passes_the_check():
    """The control: what a Dask scheduler sends is recognised (so the check can come out either way)."""
    proc = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                             "--port", "0", "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    try:
        address, t0 = None, time.monotonic()
        while address is None and time.monotonic() - t0 < 30:
            match = re.search(r"Scheduler at:\s*(tcp://\S+)", proc.stderr.readline())
            address = match and match.group(1)
        assert address, "the scheduler did not start"
        check_scheduler(address)
    finally:
        proc.terminate()
        proc.wait(10)
