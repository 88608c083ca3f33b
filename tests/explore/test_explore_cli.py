"""``grazing explore`` as a server: it listens on 127.0.0.1, serves the page, and stops cleanly on Ctrl-C."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import urllib.request

import pytest

from grazing.cli import main
from tests.explore.page import SERVER_START, _read_line
from tests.processes import all_gone, descendants

pytestmark = pytest.mark.skipif(os.name != "posix", reason="sends SIGINT to a process group")


def test_it_serves_the_page_on_127_0_0_1_and_ctrl_c_ends_it_with_130(tmp_path):
    cmd = [
        sys.executable,
        "-m",
        "grazing",
        "explore",
        "--model",
        "impact-oscillator",
        "--param",
        "omega",
        "--range",
        "2.8,3.6",
        "--num",
        "10",
        "--no-browser",
        "--port",
        "0",
    ]
    proc = subprocess.Popen(
        cmd, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    try:
        line = _read_line(proc, SERVER_START)
        url = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        assert url, line
        port = int(url.group(1))
        with urllib.request.urlopen(url.group(0), timeout=60) as page:  # (opens a session: a diagram starts)
            html = page.read().decode()
        assert "<title>grazing explore: impact-oscillator</title>" in html
        # bound to the loopback address only: no other address of this machine answers
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.settimeout(5)
            assert s.connect_ex(("127.0.0.2", port)) != 0
        children = descendants(proc.pid)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.strip() == "grazing: interrupted"
    assert out == ""  # (its one line, the address, was read above)
    assert all_gone(children | {proc.pid})
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_a_port_in_use_is_one_line(capsys):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["explore", "--no-browser", "--port", str(port)]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err == f"grazing: error: port {port} is in use: give another with --port (0: any free port)\n"
