"""What the bad-input cases are made of: the :class:`Case` record, the files they start from, and their makers.

A case is the files it needs (written into a scratch directory), the command line (``{dir}`` is the
scratch directory, ``{data}`` the built-in PETS folder) and the exit status expected: 2 for a clean
one-line error, 0 where the input is legitimate. The files start from the built-in PETS 2009 S2.L1
folder's: its pinhole calibrations (JSON), View_001's Tsai calibration (XML) and the first 40
ground-truth rows (MOTChallenge, world positions in m in columns 8-9). Made from them, or from nothing:
edited ground-truth rows and calibrations, detection rows (left, top, width, height px), small grey videos
and PNG images, truncated videos, and YAML, XML and gzip bombs.
"""

import functools
import json
import tempfile
import zlib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import cv2
import numpy as np

PETS = resources.files("ptztrack.data") / "pets2009_s2l1"
PINHOLE = (PETS / "pinhole.json").read_text()
TSAI = (PETS / "View_001.xml").read_text()
GROUND_TRUTH_ROWS = (PETS / "gt_mot15.txt").read_text().splitlines()[:40]
A_FEW_STEPS = ["--frames", "2"]


@dataclass(frozen=True)
class Case:
    name: str
    argv: tuple[str, ...]
    files: dict[str, bytes | str | None] = field(default_factory=dict)  # None: no such file
    exit_status: int = 2
    says: tuple[str, ...] = ()  # what the line must name (the field, the file, the bound)


def _ground_truth(rows: list[str]) -> str:
    return "\n".join(rows) + "\n"


def _with_field(row: str, index: int, value: str) -> str:
    fields = row.split(",")
    fields[index] = value
    return ",".join(fields)


def _xml_with_entity(declaration: str, reference: str) -> str:
    body = TSAI.split("\n", 1)[1].replace('name="View_001"', f'name="{reference}"')
    return f'<?xml version="1.0"?>\n<!DOCTYPE Camera [{declaration}]>\n{body}'


def video_bytes(frames: int, size_px: tuple[int, int], directory: Path | None, codec: str = "MJPG") -> bytes:
    """A small AVI of ``frames`` grey frames of ``size_px`` (width, height) in ``codec`` (a fourcc);
    made in ``directory``, or in a temporary one."""
    if directory is None:
        with tempfile.TemporaryDirectory() as scratch:
            return video_bytes(frames, size_px, Path(scratch), codec)
    path = directory / f"video_{frames}_{size_px[0]}_{codec}.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*codec), 7.0, size_px)
    for _ in range(frames):
        writer.write(np.full((size_px[1], size_px[0], 3), 128, np.uint8))
    writer.release()
    return path.read_bytes()


def _truncated(video: bytes) -> bytes:
    """The first half of a video, as a copy cut short leaves it: its header still counts every frame, and
    a frame cut in the middle makes FFmpeg's decoder print lines of its own (MPEG-4 Part 2 does, as
    PETS's MS-MPEG-4 does; MJPG does not)."""
    return video[: len(video) // 2]


YAML_LAUGHS = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + level)}: &{chr(98 + level)} [{', '.join(['*' + chr(97 + level)] * 9)}]\n" for level in range(8)
)
YAML_DEEP_LAUGHS = (
    "a: &a ["
    + ", ".join(["xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx"] * 20)
    + "]\n"
    + "".join(
        f"{chr(98 + level)}: &{chr(98 + level)} [{', '.join(['*' + chr(97 + level)] * 20)}]\n" for level in range(6)
    )
)
XML_LAUGHS = '<!ENTITY a "aaaaaaaaaa">' + "".join(
    f'<!ENTITY {chr(98 + level)} "{("&" + chr(97 + level) + ";") * 10}">' for level in range(8)
)


def _pinhole_with_k_scaled(scale: float) -> str:
    """PETS's pinhole calibrations with View_001's focal lengths and principal point scaled."""
    views = json.loads(PINHOLE)
    views["View_001"]["K"] = (np.diag([scale, scale, 1.0]) @ np.asarray(views["View_001"]["K"])).tolist()
    return json.dumps(views)


def _detections_of(rows: list[str]) -> str:
    """Detection rows that are the ground-truth rows' View_001 boxes."""
    return "".join(f"{','.join(row.split(',')[:1] + ['-1'] + row.split(',')[2:6])},1,-1,-1,-1\n" for row in rows)


FIRST_TEN_FRAMES = [row for row in GROUND_TRUTH_ROWS if int(row.split(",")[0]) <= 10]
FIRST_TWO_FRAMES = [row for row in GROUND_TRUTH_ROWS if row.split(",")[0] in ("1", "2")]
DETECTION_ROWS = ["1,-1,300,200,40,100,0.9,-1,-1,-1", "2,-1,302,201,40,100,0.9,-1,-1,-1"]


def _png(size_px: tuple[int, int]) -> bytes:
    """A grey PNG image of ``size_px`` (width, height)."""
    return cv2.imencode(".png", np.full((size_px[1], size_px[0], 3), 128, np.uint8))[1].tobytes()


@functools.cache
def _gzip_bomb(uncompressed_bytes: int) -> bytes:
    """A gzip file of ``uncompressed_bytes`` of commas, made in pieces (about 1000 times smaller)."""
    compressor = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
    piece = b"," * 1_000_000
    return b"".join(compressor.compress(piece) for _ in range(uncompressed_bytes // len(piece))) + compressor.flush()
