"""``grazing explore`` as a server: it listens on 127.0.0.1, serves the page, and stops cleanly on Ctrl-C."""

from __future__ import annotations

import contextlib
import json
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


BAD_FRAMES = {
    "not JSON": ["not json", "{}", "{}"],
    "an unknown message type": [json.dumps({"msgid": "1", "msgtype": "NOPE"}), "{}", "{}"],
    "a patch naming an unknown model": [
        json.dumps({"msgid": "2", "msgtype": "PATCH-DOC"}),
        "{}",
        json.dumps({"events": [{"kind": "ModelChanged", "model": {"id": "p9999"}, "attr": "x", "new": 1}]}),
    ],
}
"""Websocket messages (each its header, metadata and content frames) the server cannot read or apply."""


async def _send(port: int, token: str, frames: list[str]) -> None:
    """Open the page's websocket as the page does, send ``frames``, and read the answers."""
    import asyncio

    from tornado.httpclient import HTTPRequest
    from tornado.websocket import websocket_connect

    request = HTTPRequest(f"ws://127.0.0.1:{port}/ws", headers={"Origin": f"http://127.0.0.1:{port}"})
    ws = await websocket_connect(request, subprotocols=["bokeh", token])
    await ws.read_message()  # (the server's ACK)
    for frame in frames:
        await ws.write_message(frame)
    with contextlib.suppress(asyncio.TimeoutError):  # (read what comes, until the server closes or is quiet)
        while await asyncio.wait_for(ws.read_message(), 1.0) is not None:
            pass
    ws.close()


def test_bad_websocket_messages_are_one_logged_line_each_and_the_server_goes_on(tmp_path):
    """issue 43: Bokeh logged each with its traceback (and the message itself)."""
    import asyncio

    cmd = [sys.executable, "-m", "grazing", "explore", "--model", "impact-oscillator", "--param", "omega",
           "--range", "2.8,3.6", "--num", "10", "--no-browser", "--port", "0"]  # fmt: skip
    proc = subprocess.Popen(
        cmd, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    try:
        url = re.search(r"http://127\.0\.0\.1:(\d+)/", _read_line(proc, SERVER_START))
        with urllib.request.urlopen(url.group(0), timeout=60) as page:
            token = re.search(r'"token":\s*"([^"]+)"', page.read().decode()).group(1)
        for frames in BAD_FRAMES.values():
            asyncio.run(_send(int(url.group(1)), token, frames))
        with urllib.request.urlopen(url.group(0), timeout=60) as page:  # (still serving)
            assert "<title>grazing explore: impact-oscillator</title>" in page.read().decode()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
    _out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    lines = err.splitlines()
    refused = [line for line in lines if line.startswith("grazing explore: refused a websocket message (")]
    assert len(refused) == 3, err
    assert any("JSONDecodeError" in r for r in refused) and any("KeyError: 'NOPE'" in r for r in refused)
    assert any("UnknownReferenceError: can't resolve reference 'p9999'" in r for r in refused)
    assert lines == [*refused, "grazing: interrupted"], err  # (no traceback, nothing else)
