"""The live loop driving a camera over ONVIF: ptztrack's virtual ONVIF camera, served on 127.0.0.1, for a
few pictures.

    python examples/virtual_camera_live.py [--pictures 8] [--policy smpl]

``ptztrack serve-camera --port 0`` runs in a process of its own, as a camera is a machine of its own: a PTZ
camera inside the PETS 2009 recording, speaking ONVIF with an RTSP stream (it needs ipycam: ``pip install
--no-deps ipycam==1.3.0``, and FFmpeg). :func:`ptztrack.run_live_episode` connects to it, runs the PETS
scenario's HOG detector and tracker on its pictures as they come and sends it where the policy decides,
as it would a real camera; the camera is stopped by Ctrl-C (SIGINT) at the end. It prints each picture's
pose and tracks, and the run's pace.
"""

import argparse
import re
import signal
import subprocess
import sys

import ptztrack
from ptztrack.builders.virtual_camera import virtual_calibration
from ptztrack.camera.onvif_client import camera_address


def serve_camera() -> tuple[subprocess.Popen, str]:
    """``ptztrack serve-camera`` on any free port of 127.0.0.1, and its onvif:// address once it plays."""
    command = [sys.executable, "-m", "ptztrack.cli", "serve-camera", "--port", "0"]
    # A script started in the background by a non-interactive shell inherits SIGINT ignored: the camera
    # gets a terminal's disposition, so that the Ctrl-C (SIGINT) at the end stops it.
    camera = subprocess.Popen(
        command, stdout=subprocess.PIPE, text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)
    )
    address = ""
    for line in camera.stdout:
        address = address or next(iter(re.findall(r"onvif://127\.0\.0\.1:\d+", line)), "")
        if line.startswith("the recording plays"):
            return camera, address
    raise SystemExit(f"serve-camera ended with status {camera.wait()} before its camera was up")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pictures", type=int, default=8)
    parser.add_argument("--policy", default="smpl")
    args = parser.parse_args()

    scenario = ptztrack.pets_scenario("hog")
    camera, address = serve_camera()
    print(f"virtual camera at {address}")
    try:
        _, (live,) = ptztrack.run_live_episode(
            scenario, [virtual_calibration()], [camera_address(address)], args.policy, args.pictures,
            time_scale=1.0, seed=0,
        )  # fmt: skip
    finally:
        camera.send_signal(signal.SIGINT)
        try:
            camera.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            camera.kill()  # a camera that does not stop is not left running
            raise
    for picture, (pose, tracks) in enumerate(zip(live.poses, live.tracks, strict=True)):
        pan_deg, tilt_deg, zoom = pose
        print(f"picture {picture:2d}: pan {pan_deg:6.1f} deg, tilt {tilt_deg:5.1f} deg, zoom {zoom:4.2f}, "
              f"{len(tracks)} tracks")  # fmt: skip
    rates = live.rates()
    print(f"{len(live.capture_time_s)} pictures used of {live.frames_received} received, "
          f"{rates['frames_used_per_s']:.1f} a second")  # fmt: skip


if __name__ == "__main__":
    main()
