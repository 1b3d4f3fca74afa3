"""The live web view of a run: a page on 127.0.0.1 that draws each step, with pause, step and resume.

:class:`ViewHub` is the loop's observer (:data:`ptztrack.loop.StepObserver`)
and the meeting point of two threads: the run's, which builds a step's state
(:class:`~ptztrack.evaluate.view_state.ViewState`) only when a page is
connected and has taken the last one, at most MAX_STATES_PER_S times a
second (so the view costs a fast run little), and blocks while paused; and
uvicorn's (:class:`ViewServer`), whose WebSocket sends the newest state to
each page and passes its buttons back. The page (``web/index.html``: plain
JavaScript and SVG, no build step) keeps the last state when the run ends.
"""

import asyncio
import json
import threading
import time
from importlib import resources

import uvicorn
from starlette.applications import Starlette
from starlette.responses import HTMLResponse
from starlette.routing import Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from ptztrack.evaluate.view_state import ViewState
from ptztrack.types import DecisionContext

HOST = "127.0.0.1"  # never another interface: the view shows a camera's pictures
MAX_STATES_PER_S = 30.0  # faster than a page redraws is wasted work in the run's thread
SEND_POLL_S = 0.01  # how often a page's sender looks for a newer state
FINAL_SEND_TIMEOUT_S = 5.0  # how long the end of a run waits for the open pages to get the final state
COMMANDS = ("pause", "step", "resume")


class ViewHub:
    """The run's side of the view: observer, pause switch, newest state.

    paused : the run waits after its first step until a page sends resume or step (a run started
        with a view waits for someone to see it: ``resume_on_connect`` resumes it when a page connects).
    """

    def __init__(self, view_state: ViewState, paused: bool = False, resume_on_connect: bool = False):
        self.view_state = view_state
        self.resume_on_connect = resume_on_connect
        self._condition = threading.Condition()
        self._paused, self._steps_allowed = paused, 0
        self._message, self._version, self._taken, self._finished = "", 0, True, False
        self._pages, self._pages_with_final = 0, 0
        self._last_built_s = -float("inf")

    def __call__(self, step: int, context: DecisionContext, record: dict) -> None:
        """After each step of the loop: count, publish a state if a page can take one, wait while paused."""
        self.view_state.count(record)
        last = step == self.view_state.steps - 1
        with self._condition:
            due = self._taken and time.perf_counter() - self._last_built_s >= 1.0 / MAX_STATES_PER_S
            # While paused every step is shown: it is where the run waits, or a single step.
            wanted = self._paused or last or (self._pages > 0 and due)
        if wanted:
            self._publish(self.view_state.state(step, context, record), finished=last)
        if not last:  # nothing is left to wait for after the last step
            with self._condition:
                self._steps_allowed = max(0, self._steps_allowed - 1)
                self._condition.wait_for(lambda: not self._paused or self._steps_allowed > 0)

    def _publish(self, state: dict, finished: bool) -> None:
        with self._condition:
            state["paused"], state["finished"] = self._paused, finished
            self._message = json.dumps(state, allow_nan=False)
            self._version += 1
            self._taken, self._finished = False, finished
            self._last_built_s = time.perf_counter()

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
        """(the newest state as JSON, its version, whether it is the run's last) for a page's sender."""
        with self._condition:
            self._taken = True
            return self._message, self._version, self._finished

    def page_opened(self) -> None:
        with self._condition:
            self._pages += 1
            if self.resume_on_connect:
                self._paused, self.resume_on_connect = False, False
                self._condition.notify_all()

    def page_closed(self, got_final: bool) -> None:
        with self._condition:
            self._pages -= 1
            self._pages_with_final += got_final
            self._condition.notify_all()

    def wait_for_pages(self, timeout_s: float = FINAL_SEND_TIMEOUT_S) -> bool:
        """Wait until every open page has been sent the final state and closed; False on timeout."""
        with self._condition:
            return self._condition.wait_for(lambda: self._pages == 0, timeout_s)


def page_html() -> str:
    """The page: one HTML file with its script and style (package data, ``web/index.html``)."""
    return resources.files("ptztrack.evaluate").joinpath("web/index.html").read_text(encoding="utf-8")


def view_app(hub: ViewHub) -> Starlette:
    """The page at ``/`` and the state's WebSocket at ``/ws``."""
    html = page_html()

    async def index(request) -> HTMLResponse:
        return HTMLResponse(html)

    async def socket(websocket: WebSocket) -> None:
        await websocket.accept()
        hub.page_opened()
        receiving = asyncio.create_task(_receive_commands(websocket, hub))
        sent, finished = 0, False
        try:
            while not finished and not receiving.done():
                message, version, finished = hub.newest()
                if version != sent:
                    await websocket.send_text(message)
                    sent = version
                else:
                    await asyncio.sleep(SEND_POLL_S)
            if finished:
                # A clean close after the final state: the page keeps it, and logs no error.
                await websocket.close(code=1000)
        except WebSocketDisconnect:
            finished = False
        finally:
            receiving.cancel()
            hub.page_closed(finished)

    return Starlette(routes=[Route("/", index), WebSocketRoute("/ws", socket)])


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

    port : 0 for any free port; ``address`` is the page's URL once started.
    """

    def __init__(self, hub: ViewHub, port: int = 0):
        self.hub = hub
        config = uvicorn.Config(view_app(hub), host=HOST, port=port, log_level="warning", lifespan="off")
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
            self.hub.wait_for_pages()
        self._server.should_exit = True
        self._thread.join()
