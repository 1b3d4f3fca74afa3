"""An episode's random streams, each named for what draws from it.

Every random draw of an episode comes from one of six independent streams spawned from its seed: the
scene (the people), the detector (one stream per frame, spawned from it), the policy, the camera's
landing errors, the tracker (for a tracker that draws, such as a particle filter) and the detector
model's draws. So runs of different policies with the same seed meet the same people and, frame by
frame, the same detector luck (common random numbers), which makes their paired comparison far less
noisy.
"""

from dataclasses import dataclass, fields

import numpy as np


@dataclass(frozen=True)
class EpisodeStreams:
    """The six independent streams of an episode (:func:`episode_streams`), each a
    :class:`numpy.random.SeedSequence` that its user spawns from or seeds a generator with."""

    scene: np.random.SeedSequence
    detector: np.random.SeedSequence
    policy: np.random.SeedSequence
    landing: np.random.SeedSequence
    tracker: np.random.SeedSequence
    detector_model: np.random.SeedSequence


def episode_streams(seed: int) -> EpisodeStreams:
    """The streams of the episode of ``seed``: the seed's first six children, in the order of
    :class:`EpisodeStreams`' fields.

    Each is the stream it was before later ones were added (spawning more children does not change the
    earlier ones); each call gives fresh sequences, so what one user spawns does not move another's.
    """
    return EpisodeStreams(*np.random.SeedSequence(seed).spawn(len(fields(EpisodeStreams))))
