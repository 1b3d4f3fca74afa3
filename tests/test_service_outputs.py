"""A camera's tracks appended to rotated files: every file without .part is whole and final, the current
period is a .part of whole lines, and a .part a killed service left is made whole at the next start."""

import json

import numpy as np

from ptztrack.service.outputs import TrackFiles, recover_parts
from ptztrack.types import Tracks


def _tracks(ids, xs_m) -> Tracks:
    n = len(ids)
    mean = np.zeros((n, 4))
    mean[:, 0], mean[:, 1] = xs_m, 2.0
    return Tracks(np.array(ids), mean, np.tile(np.eye(4) * 0.04, (n, 1, 1)), np.full(n, 0.9), np.full(n, 5))


def _row(time_s: float, tracks: Tracks) -> dict:
    return {"capture_time_s": time_s, "poses": np.array([10.0, 20.0, 2.0]), "detected": True, "tracks": tracks}


class Clock:
    def __init__(self) -> None:
        self.now_s = 1_000_000.0

    def __call__(self) -> float:
        return self.now_s


def test_rotation_yields_whole_files_and_the_current_period_as_part(tmp_path):
    clock = Clock()
    files = TrackFiles(tmp_path, rotate_s=2.0, clock=clock)
    for step in range(10):  # 0.5 s apart: four pictures a period
        files.append(_row(clock.now_s, _tracks([step, step + 100], [0.5 * step, 1.0])))
        clock.now_s += 0.5
    whole = sorted(tmp_path.glob("tracks-*.jsonl"))
    parts = sorted(tmp_path.glob("*.part"))
    assert len(whole) == 2 and files.rotated == 2 and len(parts) == 2  # the third period is being written
    for jsonl in whole:
        records = [json.loads(line) for line in jsonl.read_text().splitlines()]
        assert [record["frame"] for record in records] == [1, 2, 3, 4]
        mot = jsonl.with_name(jsonl.name.replace(".jsonl", ".mot.txt")).read_text().splitlines()
        # MOTChallenge rows: frame, id, -1 x 4, 1, x, y, 0, the frame counted in its file.
        assert len(mot) == 8 and all(len(line.split(",")) == 10 for line in mot)
        assert {int(line.split(",")[0]) for line in mot} == {1, 2, 3, 4}
    first = json.loads(whole[0].read_text().splitlines()[1])
    assert first["tracks"][0] == {
        "id": 1, "x_m": 0.5, "y_m": 2.0, "vx_m_s": 0.0, "vy_m_s": 0.0, "position_sd_m": 0.2, "existence": 0.9
    }  # fmt: skip
    files.close()
    assert not list(tmp_path.glob("*.part")) and len(list(tmp_path.glob("tracks-*.jsonl"))) == 3


def test_a_part_left_by_a_killed_service_is_cut_to_its_whole_lines_and_renamed(tmp_path):
    part = tmp_path / "tracks-20261129T120000.000Z.jsonl.part"
    part.write_text('{"frame": 1}\n{"frame": 2}\n{"fra')
    assert recover_parts(tmp_path) == [tmp_path / "tracks-20261129T120000.000Z.jsonl"]
    assert (tmp_path / "tracks-20261129T120000.000Z.jsonl").read_text() == '{"frame": 1}\n{"frame": 2}\n'
    TrackFiles(tmp_path, 3600.0)  # a new start recovers as well
    assert not list(tmp_path.glob("*.part"))
