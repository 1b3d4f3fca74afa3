"""A camera network's cameras as Ray actors: each camera's capture and detection where the camera is.

Every step the centre (:func:`ptztrack.loop.simulated.run_network_loop`) sends
each camera its commanded pose; the camera's actor lands, looks and detects
with the camera's own streams (:class:`~ptztrack.loop.simulated.CameraWorker`,
moved into the actor whole, streams included) and returns its
:class:`~ptztrack.loop.steps.Look`. The centre keeps the one belief and the joint
decision: it updates the belief with camera ``k``'s look as soon as it
arrives, while the cameras after ``k`` are still looking. Since a worker
draws only from its own streams, the episode is the one of the in-process
cameras, bit for bit.

One actor per camera by default, as on a cluster whose nodes are the
cameras. Each actor is a process of its own (about 260 MB resident with
ptztrack loaded), so on a small machine ``cameras_per_actor`` puts several
cameras' workers in one actor: camera ``k`` goes to actor ``k mod A``, so
the first cameras' looks, which the centre needs first, come from
different actors.
"""

import math
from collections.abc import Iterator, Sequence
from dataclasses import replace

import numpy as np

from ptztrack.loop.executors import connect_ray
from ptztrack.loop.simulated import CameraWorker
from ptztrack.loop.steps import Look


class CameraActor:
    """The workers of one or more cameras (by their index in the network), in one process."""

    def __init__(self, workers: dict[int, CameraWorker]):
        self.workers = workers

    def look(self, camera: int, step: int, commanded, wanted: bool) -> Look:
        return self.workers[camera].look(step, commanded, wanted)


class RayCameras:
    """The cameras' workers as Ray actors (:class:`ptztrack.loop.simulated.CameraFleet`), on the cluster
    :func:`~ptztrack.loop.executors.connect_ray` connects to (``RAY_ADDRESS``, else a local one).

    cameras_per_actor : how many cameras share one actor's process (see the module's docstring).
    """

    def __init__(self, workers: Sequence[CameraWorker], cameras_per_actor: int = 1):
        if cameras_per_actor < 1:
            raise ValueError(f"cameras_per_actor must be 1 or more (got {cameras_per_actor})")
        ray = connect_ray()
        self._ray = ray
        actor_count = math.ceil(len(workers) / cameras_per_actor)
        # The centre's detector model is learned where the belief is; the cameras never read it.
        shipped = [replace(worker, world=replace(worker.world, detector_model=None)) for worker in workers]
        remote_actor = ray.remote(CameraActor).options(scheduling_strategy="SPREAD")
        self.actors = [
            remote_actor.remote({k: shipped[k] for k in range(first, len(workers), actor_count)})
            for first in range(actor_count)
        ]
        self._actor_of = [self.actors[k % actor_count] for k in range(len(workers))]

    def looks(self, step: int, commanded: Sequence[np.ndarray], wanted: Sequence[bool]) -> Iterator[Look]:
        pending = [
            actor.look.remote(k, step, np.asarray(pose), wants)
            for k, (actor, pose, wants) in enumerate(zip(self._actor_of, commanded, wanted, strict=True))
        ]
        for reference in pending:
            yield self._ray.get(reference)

    def close(self) -> None:
        """End the actors (the cluster stays up)."""
        for actor in self.actors:
            self._ray.kill(actor)
