"""Ctrl-C that is never lost, and ends the command within a second or two.

Python raises KeyboardInterrupt where the signal arrives. Inside Numba's compiler, which runs while a
run warms up, that is unsafe: in a ctypes callback the exception is printed and dropped (the command
would go on to its end), elsewhere it can leave LLVM's objects half-built (a double free at exit).
Under SciPy's compiled code (its Cython, as the scrambled Sobol points of the tracker's quadrature
are made) a KeyboardInterrupt is likewise printed as ignored. So the handler records the signal and
raises at once only outside those packages. Inside them, where one call can take seconds, the signal
is looked at again every ``POLL_S`` and raised once the call has returned, or, if it has not after
``COMPILER_WAIT_S``, the process ends without unwinding (:func:`_end_now`).
The steps of a run also ask :func:`raise_if_interrupted`, for a
KeyboardInterrupt that some library caught. A command that ends on Ctrl-C by design (a camera served
until stopped) catches the KeyboardInterrupt itself and ends as it means to.

Once the KeyboardInterrupt is raised, further Ctrl-Cs are ignored: the command is stopping, and a
second KeyboardInterrupt would break into that stop (a terminal's Ctrl-C that reaches the process
and its group, or a second press, gave a traceback from ``threading._shutdown`` joining the local
executor's thread, or a death by SIGINT instead of exit status 130).
"""

import _thread
import gc
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

INTERRUPTED = "ptztrack: interrupted; nothing was left half-written"
"""The one line on stderr of a command that Ctrl-C stopped."""
INTERRUPTED_STATUS = 130
COMPILER_WAIT_S = 1.0
POLL_S = 0.05

_COMPILER_PACKAGES = ("numba", "llvmlite", "scipy")

_interrupted = threading.Event()
_raised = threading.Event()
_watching = threading.Lock()


def _on_sigint(signum, frame) -> None:
    _interrupted.set()
    if _raised.is_set():  # a Ctrl-C that arrived before SIGINT was ignored, handled only now
        return
    if _inside_compiler(frame):
        if _watching.acquire(blocking=False):
            threading.Thread(target=_watch_the_compiler, name="ptztrack-ctrl-c", daemon=True).start()
        return
    _raise()


def _inside_compiler(frame) -> bool:
    """Whether the interrupted code runs inside Numba's compiler or SciPy (any frame of its stack in them)."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").partition(".")[0] in _COMPILER_PACKAGES:
            return True
        frame = frame.f_back
    return False


def _raise() -> None:
    _raised.set()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    raise KeyboardInterrupt


def _watch_the_compiler() -> None:
    """Have the handler look again where the main thread is, until it has raised or the wait is over."""
    deadline = time.monotonic() + COMPILER_WAIT_S
    while time.monotonic() < deadline:
        time.sleep(POLL_S)
        if _raised.is_set():
            return
        _thread.interrupt_main(signal.SIGINT)
    if not _raised.is_set():
        _end_now()


def _end_now() -> None:
    """End the process from this thread while the main thread compiles. Nothing is left half-written:
    every output appears by a rename once whole (:mod:`ptztrack.files`)."""
    _raised.set()
    if sys.stderr.isatty():  # a progress bar's line is not ended
        sys.stderr.write("\n")
    print(INTERRUPTED, file=sys.stderr, flush=True)
    sys.stdout.flush()
    os._exit(INTERRUPTED_STATUS)


def catch_interrupts() -> None:
    """Record every Ctrl-C as well as raise it, where Ctrl-C has Python's default handler (a process
    started with SIGINT ignored keeps ignoring it)."""
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt if a Ctrl-C came since the command started."""
    if _interrupted.is_set():
        _raise()


@contextmanager
def interrupt_wins() -> Iterator[None]:
    """After a Ctrl-C, whatever exception ends the block is the KeyboardInterrupt: code that calls back
    into Python may turn one raised there into an error of its own (pydantic-core made it a SchemaError
    while a model class was built, a traceback and exit status 1)."""
    try:
        yield
    except BaseException:
        if _interrupted.is_set():
            raise KeyboardInterrupt from None
        raise


def stopped() -> int:
    """Print the one line of a command that Ctrl-C stopped; its exit status."""
    print(INTERRUPTED, file=sys.stderr)
    # CPython marks a KeyboardInterrupt that left an exec() of a string (dataclasses make their methods
    # so) as never handled, and ``python -m`` then ends the process by SIGINT, not with the status
    # returned; the next exec() of a string clears the mark.
    exec("")
    # The interpreter's last collections would walk every object Numba and SciPy made, past the two
    # seconds Ctrl-C may take; nothing left needs them, and the memory goes back with the process.
    gc.freeze()
    return INTERRUPTED_STATUS
