"""``ptztrack serve CONFIG``: the cameras of a service configuration, run until SIGTERM or Ctrl-C."""

import argparse
import gc
import signal
import threading

from ptztrack.service import load_service_config, serve


def serve_command(args: argparse.Namespace) -> int:
    config = load_service_config(args.config)
    stop = threading.Event()
    # SIGTERM (systemd's stop, docker stop) ends the service as Ctrl-C does: files closed whole.
    signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())
    serve(config, stop, started=lambda line: print(line, flush=True))
    print("ptztrack serve: stopped; every file closed whole", flush=True)
    # The interpreter's last collections would walk every object Numba, SciPy and Ray made, a second of
    # the two SIGTERM may take; nothing left needs them, and the memory goes back with the process.
    gc.freeze()
    return 0
