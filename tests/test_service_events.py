"""The service's events: a track's new, its updates at the set rate, its end; written as JSON lines and
published to a real broker (Debian's Mosquitto on 127.0.0.1), the messages a subscriber gets equal to
the lines written."""

import json

import numpy as np

from mqtt_broker import Subscriber, mosquitto
from ptztrack.service.config import MQTTSection
from ptztrack.service.events import EventOutlet, TrackEvents
from ptztrack.types import Tracks


def _tracks(ids) -> Tracks:
    n = len(ids)
    mean = np.zeros((n, 4))
    mean[:, 0] = np.arange(n)
    return Tracks(np.array(ids, dtype=int), mean, np.tile(np.eye(4), (n, 1, 1)), np.full(n, 0.8), np.full(n, 3))


def test_a_track_is_new_then_updated_at_the_rate_then_ends_once_unreported_long_enough():
    sent = []
    events = TrackEvents("front", "run", position_rate_hz=1.0, track_end_s=2.0, emit=lambda *event: sent.append(event))
    for step in range(11):  # five pictures a second for 2 s, track 4 reported throughout, track 5 from 1 s
        events.step(100.0 + 0.2 * step, _tracks([4, 5] if step >= 5 else [4]))
    for step in range(11, 30):  # then nobody for 3.8 s
        events.step(100.0 + 0.2 * step, _tracks([]))
    kinds = [(payload["type"], payload["after"]["track_id"]) for _, payload in sent]
    assert kinds == [("new", 4), ("update", 4), ("new", 5), ("update", 4), ("update", 5), ("end", 4), ("end", 5)]
    assert {topic for topic, _ in sent} == {"events"}
    new, update = sent[0][1], sent[1][1]
    assert new["before"] == new["after"] and new["after"]["id"] == "front-run-4"
    assert update["before"] == new["after"] and update["after"]["frame_time"] == 101.0
    end = sent[5][1]
    assert end["after"]["end_time"] == end["time_s"] and end["time_s"] - end["before"]["frame_time"] > 2.0


def test_events_over_mqtt_equal_the_events_written(tmp_path):
    lines = tmp_path / "events.jsonl"
    with mosquitto(tmp_path) as port:
        subscriber = Subscriber(port, ["ptztrack/+/events", "ptztrack/+/status"])
        try:
            with EventOutlet(str(lines), MQTTSection(port=port)) as outlet:
                for camera in ("front", "back"):
                    events = TrackEvents(camera, "run", 5.0, 1.0, outlet.emitter(camera))
                    for step in range(50):
                        events.step(0.1 * step, _tracks(range(step // 10, step // 10 + 3)))
                    events.end_all(5.0)
                outlet.emitter("front")("status", {"type": "offline", "camera": "front"})
            # Leaving the outlet waited for the broker's acknowledgements.
            assert outlet.acknowledged == outlet.written
            received = subscriber.count_settles()
        finally:
            subscriber.close()
    written = [json.loads(line) for line in lines.read_text().splitlines()]
    assert len(written) == outlet.written > 100 and received == len(written)
    # The same payloads on the same topics, in order per camera.
    for topic in ("ptztrack/front/events", "ptztrack/back/events", "ptztrack/front/status"):
        sent = [{key: value for key, value in line.items() if key != "topic"} for line in written]
        mine = [payload for payload, line in zip(sent, written, strict=True) if line["topic"] == topic]
        got = [json.loads(payload) for message_topic, payload in subscriber.messages if message_topic == topic]
        assert got == mine and got
