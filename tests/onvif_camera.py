"""The virtual ONVIF camera of the conformance and client tests: its settings, its images and an
onvif-zeep-async session with it."""

import asyncio
import os

import cv2
import numpy as np
import pytest

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
onvif = pytest.importorskip("onvif", reason="the ONVIF client is onvif-zeep-async (pip install onvif-zeep-async)")

from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces  # noqa: E402
from ptztrack.virtual_onvif.server import VirtualONVIFCamera  # noqa: E402

HOST = "127.0.0.1"
USER, PASSWORD = "operator", "s3cret-pass"
# ONVIF's tilt: normalised +1 looks up, 10 degrees above the horizon (a depression of -10).
SPACES = CameraSpaces(pan_deg=(-170.0, 170.0), tilt_deg=(80.0, -10.0), zoom_curve=((0.0, 1.0), (1.0, 8.0)))
FAST = AxisSpeeds(pan_deg_s=340.0, tilt_deg_s=180.0, zoom_per_s=14.0)
START_POSE = (0.0, 20.0, 1.0)
WIDTH_PX, HEIGHT_PX, F_MIN_PX = 320, 240, 300.0
WSDL = os.path.join(os.path.dirname(onvif.__file__), "wsdl")
SOAP = "http://www.w3.org/2003/05/soap-envelope"
ERRORS = "http://www.onvif.org/ver10/error"


def render(pose, elapsed_s: float) -> np.ndarray:
    """A 320 x 240 image: a horizontal gradient and a disc where the pose points within the pan and tilt ranges."""
    image = np.zeros((HEIGHT_PX, WIDTH_PX, 3), np.uint8)
    image[:, :, 1] = np.linspace(0, 255, WIDTH_PX, dtype=np.uint8)
    x = int((pose[0] + 170.0) / 340.0 * (WIDTH_PX - 1))
    y = int((80.0 - pose[1]) / 90.0 * (HEIGHT_PX - 1))
    cv2.circle(image, (x, y), 20, (0, 0, 255), -1)
    return image


def camera(**options) -> VirtualONVIFCamera:
    """The camera (not started) with credentials and the focal length, unless ``options`` say otherwise."""
    options = {"username": USER, "password": PASSWORD, "f_min_px": F_MIN_PX, **options}
    return VirtualONVIFCamera(render, SPACES, FAST, START_POSE, (WIDTH_PX, HEIGHT_PX), **options)


def call(port: int, operation, password: str = PASSWORD):
    """``await operation(client, profile_token)`` with onvif-zeep-async connected to the camera as USER with
    ``password``, closed after."""

    async def run():
        client = onvif.ONVIFCamera(HOST, port, USER, password, WSDL, no_cache=True)
        try:
            await client.update_xaddrs()
            media = await client.create_media_service()
            return await operation(client, (await media.GetProfiles())[0].token)
        finally:
            await client.close()

    return asyncio.run(run())
