"""The web view of a run: a page on 127.0.0.1 that draws each step, with pause, step and resume.

:class:`ViewHub` is the meeting point of two threads. The run's thread
calls :meth:`ViewHub.after_step` after each step (through
:meth:`ViewState.observer <ptztrack.view.view_state.ViewState.observer>`,
or a replay of a finished run's states): only when a page is connected, has
taken the last state and a new one is due does it take the step's state
(references, and a synthetic view's picture), and it blocks while paused.
uvicorn's thread (:class:`ViewServer`) builds the state's JSON, once for
every page, and sends it: a page's sender sleeps until the run's thread
wakes it (``call_soon_threadsafe``), so an idle view costs nothing. A state
is due at most MAX_STATES_PER_S times a second, and no sooner than the last
one's cost (the CPU time of taking, building and sending it) divided by
VIEW_SHARE: a fast run gives the view a small share of its time, and a slow
one shows every step. The page (``web/index.html``: plain JavaScript and
SVG, no build step) keeps the last state when the run ends.
"""

import asyncio
import contextlib
import json
import threading
import time
from collections.abc import Callable, Sequence
from importlib import resources

import uvicorn
from starlette.applications import Starlette
from starlette.responses import HTMLResponse
from starlette.routing import BaseRoute, Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from ptztrack.names import LOOPBACK

HOST = LOOPBACK
MAX_STATES_PER_S = 30.0  # faster than a page redraws is wasted work
# The share of a fast run's CPU time for taking, building and sending states; the run loses about twice
# that (the threads' switching, the caches), as benchmarks/view_overhead.py measures.
VIEW_SHARE = 0.02
FINAL_SEND_TIMEOUT_S = 5.0  # how long the end of a run waits for the open pages to get the final state
COMMANDS = ("pause", "step", "resume")

Build = Callable[[], str]
"""Builds a step's state as JSON (on the server's thread)."""


class ViewHub:
    """The run's side of the view: the newest state, the pause switch, the pages.

    paused : the run waits after its first step until a page sends resume or step; with
        ``resume_on_connect`` the first page to connect resumes it (a run started with a view waits
        for someone to see it).
    """

    def __init__(self, paused: bool = False, resume_on_connect: bool = False):
        self.resume_on_connect = resume_on_connect
        self._condition = threading.Condition()
        self._paused, self._steps_allowed = paused, 0
        self._build: Build = lambda: "{}"
        self._version, self._flags, self._finished = 0, (paused, False), False
        self._message, self._message_version = "", 0
        self._taken = True  # whether a page has been sent the newest state (so that a newer one may be taken)
        self._due_s, self._published_s, self._take_s, self._cost_s = -float("inf"), 0.0, 0.0, 0.0
        self._wake: dict[int, Callable[[], None]] = {}  # per page: wakes its sender (from any thread)

    def after_step(self, step: int, last: bool, take: Callable[[], Build]) -> None:
        """From the run's thread after each step: ``take()`` (on this thread) the step's state if a page
        can show it (always while paused, and at the last step), then wait while paused."""
        with self._condition:
            due = self._taken and time.perf_counter() >= self._due_s
            # While paused every step is shown: it is where the run waits, or a single step.
            wanted = self._paused or last or (bool(self._wake) and due)
        if wanted:
            # Costs in the working thread's CPU time: on a loaded machine the wall time would count
            # other processes' turns too.
            started_s = time.thread_time()
            build = take()
            taken_s = time.thread_time() - started_s
            with self._condition:
                self._published_s = time.perf_counter()
                self._take_s, self._cost_s = taken_s, 0.0
                self._due_s = self._published_s + 1.0 / MAX_STATES_PER_S
                self._build, self._version = build, self._version + 1
                self._flags, self._finished, self._taken = (self._paused, last), last, False
                wake = list(self._wake.values())
            for wake_page in wake:
                wake_page()
        if not last:  # nothing is left to wait for after the last step
            with self._condition:
                self._steps_allowed = max(0, self._steps_allowed - 1)
                self._condition.wait_for(lambda: not self._paused or self._steps_allowed > 0)

    def end(self) -> None:
        """The run is over, at its last step or cut short (Ctrl-C of a live run): the newest state
        becomes the final one, sent to the open pages, which then close."""
        with self._condition:
            if self._finished:
                return
            self._version += self._version > 0  # republished as final; without a state, nothing to send
            self._flags, self._finished, self._taken = (False, True), True, False
            wake = list(self._wake.values())
        for wake_page in wake:
            wake_page()

    def command(self, name: str) -> None:
        """A page's button: pause, step (one step, then paused) or resume."""
        with self._condition:
            if name == "pause":
                self._paused = True
            elif name == "step":
                self._paused, self._steps_allowed = True, self._steps_allowed + 1
            elif name == "resume":
                self._paused = False
            self._condition.notify_all()

    def newest(self) -> tuple[str, int, bool]:
        """(the newest state's message, its version, whether it is the run's last) for a page's sender;
        the message is built here by the first sender to ask for it."""
        with self._condition:
            version, build, (paused, finished) = self._version, self._build, self._flags
            message = self._message if self._message_version == version else None
        if message is None:
            message = f'{{"paused": {json.dumps(paused)}, "finished": {json.dumps(finished)}, "state": {build()}}}'
            with self._condition:
                if self._version == version:
                    self._message, self._message_version = message, version
        return message, version, finished

    def sent(self, version: int, cost_s: float) -> None:
        """A page's sender has sent state ``version``, which took its thread ``cost_s`` of CPU time (building
        it, if it did, and sending it): the next state is due no sooner than all of the state's cost over
        VIEW_SHARE after it was published."""
        with self._condition:
            if version == self._version:
                self._cost_s += cost_s
                self._due_s = max(self._due_s, self._published_s + (self._take_s + self._cost_s) / VIEW_SHARE)
                self._taken = True

    @property
    def published(self) -> int:
        """The states published so far."""
        with self._condition:
            return self._version

    @property
    def pages(self) -> int:
        """The pages connected."""
        with self._condition:
            return len(self._wake)

    def page_opened(self, page: int, wake: Callable[[], None]) -> None:
        """A page's sender, and how to wake it when a state is published."""
        with self._condition:
            self._wake[page] = wake
            if self.resume_on_connect:
                self._paused, self.resume_on_connect = False, False
                self._condition.notify_all()

    def page_closed(self, page: int) -> None:
        with self._condition:
            del self._wake[page]
            self._condition.notify_all()

    def wait_for_pages(self, timeout_s: float = FINAL_SEND_TIMEOUT_S) -> bool:
        """Wait until every open page has been sent the final state and closed; False on timeout."""
        with self._condition:
            return self._condition.wait_for(lambda: not self._wake, timeout_s)


def page_html() -> str:
    """The page: one HTML file with its script and style (package data, ``web/index.html``)."""
    return resources.files("ptztrack.view").joinpath("web/index.html").read_text(encoding="utf-8")


def view_app(hub: ViewHub, routes: Sequence[BaseRoute] = ()) -> Starlette:
    """The page at ``/`` and the state's WebSocket at ``/ws``, and ``routes`` beside them (a service's
    health, say)."""
    html = page_html()

    async def index(request) -> HTMLResponse:
        return HTMLResponse(html)

    async def socket(websocket: WebSocket) -> None:
        await websocket.accept()
        loop, published = asyncio.get_running_loop(), asyncio.Event()
        page = id(published)

        def wake() -> None:
            with contextlib.suppress(RuntimeError):  # the server stopped as the run published: nobody to wake
                loop.call_soon_threadsafe(published.set)

        hub.page_opened(page, wake)
        receiving = asyncio.create_task(_receive_commands(websocket, hub))
        sent, finished = 0, False
        try:
            while not receiving.done():
                # Cleared before looking: a state published after the look sets it again.
                published.clear()
                started_s = time.thread_time()
                message, version, finished = hub.newest()
                if version != sent:
                    await websocket.send_text(message)
                    hub.sent(version, time.thread_time() - started_s)
                    sent = version
                    if not finished:
                        continue  # a newer state may be out already
                if finished:
                    break
                waiting = asyncio.create_task(published.wait())
                await asyncio.wait((waiting, receiving), return_when=asyncio.FIRST_COMPLETED)
                waiting.cancel()
            if finished:
                # A clean close after the final state: the page keeps it, and logs no error.
                await websocket.close(code=1000)
        except WebSocketDisconnect:
            pass  # the page went
        finally:
            receiving.cancel()
            hub.page_closed(page)

    return Starlette(routes=[Route("/", index), WebSocketRoute("/ws", socket), *routes])


async def _receive_commands(websocket: WebSocket, hub: ViewHub) -> None:
    """The page's buttons, as JSON ``{"command": "pause" | "step" | "resume"}``; anything else is ignored."""
    try:
        while True:
            try:
                name = json.loads(await websocket.receive_text()).get("command")
            except (json.JSONDecodeError, AttributeError):
                continue
            if name in COMMANDS:
                hub.command(name)
    except (WebSocketDisconnect, RuntimeError):
        return  # the page went, or the socket was closed after the final state


class ViewServer:
    """uvicorn serving :func:`view_app` on 127.0.0.1 in a background thread (a context manager).

    port : 0 for any free port; ``address`` is the page's URL once started; routes : served beside the
    view (:func:`view_app`).
    """

    def __init__(self, hub: ViewHub, port: int = 0, routes: Sequence[BaseRoute] = ()):
        self.hub = hub
        config = uvicorn.Config(view_app(hub, routes), host=HOST, port=port, log_level="warning", lifespan="off")
        self._server = uvicorn.Server(config)
        self._thread = threading.Thread(target=self._server.run, name="ptztrack-view", daemon=True)

    def __enter__(self) -> "ViewServer":
        self._thread.start()
        while not self._server.started:
            if not self._thread.is_alive():
                raise RuntimeError(f"the view could not listen on {HOST}:{self._server.config.port}")
            time.sleep(0.01)
        return self

    @property
    def port(self) -> int:
        return int(self._server.servers[0].sockets[0].getsockname()[1])

    @property
    def address(self) -> str:
        return f"http://{HOST}:{self.port}/"

    def __exit__(self, exc_type, exc, traceback) -> None:
        if exc_type is None:  # after a failure there is no final state to wait for
            self.hub.end()
            self.hub.wait_for_pages()
        self._server.should_exit = True
        self._thread.join()


def replay(hub: ViewHub, lines: list[str], steps_per_s: float) -> None:
    """A finished run's states (``view_states.jsonl``'s lines) through ``hub`` as a run would publish
    them, ``steps_per_s`` of them a second (pause, step and resume work the same)."""
    for step, line in enumerate(lines):
        shown_s = time.monotonic()
        last = step == len(lines) - 1
        hub.after_step(step, last, _built(line))
        if not last:
            time.sleep(max(0.0, shown_s + 1.0 / steps_per_s - time.monotonic()))


def _built(state: str) -> Callable[[], Build]:
    """``take`` of a state built already."""

    def take() -> Build:
        return lambda: state

    return take
