"""Serve the explorer: a Bokeh server (through Panel) on 127.0.0.1, one :class:`~.app.Explorer` per page.

:func:`serve` blocks until Ctrl-C (``KeyboardInterrupt``, which it lets pass after
stopping the server and every page's background work: no thread or process is
left behind).  The diagram of each page opened is computed for that page.
"""

from __future__ import annotations

import errno
import logging
import signal
import socket
import sys
from collections.abc import Callable

from grazing.errors import GrazingError
from grazing.explore.diagram import View

__all__ = ["DEFAULT_ADDRESS", "DEFAULT_PORT", "PortInUseError", "serve"]

DEFAULT_PORT = 5006
"""The port ``grazing explore`` listens on (Bokeh's own default)."""

DEFAULT_ADDRESS = "127.0.0.1"
"""Where it listens: this machine only."""


class PortInUseError(GrazingError):
    """The port asked for is taken."""


REFUSED_SHOWN = 160
"""Characters of a refused message's error that its log line shows."""

WEBSOCKET_LOGGERS = ("bokeh.server.views.ws", "bokeh.server.protocol_handler", "tornado.application")
"""Bokeh's loggers that report a websocket message the server could not read or apply, and Tornado's,
that reports a request its handler failed on (a websocket opened with a token that is not one)."""


class OneLineRefusals(logging.Filter):
    """Bokeh's report of a bad websocket message as one line: no traceback, no echo of the message.

    A frame that is not JSON, a message of an unknown type, a patch naming a
    model the page does not have: Bokeh logs each with its traceback (and
    the message itself, however long), then that it closes the connection.
    This filter makes that one line, ``grazing explore: refused a websocket
    message (ERROR)``, written by ``say`` (to stderr, without the logging
    prefix of Bokeh's handler); the server goes on serving the other pages.

    Examples
    --------
    >>> import sys
    >>> try:
    ...     raise KeyError("NOPE")
    ... except KeyError:
    ...     record = logging.LogRecord("bokeh.server.views.ws", logging.ERROR, "ws.py", 1,
    ...                                "Unhandled exception receiving a message: %r: %r", (0, "{}"),
    ...                                sys.exc_info())
    >>> said = []
    >>> OneLineRefusals(said.append).filter(record), said
    (False, ["grazing explore: refused a websocket message (KeyError: 'NOPE')"])
    """

    def __init__(self, say: Callable[[str], object] | None = None) -> None:
        super().__init__()
        self.say = say if say is not None else (lambda line: print(line, file=sys.stderr, flush=True))

    def filter(self, record: logging.LogRecord) -> bool:
        if record.getMessage().startswith("Bokeh Server internal error: server failed to"):
            return False  # (the closing of the connection, after the line below)
        if record.exc_info and record.exc_info[1] is not None:
            exc = record.exc_info[1]
            text = " ".join(f"{type(exc).__name__}: {exc}".split())
            if len(text) > REFUSED_SHOWN:
                text = text[: REFUSED_SHOWN - 3] + "..."
            what = "request" if record.name.startswith("tornado") else "websocket message"
            self.say(f"grazing explore: refused a {what} ({text})")
            return False
        return True


def check_port(address: str, port: int) -> int:
    """The port to listen on: ``port``, or a free one for 0; :class:`PortInUseError` when it is taken."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((address, port))
            return int(s.getsockname()[1])
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise PortInUseError(
                    f"port {port} is in use: give another with port= (0: any free port)"
                ) from None
            raise GrazingError(f"cannot listen on {address}:{port}: {exc.strerror or exc}") from None


def serve(
    view: View,
    *,
    port: int = DEFAULT_PORT,
    address: str = DEFAULT_ADDRESS,
    open_browser: bool = True,
    ready: Callable[[str], None] | None = None,
    mode: str | None = None,
) -> None:
    """Serve the explorer of ``view`` at ``http://address:port/`` until Ctrl-C (then ``KeyboardInterrupt``).

    ``ready(url)`` is called once the server listens (``port`` 0: a free port
    is chosen, and ``url`` says which); ``open_browser`` then opens the page.
    ``mode``: a model with modes, the page's start mode of a click (see :class:`~.app.Explorer`).
    Only pages served from that address and port may open the server's websocket.
    """
    import panel as pn

    from grazing.explore.app import PAGE_TEMPLATE, Explorer

    port = check_port(address, port)
    pages: list[Explorer] = []

    def page() -> object:
        explorer = Explorer(view, mode=mode)
        pages.append(explorer)
        pn.state.curdoc.template = PAGE_TEMPLATE  # (a viewport: a phone lays the page out at its width)
        pn.state.on_session_destroyed(lambda _ctx: explorer.close())
        return explorer.panel

    server = pn.serve(
        {"/": page},
        port=port,
        address=address,
        show=False,
        start=False,
        verbose=False,
        title=f"grazing explore: {view.model.name}",
        websocket_origin=[f"{address}:{port}", f"localhost:{port}"],
    )
    interrupted: list[int] = []
    loop = server.io_loop

    def on_sigint(signum: int, _frame: object) -> None:  # Ctrl-C: stop the loop, then say so
        interrupted.append(signum)
        loop.add_callback_from_signal(loop.stop)

    previous = signal.signal(signal.SIGINT, on_sigint)  # (Panel's own handler would stop it silently)
    refusals = OneLineRefusals()
    for name in WEBSOCKET_LOGGERS:
        logging.getLogger(name).addFilter(refusals)
    try:
        server.start()
        url = f"http://{address}:{server.port}/"
        if ready is not None:
            ready(url)
        if open_browser:
            import webbrowser

            webbrowser.open(url)
        loop.start()
    finally:
        for name in WEBSOCKET_LOGGERS:
            logging.getLogger(name).removeFilter(refusals)
        signal.signal(signal.SIGINT, previous)
        for explorer in pages:
            explorer.jobs.close(timeout=0)
        server.stop()
        for explorer in pages:
            explorer.jobs.close(timeout=10)
    if interrupted:
        raise KeyboardInterrupt
