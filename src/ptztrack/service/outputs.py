"""A camera's tracks as they are decided, appended to files rotated every ``rotate_s``.

Each camera's folder holds, per period, ``tracks-<UTC start>.mot.txt`` (the MOTChallenge text layout of
a run folder's ``tracks_mot.txt``: ``frame, id, -1, -1, -1, -1, 1, x_m, y_m, 0``, the frame counted from
1 in each file) and ``tracks-<UTC start>.jsonl`` (one JSON object per picture used: its capture time,
frame, pose and tracks). A period's files are written as ``<name>.part``, whole lines at a time, and
renamed to ``<name>`` when the period ends or the service stops: a file without ``.part`` is whole and
never written again. A ``.part`` left by a process that was killed is cut to its last whole line and
renamed when the service starts again.
"""

import json
import os
import time
from pathlib import Path

import numpy as np

from ptztrack.evaluate.report import mot_rows
from ptztrack.types import Tracks

PART = ".part"
SUFFIXES = (".mot.txt", ".jsonl")


def _stamp(time_s: float) -> str:
    """The UTC time ``time_s`` (epoch s) to the millisecond, as it sorts: 20261129T221500.250Z."""
    return time.strftime("%Y%m%dT%H%M%S", time.gmtime(time_s)) + f".{int(time_s % 1 * 1000):03d}Z"


def mot_lines(frame: int, tracks: Tracks) -> str:
    """The tracks of one picture as the lines of a run folder's tracks_mot.txt
    (:func:`ptztrack.evaluate.report.mot_rows`)."""
    return "".join(",".join(map(str, row)) + "\n" for row in mot_rows(frame, tracks))


def track_states(tracks: Tracks) -> list[dict]:
    """Each track as a JSON-ready mapping: id, ground position x_m, y_m, velocity vx_m_s, vy_m_s, the
    position's standard deviation ``position_sd_m`` (the root of the mean of its two variances, m) and
    its existence."""
    variances_m2 = np.diagonal(tracks.covariance, axis1=1, axis2=2)[:, :2]
    sd_m = np.sqrt(np.mean(variances_m2, axis=1))
    return [
        {
            "id": int(track_id),
            "x_m": round(float(mean[0]), 4),
            "y_m": round(float(mean[1]), 4),
            "vx_m_s": round(float(mean[2]), 4),
            "vy_m_s": round(float(mean[3]), 4),
            "position_sd_m": round(float(sd), 4),
            "existence": round(float(existence), 4),
        }
        for track_id, mean, sd, existence in zip(tracks.ids, tracks.mean, sd_m, tracks.existence, strict=True)
    ]


def recover_parts(folder: Path) -> list[Path]:
    """Cut every ``.part`` in ``folder`` to its last whole line and rename it whole; the files renamed."""
    recovered = []
    for part in sorted(folder.glob(f"*{PART}")):
        data = part.read_bytes()
        with open(part, "r+b") as file:
            file.truncate(data.rfind(b"\n") + 1)
        whole = part.with_name(part.name[: -len(PART)])
        os.replace(part, whole)
        recovered.append(whole)
    return recovered


class TrackFiles:
    """One camera's MOT and JSON-lines files in ``folder``, rotated every ``rotate_s`` of ``clock``.

    :meth:`append` writes one picture's row; :meth:`close` renames the current period's files whole.
    """

    def __init__(self, folder: Path, rotate_s: float, clock=time.time):
        self.folder, self.rotate_s, self._clock = folder, rotate_s, clock
        folder.mkdir(parents=True, exist_ok=True)
        recover_parts(folder)
        self._files: list = []
        self._paths: list[Path] = []
        self._ends_s = -np.inf
        self._frame = 0
        self.rotated = 0

    def append(self, row: dict) -> None:
        """One picture's row of the live loop (capture_time_s, poses, tracks), as whole lines."""
        now_s = self._clock()
        if now_s >= self._ends_s:
            self._rotate(now_s)
        self._frame += 1
        tracks: Tracks = row["tracks"]
        record = {
            "time_s": round(float(row["capture_time_s"]), 6),
            "frame": self._frame,
            "pose": [None if not np.isfinite(value) else round(float(value), 4) for value in row["poses"]],
            "detected": bool(row["detected"]),
            "tracks": track_states(tracks),
        }
        mot, jsonl = self._files
        mot.write(mot_lines(self._frame, tracks))
        jsonl.write(json.dumps(record, separators=(",", ":")) + "\n")

    def close(self) -> None:
        """Close the current period's files and rename them whole."""
        for file, path in zip(self._files, self._paths, strict=True):
            file.close()
            os.replace(path, path.with_name(path.name[: -len(PART)]))
        self._files, self._paths = [], []

    def _rotate(self, now_s: float) -> None:
        if self._files:
            self.close()
            self.rotated += 1
        stamp = _stamp(now_s)
        self._paths = [self.folder / f"tracks-{stamp}{suffix}{PART}" for suffix in SUFFIXES]
        # Line-buffered: every line written reaches the file whole, for a reader that follows it.
        self._files = [open(path, "a", encoding="utf-8", buffering=1) for path in self._paths]  # noqa: SIM115
        self._ends_s, self._frame = now_s + self.rotate_s, 0
