import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.loop.history import StepHistory
from ptztrack.types import Detections, Tracks


def tracks_of(count: int, first_id: int) -> Tracks:
    rows = np.arange(count, dtype=float)
    return Tracks(
        ids=first_id + np.arange(count),
        mean=np.outer(rows + first_id, [1.0, 2.0, 3.0, 4.0]),
        covariance=np.einsum("n,ij->nij", rows + 1.0, np.eye(4)),
        existence=np.linspace(0.1, 0.9, count),
        hits=np.arange(count) + 1,
        next_id=first_id + count,
    )


def assert_same_tracks(read: Tracks, written: Tracks) -> None:
    assert read.next_id == written.next_id and type(read.next_id) is type(written.next_id)
    for name in ("ids", "mean", "covariance", "existence", "hits"):
        np.testing.assert_array_equal(getattr(read, name), getattr(written, name))
        assert getattr(read, name).dtype == getattr(written, name).dtype


@settings(max_examples=30, deadline=None)
@given(counts=st.lists(st.integers(0, 9), min_size=1, max_size=40), chunk_rows=st.integers(1, 16))
def test_every_step_reads_back_as_it_was_written_across_chunks(counts, chunk_rows):
    written = [tracks_of(count, step * 10) for step, count in enumerate(counts)]
    kept = StepHistory(chunk_rows)
    for tracks in written:
        kept.append(tracks)
    assert len(kept) == len(written)
    for read, tracks in zip(kept, written, strict=True):
        assert_same_tracks(read, tracks)
    assert_same_tracks(kept[-1], written[-1])
    assert [len(step) for step in kept[1:3]] == counts[1:3]


def test_a_step_is_read_only_and_a_step_beyond_the_run_is_refused():
    kept = StepHistory()
    kept.append(Detections(np.array([[1.0, 2.0]]), np.array([50.0]), np.array([3])))
    kept.append(Detections.empty())
    assert len(kept[1]) == 0 and kept[0].person_index.tolist() == [3]
    with pytest.raises(ValueError):
        kept[0].feet_px[0, 0] = 5.0
    with pytest.raises(IndexError, match="step 2 of a history of 2"):
        kept[2]


def test_a_record_of_another_kind_or_shape_is_refused_naming_the_field():
    kept = StepHistory()
    kept.append(tracks_of(2, 0))
    with pytest.raises(TypeError, match="a history of Tracks given a Detections"):
        kept.append(Detections.empty())
    wrong = tracks_of(1, 5)
    with pytest.raises(ValueError, match=r"Tracks.mean of shape \(1, 2\)"):
        kept.append(Tracks(wrong.ids, wrong.mean[:, :2], wrong.covariance, wrong.existence, wrong.hits, 6))
