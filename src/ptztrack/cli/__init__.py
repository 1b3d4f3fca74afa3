"""The ``ptztrack`` command: a thin layer over the Python API.

:func:`main` parses the command line (:mod:`ptztrack.cli.arguments`, which imports no subsystem),
then imports the body of the command given from the module of its subject: ``run`` and ``view``
(:mod:`.run`), the PTZ paper's experiments (:mod:`.ptz_paper`), ``msg`` (:mod:`.msg`),
``registration`` (:mod:`.registration`), ``follow`` (:mod:`.follow`), ``occupancy``
(:mod:`.occupancy`), ``render`` (:mod:`.render`), ``score`` (:mod:`.score`), and the real and virtual cameras
(:mod:`.camera`).
"""

import argparse
import importlib
import logging
import os
import socket
import sys

from ptztrack.cli.arguments import parser
from ptztrack.cli.interrupt import catch_interrupts, interrupt_wins, stopped
from ptztrack.files import InputError, check_output_file, check_output_folder
from ptztrack.names import LOOPBACK

__all__ = ["main", "parser", "check_outputs", "check_ports"]


def check_ports(args: argparse.Namespace) -> None:
    """Refuse, before any work, a port of ``--port`` or ``--view`` that another program listens on, and
    ``--view-wait`` without ``--view``."""
    if getattr(args, "view_wait", False) and args.view is None:
        raise InputError("--view-wait: goes with --view (the run waits until a page of its view opens it)")
    for name in ("port", "view"):
        port = getattr(args, name, None)
        if not port:  # none, or 0: any free one
            continue
        with socket.socket() as probe:
            # As the servers bind: a port that only closed connections still hold is free to them.
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind((LOOPBACK, port))
            except OSError as error:
                raise InputError(f"--{name} {port}: cannot listen on {LOOPBACK}:{port} ({error.strerror})") from None


def check_outputs(args: argparse.Namespace) -> None:
    """Refuse, before any work, output paths that could not be written."""
    for name in ("json", "plot", "trails", "truth_log"):
        if getattr(args, name, None) is not None:
            check_output_file(getattr(args, name), "--" + name.replace("_", "-"))  # as the option is typed
    if getattr(args, "index", None) is not None and not args.index.exists():
        check_output_file(args.index, "--index")
    if getattr(args, "out", None) is not None:
        check_output_folder(args.out, "--out", args.overwrite)


def main(argv: list[str] | None = None) -> int:
    """The command line: 0 when done, 2 with one line on stderr for any bad input, 130 on Ctrl-C."""
    # Before any library configures the root logger (onvif-zeep-async does at import): warnings only,
    # one line each (a camera lost, back, still unreachable).
    logging.basicConfig(level=logging.WARNING, format="ptztrack: %(message)s")
    catch_interrupts()
    try:
        with interrupt_wins():
            args = parser().parse_args(argv)
            check_outputs(args)
            check_ports(args)
            module, _, function = args.handler.partition(":")
            return getattr(importlib.import_module(module), function)(args)
    except (InputError, RuntimeError) as error:
        print(f"ptztrack: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return stopped()
    except BrokenPipeError:
        # The reader (say, `head`) has gone: stop quietly, and keep Python from
        # complaining again when it flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:
        where = f"{error.filename}: " if error.filename else ""
        print(f"ptztrack: error: {where}{error.strerror or error}", file=sys.stderr)
        return 2
