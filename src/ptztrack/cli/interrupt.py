"""Ctrl-C that is never lost.

Python raises KeyboardInterrupt where the signal arrives. Inside Numba's compiler, which runs while a
run warms up, that is unsafe: in a ctypes callback the exception is printed and dropped (the command
would go on to its end), elsewhere it can leave LLVM's objects half-built (a double free at exit).
So the handler records the signal, raises at once only outside the compiler, and the steps of a run
ask :func:`raise_if_interrupted`. A command that ends on Ctrl-C by design (a camera served until
stopped) catches the KeyboardInterrupt itself and ends as it means to.
"""

import signal
import threading

_interrupted = threading.Event()


_COMPILER_PACKAGES = ("numba", "llvmlite")


def _on_sigint(signum, frame) -> None:
    _interrupted.set()
    if not _inside_compiler(frame):
        raise KeyboardInterrupt


def _inside_compiler(frame) -> bool:
    """Whether the interrupted code runs inside Numba's compiler (any frame of its stack in it)."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").partition(".")[0] in _COMPILER_PACKAGES:
            return True
        frame = frame.f_back
    return False


def catch_interrupts() -> None:
    """Record every Ctrl-C as well as raise it, where Ctrl-C has Python's default handler (a process
    started with SIGINT ignored keeps ignoring it)."""
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt if a Ctrl-C came since the command started."""
    if _interrupted.is_set():
        raise KeyboardInterrupt
