import subprocess
import sys

import pytest

from robocourse.site.netguard import is_loopback_host


@pytest.mark.parametrize("host, ok", [("localhost", True), ("127.0.0.1", True), ("::1", True),
                                      ("127.5.5.5", True), ("example.com", False),
                                      ("10.0.0.1", False), ("8.8.8.8", False)])
def test_loopback_classification(host, ok):
    assert is_loopback_host(host) is ok


def test_guard_refuses_remote_and_allows_loopback():
    code = r"""
import socket, threading
from robocourse.site import netguard
netguard.install()
for target in [("example.com", 80), ("192.0.2.1", 80)]:
    try:
        socket.create_connection(target, timeout=1)
    except netguard.NetworkDisabledError as e:
        print("refused", target[0])
srv = socket.socket(); srv.bind(("127.0.0.1", 0)); srv.listen(1)
c = socket.create_connection(srv.getsockname(), timeout=1); print("loopback ok")
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:3] == ["refused example.com", "refused 192.0.2.1", "loopback ok"]
