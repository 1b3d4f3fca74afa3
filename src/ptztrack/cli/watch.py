"""What watches a run of ``run``, ``follow`` or ``live``: its web view, its view states, its progress bar."""

from collections import deque
from pathlib import Path

from ptztrack.cli.interrupt import raise_if_interrupted
from ptztrack.loop.executors import Progress
from ptztrack.loop.steps import StepObserver
from ptztrack.names import VIEW_STATES_FILE
from ptztrack.view.video import VIDEO_MAX_STEPS
from ptztrack.view.view_state import StepView, ViewState
from ptztrack.view.web_view import ViewHub, ViewServer


class Watch:
    """What watches a run of ``run``, ``follow`` or ``live``: the web view on 127.0.0.1:``port`` (None:
    none; a context manager: the server runs inside the block), where ``keep``, the view states of the
    last ``VIDEO_MAX_STEPS`` steps (those of the run's video), for the run folder's view_states.jsonl
    (what ``ptztrack view`` replays), and a progress bar of the steps (``progress``; None: none).

    view : ``view(world, policy)`` gives the run's :class:`ViewState`.
    hold : the run waits after its first step for a page to open it (``--view-wait`` of a simulated run, to
    be watched from its start); without, pages join and leave a run that never waits for them.
    """

    def __init__(self, port: int | None, keep: bool, view, progress: Progress | None = None, hold: bool = False):
        self.view, self.port, self.keep, self.progress, self.hold = view, port, keep, progress, hold
        self.views: deque[StepView] = deque(maxlen=VIDEO_MAX_STEPS)
        self.view_state: ViewState | None = None
        self.hub = None if port is None else ViewHub(paused=hold, resume_on_connect=hold)
        self._server: ViewServer | None = None

    def __enter__(self) -> "Watch":
        if self.hub is not None and self.port is not None:
            self._server = ViewServer(self.hub, self.port).__enter__()
            when = "the run starts when a page opens it" if self.hold else "pages may join and leave at any time"
            print(f"view at {self._server.address} ({when})", flush=True)
        return self

    def __exit__(self, *failure) -> None:
        if self.progress is not None:
            self.progress.close()
        if self._server is not None:
            self._server.__exit__(*failure)

    def observe(self, world, policy) -> StepObserver:
        """The run's step observer: it also stops the run at the step after a Ctrl-C that was lost."""
        view_state = self.view_state = self.view(world, policy)
        watching = None
        if self.hub is not None or self.keep:
            watching = view_state.observer(
                None if self.hub is None else self.hub.after_step, self.views if self.keep else None
            )
        progress = self.progress

        def observe(step: int, context, record: dict) -> None:
            raise_if_interrupted()
            if watching is not None:
                watching(step, context, record)
            if progress is not None:
                progress(step + 1, view_state.steps)

        return observe

    def write(self, folder: Path) -> None:
        """view_states.jsonl into the run's folder."""
        assert self.view_state is not None, "observe() gives the run its observer first"
        self.view_state.write(folder / VIEW_STATES_FILE, self.views)
