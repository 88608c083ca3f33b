"""Ctrl-C inside the compiled driver: a SIGINT counter that the driver reads on every step.

While the driver runs, Python cannot run its own SIGINT handler (which only
sets a flag that the interpreter looks at between bytecodes), so a long run
would ignore Ctrl-C until it ends.  Around each driver call made in the main
thread, :func:`counting_sigint` installs instead a handler in machine code
(compiled here with llvmlite, a few instructions, async-signal-safe) that
adds one to :data:`SIGINTS`; the driver compares :data:`SIGINTS` with the
count at its start once per step and returns
:attr:`~grazing.core.solution.Status.INTERRUPTED`; the previous handler is
restored when the call returns, and the caller raises
:class:`KeyboardInterrupt` (:func:`raise_if_interrupted`).

The handler is installed only where Python's default handler is in place
(:func:`signal.default_int_handler`, which raises ``KeyboardInterrupt``), in
the main thread, on POSIX systems: a program with a SIGINT handler of its
own keeps it, and its handler runs when the driver call returns, as before.

SIGTERM (``kill``, a scheduler ending a job) ends a command as Ctrl-C does
where :func:`terminating_as_interrupted` is in force (the command line):
:func:`raise_terminated` raises :class:`Terminated`, a ``KeyboardInterrupt``,
so that the same clean-up runs (temporaries removed, workers stopped) and the
command ends with status 143 instead of 130.  Around a driver call it is
counted by the same machine-code handler, which also keeps the number of the
last signal (:data:`LAST_SIGNAL`): :func:`raise_if_interrupted` then raises
:class:`Terminated`.

Examples
--------
>>> import signal
>>> previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a new Python
>>> with counting_sigint() as seen:
...     signal.raise_signal(signal.SIGINT)  # as a Ctrl-C while the driver runs
...     int(SIGINTS[0]) - seen
1
>>> signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
True
>>> _ = signal.signal(signal.SIGINT, previous)
"""

from __future__ import annotations

import _signal
import ctypes
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")

SIGINTS = np.zeros(1, dtype=np.int64)
"""How many SIGINTs (and SIGTERMs) the machine-code handler has seen in this process (only ever increased)."""

LAST_SIGNAL = np.zeros(1, dtype=np.int64)
"""The number of the last signal the machine-code handler counted (SIGINT or SIGTERM)."""


class Terminated(KeyboardInterrupt):
    """SIGTERM: the command ends as on Ctrl-C (the same clean-up), with its own status (143)."""


def interruptibly(make: Callable[[], T]) -> T:
    """``make()`` (a compile: half a minute the first time), run so that a Ctrl-C ends it at once.

    In the main thread it runs in a daemon thread of its own, waited for in slices of 50 ms: the
    ``KeyboardInterrupt`` (or :class:`Terminated`) is raised here at once, and the compile, left to its
    thread, ends with the process.  Run there, a Ctrl-C that fell inside one of llvmlite's ctypes
    callbacks was "ignored" (a traceback on stderr) and the command went on to the end, exit 0.
    Elsewhere ``make()`` is called directly.

    Examples
    --------
    >>> interruptibly(lambda: 6 * 7)
    42
    """
    if threading.current_thread() is not threading.main_thread():
        return make()
    done: dict[str, Any] = {}

    def work() -> None:
        try:
            done["value"] = make()
        except BaseException as exc:  # (re-raised in the caller's thread)
            done["error"] = exc

    worker = threading.Thread(target=work, name="grazing-compile", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(0.05)
    if "error" in done:
        raise done["error"]
    return done["value"]


_TERMINATED: list[bool] = []
"""Set when :func:`raise_terminated` has run since the last :func:`terminating_as_interrupted` block began
(:func:`was_terminated`)."""

_INTERRUPTED: list[bool] = []
"""Set when :func:`raise_interrupted` has run since the last :func:`terminating_as_interrupted` block began
(:func:`was_interrupted`)."""

REDELIVERY_INTERVAL = 0.2
"""Seconds between two deliveries again of a signal whose exception may be lost (:func:`_redeliver`)."""

_BLOCK: dict[str, Any] = {}
"""The :func:`terminating_as_interrupted` block running: ``"done"``, an event set as it ends,
``"hook"``, the ``sys.unraisablehook`` before it, and ``"again"``, the thread delivering a signal again
(once one came)."""


def _forked() -> None:
    """In a process forked inside the block (a pool's worker): no block of its own, so nothing delivered
    again, and lost exceptions reported as before."""
    if _BLOCK:
        sys.unraisablehook = _BLOCK["hook"]
        _BLOCK.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forked)


def _in_flight() -> bool:
    """Whether a ``KeyboardInterrupt`` (or :class:`Terminated`) is on its way out of the main thread: the
    exception being handled where this runs (a ``finally``, ``except`` or ``__exit__`` it passes
    through), or the one that exception was raised while handling."""
    exc = sys.exc_info()[1]
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__context__
    return False


def _redeliver(signum: int) -> None:
    """Deliver ``signum`` to the main thread again every :data:`REDELIVERY_INTERVAL` s until the
    :func:`terminating_as_interrupted` block ends (a thread started once).

    The exception a signal handler raises is lost where Python cannot raise it: a handler run inside a
    weak reference's callback (importlib's module locks), a ``__del__`` or a garbage collector's
    callback is reported as "Exception ignored" and the command went on to its end, exit 0 (the
    signal fuzz, 1 run in 87).  Each delivery again runs the handler, which raises again unless the
    first exception is still on its way out (:func:`_in_flight`).  ``_thread.interrupt_main`` trips
    Python's flag for the signal without sending one: no system call of the main thread is
    interrupted, and nothing is sent once the handler is gone.
    """
    import _thread

    done = _BLOCK.get("done")
    if done is None or "again" in _BLOCK:
        return

    def again() -> None:
        while not done.wait(REDELIVERY_INTERVAL):
            _thread.interrupt_main(signum)

    thread = threading.Thread(target=again, name="grazing-signal-again", daemon=True)
    _BLOCK["again"] = thread
    thread.start()


def _raise(signum: int, error: type[KeyboardInterrupt]) -> None:
    """Raise ``error`` for ``signum`` (a handler of :func:`terminating_as_interrupted`), unless one is
    on its way out already (a delivery again of the same signal: :func:`_redeliver`)."""
    if _in_flight():
        return
    _redeliver(signum)
    raise error


def raise_terminated(_signum: int, _frame: object) -> None:
    """The SIGTERM handler of :func:`terminating_as_interrupted`: raise :class:`Terminated` (and remember
    it: :func:`was_terminated`)."""
    _TERMINATED.append(True)
    _raise(signal.SIGTERM, Terminated)


def raise_interrupted(_signum: int, _frame: object) -> None:
    """The SIGINT handler of :func:`terminating_as_interrupted`: Python's (``KeyboardInterrupt``), raised
    again if it was lost (:func:`_redeliver`), and remembered (:func:`was_interrupted`)."""
    _INTERRUPTED.append(True)
    _raise(signal.SIGINT, KeyboardInterrupt)


def was_terminated() -> bool:
    """Has a SIGTERM been raised as :class:`Terminated` since the last :func:`terminating_as_interrupted`
    block began (it stays known after the block, for the caller's handler)?

    An extension module being imported when the signal comes turns the exception into its own (scipy's
    HiGHS: ``ImportError: initialization failed``): the command line ends as terminated all the same.
    """
    return bool(_TERMINATED)


def was_interrupted() -> bool:
    """Has a Ctrl-C (SIGINT) been raised by :func:`raise_interrupted` since the last
    :func:`terminating_as_interrupted` block began?  As for :func:`was_terminated`: an extension module
    being imported turns the ``KeyboardInterrupt`` into its own error (scipy's HiGHS, ``ImportError:
    initialization failed``, the signal fuzz), and the command line ends as interrupted all the same."""
    return bool(_INTERRUPTED)


def _quiet_lost_interrupts(previous: Callable[[Any], object]) -> Callable[[Any], object]:
    """``sys.unraisablehook`` that says nothing of a lost ``KeyboardInterrupt`` (delivered again:
    :func:`_redeliver`) and passes anything else to ``previous``."""

    def hook(unraisable: Any) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            previous(unraisable)

    return hook


@contextmanager
def terminating_as_interrupted() -> Iterator[None]:
    """Within the block, SIGTERM raises :class:`Terminated` (in the main thread, where SIGTERM's default
    action is in place: a program with a handler of its own keeps it); the default is restored after.

    A SIGTERM or a Ctrl-C (where Python's own handler is in place) whose exception is lost is delivered
    again until the block ends (:func:`_redeliver`), and the loss is not reported.

    Examples
    --------
    >>> previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)  # as in a new Python
    >>> with terminating_as_interrupted():
    ...     try:
    ...         signal.raise_signal(signal.SIGTERM)
    ...     except Terminated:
    ...         print("ended as on Ctrl-C")
    ended as on Ctrl-C
    >>> signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    True
    >>> _ = signal.signal(signal.SIGTERM, previous)
    """
    if threading.current_thread() is not threading.main_thread() or _BLOCK:
        yield
        return
    _TERMINATED.clear()
    _INTERRUPTED.clear()
    previous = {
        signal.SIGTERM: signal.getsignal(signal.SIGTERM),
        signal.SIGINT: signal.getsignal(signal.SIGINT),
    }
    ours = {signal.SIGTERM: raise_terminated, signal.SIGINT: raise_interrupted}
    default = {signal.SIGTERM: signal.SIG_DFL, signal.SIGINT: signal.default_int_handler}
    taken = [sig for sig in ours if previous[sig] == default[sig]]
    if signal.SIGTERM not in taken:
        yield
        return
    hook = sys.unraisablehook
    _BLOCK.update(done=threading.Event(), hook=hook)
    for sig in taken:
        signal.signal(sig, ours[sig])
    sys.unraisablehook = _quiet_lost_interrupts(hook)
    try:
        yield
    finally:
        try:
            _BLOCK["done"].set()
            if "again" in _BLOCK:
                _BLOCK["again"].join()  # (a delivery it made is handled here, while the handlers are ours)
        finally:
            _BLOCK.clear()
            sys.unraisablehook = hook
            for sig in reversed(taken):
                signal.signal(sig, previous[sig])


_SIGACTION_BYTES = 512
"""Room for a ``struct sigaction`` on every POSIX system (152 bytes on Linux x86-64)."""

_state: dict[str, Any] = {}


def _handler_address() -> int:
    """The address of ``void handler(int)`` adding one to :data:`SIGINTS` (compiled once per process)."""
    if "address" not in _state:
        import llvmlite.binding as llvm
        from llvmlite import ir

        from grazing.engine.llvmgen import _target_machine

        module = ir.Module(name="grazing_interrupts")
        i64 = ir.IntType(64)
        fn = ir.Function(module, ir.FunctionType(ir.VoidType(), [ir.IntType(32)]), "grazing_count_sigint")
        builder = ir.IRBuilder(fn.append_basic_block())
        last = builder.inttoptr(ir.Constant(i64, LAST_SIGNAL.ctypes.data), i64.as_pointer())
        builder.store_atomic(builder.sext(fn.args[0], i64), last, "seq_cst", 8)  # (before the count moves)
        counter = builder.inttoptr(ir.Constant(i64, SIGINTS.ctypes.data), i64.as_pointer())
        builder.atomic_rmw("add", counter, ir.Constant(i64, 1), "seq_cst")
        builder.ret_void()
        parsed = llvm.parse_assembly(str(module))
        parsed.verify()
        engine = llvm.create_mcjit_compiler(parsed, _target_machine())
        engine.finalize_object()
        _state["engine"] = engine  # the code lives as long as the process
        _state["address"] = int(engine.get_function_address("grazing_count_sigint"))
    return int(_state["address"])


def _sigaction() -> Any:
    """libc's ``sigaction``, or None where there is none (Windows)."""
    if "sigaction" not in _state:
        fn = None
        if os.name == "posix":
            try:
                fn = ctypes.CDLL(None, use_errno=True).sigaction
                fn.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p]
                fn.restype = ctypes.c_int
            except (OSError, AttributeError):  # pragma: no cover - a libc without sigaction
                fn = None
        _state["sigaction"] = fn
    return _state["sigaction"]


_COUNTED = {
    signal.SIGINT: (signal.default_int_handler, raise_interrupted),
    signal.SIGTERM: (raise_terminated,),
}
"""The signals the machine-code handler counts, each where one of these Python handlers of it is in place."""


def _counted_signals() -> list[int]:
    if threading.current_thread() is not threading.main_thread() or _sigaction() is None:
        return []
    # (signal.getsignal's value, without its 2 us of trying the handler as an enum member)
    return [sig for sig, handlers in _COUNTED.items() if any(_signal.getsignal(sig) is h for h in handlers)]


@contextmanager
def counting_sigint() -> Iterator[int]:
    """Within the block, SIGINT (and SIGTERM, see the module) adds one to :data:`SIGINTS` instead of running
    Python's handler.

    Yields the count at the start (what the driver compares with).  Where the
    counting handler does not apply (another thread, a handler of the
    program's own, no ``sigaction``) nothing is changed: the count then never
    moves and a SIGINT is handled by Python when the block ends.
    """
    seen = int(SIGINTS[0])
    signals = _counted_signals()
    sigaction = _sigaction()
    restore = []
    try:
        for sig in signals:
            old = ctypes.create_string_buffer(_SIGACTION_BYTES)
            if sigaction(sig, None, old) != 0:  # pragma: no cover - cannot fail for SIGINT or SIGTERM
                continue
            new = ctypes.create_string_buffer(old.raw, _SIGACTION_BYTES)  # same mask and flags
            ctypes.c_void_p.from_buffer(new).value = _handler_address()  # the handler is the first member
            sigaction(sig, new, None)
            restore.append((sig, old))
        yield seen
    finally:
        for sig, old in reversed(restore):
            sigaction(sig, old, None)


def raise_if_interrupted(seen: int) -> None:
    """Raise :class:`KeyboardInterrupt` (:class:`Terminated` for a SIGTERM) if a signal was counted since
    the count was ``seen``."""
    if int(SIGINTS[0]) != seen:
        raise Terminated if int(LAST_SIGNAL[0]) == signal.SIGTERM else KeyboardInterrupt
