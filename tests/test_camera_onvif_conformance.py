"""The virtual ONVIF camera against the standards other ONVIF tools expect: every answer valid against
the ONVIF schemas that onvif-zeep-async ships, SOAP 1.2 faults with their HTTP status, WS-Security
replay protection, HTTP Digest, RelativeMove in the FOV translation space, RTSP over UDP and TCP,
quiet disconnects, and a session of an ONVIF client that ptztrack does not use (onveef)."""

import asyncio
import base64
import hashlib
import http.client
import logging
import os
import re
import secrets
import socket
import struct
import subprocess
import sys
import threading
import time
from datetime import UTC, datetime, timedelta

import cv2
import numpy as np
import pytest

pytest.importorskip("ipycam", reason="the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
onvif = pytest.importorskip("onvif", reason="the ONVIF client is onvif-zeep-async (pip install onvif-zeep-async)")
onveef = pytest.importorskip("onveef", reason="the outside ONVIF client is onveef (pip install '.[test]')")

import zeep.exceptions  # noqa: E402  (onvif-zeep-async's SOAP library)
from lxml import etree  # noqa: E402  (zeep's XML library)

from ptztrack.camera.onvif_http import HTTPAuth, Verdict  # noqa: E402
from ptztrack.camera.onvif_media import DeviceMediaService, MediaSettings  # noqa: E402
from ptztrack.camera.onvif_ptz import PAN_TILT_FOV, PTZService  # noqa: E402
from ptztrack.camera.onvif_server import VirtualONVIFCamera  # noqa: E402
from ptztrack.camera.onvif_soap import Fault, UsernameTokens  # noqa: E402
from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces  # noqa: E402
from ptztrack.geometry.ptz import rotation_world_to_camera  # noqa: E402

pytestmark = pytest.mark.onvif

HOST = "127.0.0.1"
USER, PASSWORD = "operator", "s3cret-pass"
SPACES = CameraSpaces(pan_deg=(-170.0, 170.0), tilt_deg=(-10.0, 80.0), zoom_curve=((0.0, 1.0), (1.0, 8.0)))
FAST = AxisSpeeds(pan_deg_s=340.0, tilt_deg_s=180.0, zoom_per_s=14.0)
START_POSE = (0.0, 20.0, 1.0)
WIDTH_PX, HEIGHT_PX, F_MIN_PX = 320, 240, 300.0
WSDL = os.path.join(os.path.dirname(onvif.__file__), "wsdl")
XS = "http://www.w3.org/2001/XMLSchema"
SOAP = "http://www.w3.org/2003/05/soap-envelope"
ERRORS = "http://www.onvif.org/ver10/error"
WSSE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-secext-1.0.xsd"
WSU = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-utility-1.0.xsd"
TOKEN_PROFILE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-username-token-profile-1.0"
NAMESPACES = {
    "tds": "http://www.onvif.org/ver10/device/wsdl",
    "trt": "http://www.onvif.org/ver10/media/wsdl",
    "tptz": "http://www.onvif.org/ver20/ptz/wsdl",
    "tt": "http://www.onvif.org/ver10/schema",
}


def render(pose, elapsed_s: float) -> np.ndarray:
    """A 320 x 240 image: a horizontal gradient, a disc where the pose points, the pose in text."""
    image = np.zeros((HEIGHT_PX, WIDTH_PX, 3), np.uint8)
    image[:, :, 1] = np.linspace(0, 255, WIDTH_PX, dtype=np.uint8)
    x = int((pose[0] + 170.0) / 340.0 * (WIDTH_PX - 1))
    y = int((80.0 - pose[1]) / 90.0 * (HEIGHT_PX - 1))
    cv2.circle(image, (x, y), 20, (0, 0, 255), -1)
    return image


def camera(**options) -> VirtualONVIFCamera:
    options = {"username": USER, "password": PASSWORD, "f_min_px": F_MIN_PX, **options}
    return VirtualONVIFCamera(render, SPACES, FAST, START_POSE, (WIDTH_PX, HEIGHT_PX), **options)


# The schemas: onvif.xsd and the request/response elements embedded in the services' WSDLs.


class _Embedded(etree.Resolver):
    """Serves the WSDLs' embedded schemas under made-up URLs; anything else resolves as usual (files
    next to the WSDLs; the parser has no network)."""

    def __init__(self, documents: dict[str, bytes]):
        super().__init__()
        self.documents = documents

    def resolve(self, url, pubid, context):
        return self.resolve_string(self.documents[url], context) if url in self.documents else None


@pytest.fixture(scope="module")
def schema() -> etree.XMLSchema:
    """One schema of every element of devicemgmt.wsdl, media.wsdl and ptz.wsdl and of onvif.xsd, which
    they import (and it xmlmime, include, envelope and the WS-Notification files, all local)."""
    documents, imports = {}, []
    for service in ("devicemgmt", "media", "ptz"):
        embedded = etree.parse(os.path.join(WSDL, f"{service}.wsdl")).find(f".//{{{XS}}}schema")
        for imported in embedded.iter(f"{{{XS}}}import"):  # relative to the WSDL, which the copy leaves
            imported.set("schemaLocation", "file://" + os.path.join(WSDL, imported.get("schemaLocation")))
        url = f"embedded:{service}.xsd"
        documents[url] = etree.tostring(embedded)
        imports.append(f'<xs:import namespace="{embedded.get("targetNamespace")}" schemaLocation="{url}"/>')
    parser = etree.XMLParser(no_network=True)
    parser.resolvers.add(_Embedded(documents))
    wrapper = f'<xs:schema xmlns:xs="{XS}" targetNamespace="urn:ptztrack:tests">{"".join(imports)}</xs:schema>'
    return etree.XMLSchema(etree.fromstring(wrapper, parser))


# Raw SOAP: the test's own requests, signed here.


def security_header(nonce: bytes | None = None, created: datetime | None = None, password: str = PASSWORD) -> str:
    """A WS-Security UsernameToken with PasswordDigest = Base64(SHA-1(nonce + Created + password))."""
    nonce = secrets.token_bytes(16) if nonce is None else nonce
    created_text = (created or datetime.now(UTC)).strftime("%Y-%m-%dT%H:%M:%SZ")
    digest = base64.b64encode(hashlib.sha1(nonce + created_text.encode() + password.encode()).digest()).decode()
    return (
        f'<s:Header><wsse:Security xmlns:wsse="{WSSE}" xmlns:wsu="{WSU}"><wsse:UsernameToken>'
        f"<wsse:Username>{USER}</wsse:Username>"
        f'<wsse:Password Type="{TOKEN_PROFILE}#PasswordDigest">{digest}</wsse:Password>'
        f"<wsse:Nonce>{base64.b64encode(nonce).decode()}</wsse:Nonce><wsu:Created>{created_text}</wsu:Created>"
        "</wsse:UsernameToken></wsse:Security></s:Header>"
    )


def post(port: int, data: bytes) -> tuple[int, etree._Element]:
    connection = http.client.HTTPConnection(HOST, port, timeout=5)
    try:
        connection.request("POST", "/onvif/device_service", data, {"Content-Type": "application/soap+xml"})
        response = connection.getresponse()
        return response.status, etree.fromstring(response.read())
    finally:
        connection.close()


def soap(port: int, body: str, header: str | None = None) -> tuple[int, etree._Element]:
    """(HTTP status, the Body's child) of the request ``body`` (prefixes tds, trt, tptz, tt), signed."""
    declarations = " ".join(f'xmlns:{prefix}="{uri}"' for prefix, uri in NAMESPACES.items())
    header = security_header() if header is None else header
    status, root = post(
        port, f'<s:Envelope xmlns:s="{SOAP}" {declarations}>{header}<s:Body>{body}</s:Body></s:Envelope>'.encode()
    )
    return status, root.find(f"{{{SOAP}}}Body")[0]


def assert_soap_1_2_fault(fault: etree._Element, code: str, subcodes: list[str]) -> None:
    """A SOAP 1.2 fault (Part 1, 5.4): Code (Value, nested Subcodes), then Reason with xml:lang Texts,
    and nothing else; the codes are QNames in scope, here the given code and ONVIF subcodes."""
    assert fault.tag == f"{{{SOAP}}}Fault"
    children = [child.tag for child in fault]
    assert children[:2] == [f"{{{SOAP}}}Code", f"{{{SOAP}}}Reason"], children
    assert set(children[2:]) <= {f"{{{SOAP}}}{name}" for name in ("Node", "Role", "Detail")}

    def qname(value: etree._Element) -> str:
        prefix, _, local = value.text.strip().rpartition(":")
        return f"{{{value.nsmap[prefix or None]}}}{local}"

    level, codes = fault.find(f"{{{SOAP}}}Code"), []
    while level is not None:
        assert level[0].tag == f"{{{SOAP}}}Value"
        codes.append(qname(level[0]))
        level = level.find(f"{{{SOAP}}}Subcode")
    assert codes == [f"{{{SOAP}}}{code}", *(f"{{{ERRORS}}}{subcode}" for subcode in subcodes)], codes
    texts = fault.find(f"{{{SOAP}}}Reason")
    assert len(texts) >= 1 and all(
        text.tag == f"{{{SOAP}}}Text" and text.get("{http://www.w3.org/XML/1998/namespace}lang") and text.text
        for text in texts
    )


PROFILE = "<{0}:ProfileToken>Profile_Main</{0}:ProfileToken>"
# A request for every operation of the camera, valid against the schemas too (checked below).
REQUESTS = {
    ("tds", "GetSystemDateAndTime"): "<tds:GetSystemDateAndTime/>",
    ("tds", "GetDeviceInformation"): "<tds:GetDeviceInformation/>",
    ("tds", "GetCapabilities"): "<tds:GetCapabilities><tds:Category>All</tds:Category></tds:GetCapabilities>",
    ("tds", "GetServices"): "<tds:GetServices><tds:IncludeCapability>true</tds:IncludeCapability></tds:GetServices>",
    ("tds", "GetServiceCapabilities"): "<tds:GetServiceCapabilities/>",
    ("tds", "GetScopes"): "<tds:GetScopes/>",
    ("trt", "GetServiceCapabilities"): "<trt:GetServiceCapabilities/>",
    ("trt", "GetProfiles"): "<trt:GetProfiles/>",
    ("trt", "GetProfile"): f"<trt:GetProfile>{PROFILE.format('trt')}</trt:GetProfile>",
    ("trt", "GetVideoSources"): "<trt:GetVideoSources/>",
    ("trt", "GetVideoSourceConfigurations"): "<trt:GetVideoSourceConfigurations/>",
    ("trt", "GetVideoSourceConfiguration"): "<trt:GetVideoSourceConfiguration>"
    "<trt:ConfigurationToken>VSC_1</trt:ConfigurationToken></trt:GetVideoSourceConfiguration>",
    ("trt", "GetCompatibleVideoSourceConfigurations"): "<trt:GetCompatibleVideoSourceConfigurations>"
    f"{PROFILE.format('trt')}</trt:GetCompatibleVideoSourceConfigurations>",
    ("trt", "GetVideoEncoderConfigurations"): "<trt:GetVideoEncoderConfigurations/>",
    ("trt", "GetVideoEncoderConfiguration"): "<trt:GetVideoEncoderConfiguration>"
    "<trt:ConfigurationToken>VEC_1</trt:ConfigurationToken></trt:GetVideoEncoderConfiguration>",
    ("trt", "GetCompatibleVideoEncoderConfigurations"): "<trt:GetCompatibleVideoEncoderConfigurations>"
    f"{PROFILE.format('trt')}</trt:GetCompatibleVideoEncoderConfigurations>",
    ("trt", "GetStreamUri"): "<trt:GetStreamUri><trt:StreamSetup><tt:Stream>RTP-Unicast</tt:Stream>"
    f"<tt:Transport><tt:Protocol>UDP</tt:Protocol></tt:Transport></trt:StreamSetup>{PROFILE.format('trt')}"
    "</trt:GetStreamUri>",
    ("trt", "GetSnapshotUri"): f"<trt:GetSnapshotUri>{PROFILE.format('trt')}</trt:GetSnapshotUri>",
    ("tptz", "GetServiceCapabilities"): "<tptz:GetServiceCapabilities/>",
    ("tptz", "GetNodes"): "<tptz:GetNodes/>",
    ("tptz", "GetNode"): "<tptz:GetNode><tptz:NodeToken>PTZ_Node_1</tptz:NodeToken></tptz:GetNode>",
    ("tptz", "GetConfigurations"): "<tptz:GetConfigurations/>",
    ("tptz", "GetConfiguration"): "<tptz:GetConfiguration>"
    "<tptz:PTZConfigurationToken>PTZ_Config_1</tptz:PTZConfigurationToken></tptz:GetConfiguration>",
    ("tptz", "GetConfigurationOptions"): "<tptz:GetConfigurationOptions>"
    "<tptz:ConfigurationToken>PTZ_Config_1</tptz:ConfigurationToken></tptz:GetConfigurationOptions>",
    ("tptz", "GetCompatibleConfigurations"): "<tptz:GetCompatibleConfigurations>"
    f"{PROFILE.format('tptz')}</tptz:GetCompatibleConfigurations>",
    ("tptz", "GetStatus"): f"<tptz:GetStatus>{PROFILE.format('tptz')}</tptz:GetStatus>",
    ("tptz", "AbsoluteMove"): f"<tptz:AbsoluteMove>{PROFILE.format('tptz')}<tptz:Position>"
    '<tt:PanTilt x="0.1" y="0.2"/><tt:Zoom x="0.1"/></tptz:Position></tptz:AbsoluteMove>',
    ("tptz", "RelativeMove"): f"<tptz:RelativeMove>{PROFILE.format('tptz')}<tptz:Translation>"
    f'<tt:PanTilt x="0.2" y="-0.1" space="{PAN_TILT_FOV}"/></tptz:Translation>'
    '<tptz:Speed><tt:PanTilt x="1" y="1"/></tptz:Speed></tptz:RelativeMove>',
    ("tptz", "ContinuousMove"): f"<tptz:ContinuousMove>{PROFILE.format('tptz')}<tptz:Velocity>"
    '<tt:PanTilt x="0.1" y="0"/></tptz:Velocity><tptz:Timeout>PT0.1S</tptz:Timeout></tptz:ContinuousMove>',
    ("tptz", "Stop"): f"<tptz:Stop>{PROFILE.format('tptz')}<tptz:PanTilt>true</tptz:PanTilt></tptz:Stop>",
    ("tptz", "GotoHomePosition"): f"<tptz:GotoHomePosition>{PROFILE.format('tptz')}</tptz:GotoHomePosition>",
    ("tptz", "SetPreset"): f"<tptz:SetPreset>{PROFILE.format('tptz')}<tptz:PresetName>door</tptz:PresetName>"
    "</tptz:SetPreset>",
    ("tptz", "GetPresets"): f"<tptz:GetPresets>{PROFILE.format('tptz')}</tptz:GetPresets>",
    ("tptz", "GotoPreset"): f"<tptz:GotoPreset>{PROFILE.format('tptz')}<tptz:PresetToken>1</tptz:PresetToken>"
    "</tptz:GotoPreset>",
    ("tptz", "RemovePreset"): f"<tptz:RemovePreset>{PROFILE.format('tptz')}<tptz:PresetToken>1</tptz:PresetToken>"
    "</tptz:RemovePreset>",
}


def test_every_operation_answers_schema_valid_xml_and_faults_are_soap_1_2_with_their_http_status(schema):
    """Each operation in the camera's dispatch tables, sent in the order above (the preset is set before
    it is used), is answered 200 with its response element, valid against the ONVIF schemas; refusals
    are SOAP 1.2 faults with ONVIF subcodes, 400 for env:Sender and 500 for env:Receiver."""
    settings = MediaSettings("x", "http://x", 1, 1, 1, 1, "http://x", "rtsp://x")
    ptz = PTZService(None, SPACES, np.zeros(3), (WIDTH_PX, HEIGHT_PX), F_MIN_PX)
    supported = set(DeviceMediaService(settings).operations()) | set(ptz.operations())
    assert {(NAMESPACES[prefix], name) for prefix, name in REQUESTS} == supported
    with camera() as cam:
        for (prefix, name), body in REQUESTS.items():
            request = etree.fromstring(f"<e {' '.join(f'xmlns:{p}={u!r}' for p, u in NAMESPACES.items())}>{body}</e>")
            assert schema.validate(request[0]), (name, "the test's request", str(schema.error_log))
            status, answer = soap(cam.onvif_port, body)
            assert (status, answer.tag) == (200, f"{{{NAMESPACES[prefix]}}}{name}Response"), (name, status)
            assert schema.validate(answer), (name, str(schema.error_log))
        # (request, its header (None: a valid token), HTTP status, code, subcodes, what the reason names)
        refusals = [
            (
                f"<tptz:GetStatus>{PROFILE.format('tptz').replace('Profile_Main', 'nope')}</tptz:GetStatus>",
                None,
                400,
                "Sender",
                ["InvalidArgVal", "NoProfile"],
                "ProfileToken 'nope'",
            ),
            ("<tptz:GetStatus/>", None, 400, "Sender", ["InvalidArgVal", "NoProfile"], "ProfileToken is missing"),
            (
                f'<tptz:AbsoluteMove>{PROFILE.format("tptz")}<tptz:Position><tt:PanTilt x="1.5" y="0"/></tptz:Position>'
                "</tptz:AbsoluteMove>",
                None,
                400,
                "Sender",
                ["InvalidArgVal", "InvalidPosition"],
                "Position 1.5",
            ),
            (
                f'<tptz:RelativeMove>{PROFILE.format("tptz")}<tptz:Translation><tt:PanTilt x="0" y="0" space="urn:x"/>'
                "</tptz:Translation></tptz:RelativeMove>",
                None,
                400,
                "Sender",
                ["InvalidArgVal", "SpaceNotSupported"],
                "Translation.PanTilt space 'urn:x'",
            ),
            (
                f"<tptz:RelativeMove>{PROFILE.format('tptz')}</tptz:RelativeMove>",
                None,
                400,
                "Sender",
                ["InvalidArgs"],
                "Translation is missing",
            ),
            (
                "<tds:GetCapabilities><tds:Category>Events</tds:Category></tds:GetCapabilities>",
                None,
                500,
                "Receiver",
                ["ActionNotSupported", "NoSuchService"],
                "Category ['Events']",
            ),
            ("<tds:SystemReboot/>", None, 500, "Receiver", ["ActionNotSupported"], "SystemReboot"),
            ("<trt:GetProfiles/>", "", 400, "Sender", ["NotAuthorized"], "UsernameToken"),
            ("<trt:GetProfiles/>", security_header(password="wrong"), 400, "Sender", ["NotAuthorized"], "digest"),
        ]
        for body, header, status, code, subcodes, named in refusals:
            answered, fault = soap(cam.onvif_port, body, header)
            assert answered == status, (body, answered)
            assert_soap_1_2_fault(fault, code, subcodes)
            assert named in fault.findtext(f".//{{{SOAP}}}Text"), (named, fault.findtext(f".//{{{SOAP}}}Text"))
        status, root = post(cam.onvif_port, b"<s:Envelope xmlns:s='" + SOAP.encode() + b"'><s:Body><oops")
        assert status == 400
        assert_soap_1_2_fault(root.find(f"{{{SOAP}}}Body")[0], "Sender", ["WellFormed"])
        soap_1_1 = b'<e:Envelope xmlns:e="http://schemas.xmlsoap.org/soap/envelope/"><e:Body/></e:Envelope>'
        status, root = post(cam.onvif_port, soap_1_1)
        assert status == 500
        assert_soap_1_2_fault(root.find(f"{{{SOAP}}}Body")[0], "VersionMismatch", [])


def test_a_replayed_or_stale_usernametoken_is_refused_and_the_nonce_store_forgets_past_the_window():
    """A token accepted once is refused when sent again (ter:NotAuthorized, HTTP 400); a Created 6 min
    before or after the camera's clock is refused, one 4 min off accepted; the store of nonces holds
    those whose Created is within the window, and no more."""
    body = "<trt:GetProfiles/>"
    with camera() as cam:
        token = security_header()
        assert soap(cam.onvif_port, body, token)[0] == 200
        status, fault = soap(cam.onvif_port, body, token)
        assert status == 400 and "already used" in fault.findtext(f".//{{{SOAP}}}Text")
        assert_soap_1_2_fault(fault, "Sender", ["NotAuthorized"])
        now = datetime.now(UTC)
        for minutes, accepted in ((-6, False), (6, False), (-4, True), (4, True)):
            status, answer = soap(cam.onvif_port, body, security_header(created=now + timedelta(minutes=minutes)))
            assert (status == 200) == accepted, (minutes, status)
            if not accepted:
                assert_soap_1_2_fault(answer, "Sender", ["NotAuthorized"])
                assert "wsu:Created" in answer.findtext(f".//{{{SOAP}}}Text")

    clock_s = [1_000_000.0]
    tokens = UsernameTokens(USER, PASSWORD, window_s=300.0, clock=lambda: clock_s[0])

    def header(nonce: bytes, created_s: float) -> etree._Element:
        created = datetime.fromtimestamp(created_s, UTC)
        text = f'<s:Envelope xmlns:s="{SOAP}">{security_header(nonce, created)}</s:Envelope>'
        return etree.fromstring(text)[0]

    for second in range(100):
        tokens.verify(header(struct.pack(">I", second), clock_s[0] - 250.0 + second))
    assert len(tokens) == 100
    clock_s[0] += 100.0  # the first 50 tokens' Created are now more than 300 s old
    assert len(tokens) == 50
    with pytest.raises(Fault, match="already used"):
        tokens.verify(header(struct.pack(">I", 99), clock_s[0] - 251.0))
    clock_s[0] += 300.0
    assert len(tokens) == 0


def digest_authorization(challenge: str, method: str, uri: str, password: str = PASSWORD) -> str:
    """The test's own RFC 7616 answer (qop=auth) to a Digest challenge."""
    params = dict(re.findall(r'(\w+)="?([^",]*)"?', challenge.partition(" ")[2]))
    algorithm = params["algorithm"]
    digest = {"MD5": hashlib.md5, "SHA-256": hashlib.sha256}[algorithm]

    def h(text: str) -> str:
        return digest(text.encode()).hexdigest()

    cnonce, nc = secrets.token_hex(8), "00000001"
    ha1, ha2 = h(f"{USER}:{params['realm']}:{password}"), h(f"{method}:{uri}")
    response = h(f"{ha1}:{params['nonce']}:{nc}:{cnonce}:auth:{ha2}")
    return (
        f'Digest username="{USER}", realm="{params["realm"]}", nonce="{params["nonce"]}", uri="{uri}", '
        f'algorithm={algorithm}, qop=auth, nc={nc}, cnonce="{cnonce}", response="{response}"'
    )


def get(port: int, path: str, authorization: str | None = None) -> http.client.HTTPResponse:
    connection = http.client.HTTPConnection(HOST, port, timeout=5)
    connection.request("GET", path, headers={} if authorization is None else {"Authorization": authorization})
    return connection.getresponse()


def test_snapshots_and_mjpeg_take_http_digest_md5_and_sha256_and_basic():
    """Unauthenticated, the snapshot is refused with Digest SHA-256, Digest MD5 and Basic challenges in
    that order; an answer to either Digest challenge, and Basic, get the image, a wrong password does
    not; MJPEG takes Digest too; onvif-zeep-async's get_snapshot (Digest by default) gets the image."""
    with camera() as cam:
        refused = get(cam.onvif_port, "/snapshot.jpg")
        challenges = refused.headers.get_all("WWW-Authenticate")
        assert refused.status == 401 and [c.split(",")[0].split()[0] for c in challenges] == [
            "Digest",
            "Digest",
            "Basic",
        ]
        assert ["algorithm=SHA-256" in challenges[0], "algorithm=MD5" in challenges[1]] == [True, True]
        for challenge in challenges[:2]:
            answer = get(cam.onvif_port, "/snapshot.jpg", digest_authorization(challenge, "GET", "/snapshot.jpg"))
            image = cv2.imdecode(np.frombuffer(answer.read(), np.uint8), cv2.IMREAD_COLOR)
            assert answer.status == 200 and image.shape == (HEIGHT_PX, WIDTH_PX, 3)
            wrong = digest_authorization(challenge, "GET", "/snapshot.jpg", password="wrong")
            assert get(cam.onvif_port, "/snapshot.jpg", wrong).status == 401
            elsewhere = digest_authorization(challenge, "GET", "/stream.mjpeg")  # answered for another URI
            assert get(cam.onvif_port, "/snapshot.jpg", elsewhere).status == 401
        basic = "Basic " + base64.b64encode(f"{USER}:{PASSWORD}".encode()).decode()
        assert get(cam.onvif_port, "/snapshot.jpg", basic).status == 200
        mjpeg = get(cam.onvif_port, "/stream.mjpeg", digest_authorization(challenges[0], "GET", "/stream.mjpeg"))
        assert mjpeg.status == 200 and b"--frame" in mjpeg.read1(4096)
        mjpeg.close()

        async def snapshot() -> bytes:
            client = onvif.ONVIFCamera(HOST, cam.onvif_port, USER, PASSWORD, WSDL, no_cache=True)
            try:
                await client.update_xaddrs()
                media = await client.create_media_service()
                token = (await media.GetProfiles())[0].token
                return await client.get_snapshot(token, basic_auth=False)
            finally:
                await client.close()

        jpeg = asyncio.run(snapshot())
    image = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR)
    assert np.abs(image.astype(float) - render(np.array(START_POSE), 0.0)).mean() < 10.0


def test_digest_nonces_expire_into_a_stale_challenge():
    """A right answer to a nonce older than its lifetime is STALE (the client retries with the new
    challenge, which says stale=true); a nonce the camera did not issue is refused."""
    clock_s = [5000.0]
    auth = HTTPAuth(USER, PASSWORD, realm="cam", nonce_lifetime_s=60.0, clock=lambda: clock_s[0])
    challenge = auth.challenges()[0]
    answer = digest_authorization(challenge, "GET", "/snapshot.jpg")
    assert auth.check("GET", "/snapshot.jpg", answer) is Verdict.ACCEPTED
    clock_s[0] += 61.0
    assert auth.check("GET", "/snapshot.jpg", answer) is Verdict.STALE
    assert "stale=true" in auth.challenges(stale=True)[0]
    forged = re.sub(r'nonce="[^"]*"', 'nonce="5061.00ff"', challenge)
    assert auth.check("GET", "/snapshot.jpg", digest_authorization(forged, "GET", "/snapshot.jpg")) is Verdict.REFUSED


def call(port: int, operation):
    """``await operation(client, profile_token)`` with onvif-zeep-async connected to the camera."""

    async def run():
        client = onvif.ONVIFCamera(HOST, port, USER, PASSWORD, WSDL, no_cache=True)
        try:
            await client.update_xaddrs()
            media = await client.create_media_service()
            return await operation(client, (await media.GetProfiles())[0].token)
        finally:
            await client.close()

    return asyncio.run(run())


def test_video_sources_and_compatible_ptz_configurations_are_answered():
    async def read(client, token: str):
        media, ptz = await client.create_media_service(), await client.create_ptz_service()
        return await media.GetVideoSources(), await ptz.GetCompatibleConfigurations({"ProfileToken": token})

    with camera(frame_rate_hz=12.0) as cam:
        sources, configurations = call(cam.onvif_port, read)
    assert [(s.token, s.Framerate, s.Resolution.Width, s.Resolution.Height) for s in sources] == [
        ("VS_1", 12.0, WIDTH_PX, HEIGHT_PX)
    ]
    assert [(c.token, c.NodeToken) for c in configurations] == [("PTZ_Config_1", "PTZ_Node_1")]


def test_a_fov_relative_move_centres_the_point_seen_there_within_the_limits():
    """The node offers TranslationSpaceFov; RelativeMove by FOV (x, y) brings the scene point seen at pixel
    (W/2 + x W/2, H/2 - y H/2) to the image centre, exactly on the model, at zoom 1 and zoomed in (a
    corner, then); at the pan limit the head stops there. Without a focal length the space is neither
    offered nor taken."""
    cx, cy = WIDTH_PX / 2.0, HEIGHT_PX / 2.0

    async def moves(client, token: str):
        ptz, profile = await client.create_ptz_service(), {"ProfileToken": token}
        nodes = await ptz.GetNodes()
        options = await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})
        offered = [
            [space.URI for space in spaces.RelativePanTiltTranslationSpace]
            for spaces in (nodes[0].SupportedPTZSpaces, options.Spaces)
        ]

        async def idle_pose():
            while (
                status := await ptz.GetStatus(profile)
            ).MoveStatus.PanTilt != "IDLE" or status.MoveStatus.Zoom != "IDLE":
                await asyncio.sleep(0.02)
            await asyncio.sleep(0.25)  # an image rendered at the pose reached
            return cam.truth()[1][-1]

        seen = []
        for start, fov in (
            ((0.0, -1 / 3, 0.0), (0.5, -0.4)),
            ((0.1, 0.2, 0.5), (1.0, 1.0)),
            ((0.97, 0.0, 0.0), (1.0, 0.0)),
        ):
            position = {"PanTilt": {"x": start[0], "y": start[1]}, "Zoom": {"x": start[2]}}
            await ptz.AbsoluteMove({**profile, "Position": position})
            before = await idle_pose()
            translation = {"PanTilt": {"x": fov[0], "y": fov[1], "space": PAN_TILT_FOV}}
            await ptz.RelativeMove({**profile, "Translation": translation})
            seen.append((fov, before, await idle_pose()))
        return offered, seen

    with camera() as cam:
        offered, seen = call(cam.onvif_port, moves)
    assert offered == [[PAN_TILT_FOV.replace("TranslationSpaceFov", "TranslationGenericSpace"), PAN_TILT_FOV]] * 2
    for fov, before, after in seen[:2]:
        pixel = np.array([cx + fov[0] * cx, cy - fov[1] * cy])
        ray = np.array([(pixel[0] - cx) / (before[2] * F_MIN_PX), (pixel[1] - cy) / (before[2] * F_MIN_PX), 1.0])
        seen_after = (
            rotation_world_to_camera(after[0], after[1]) @ rotation_world_to_camera(before[0], before[1]).T @ ray
        )
        centred = after[2] * F_MIN_PX * seen_after[:2] / seen_after[2] + [cx, cy]
        assert np.allclose(centred, [cx, cy], atol=1e-6), (fov, before, after, centred)
        assert after[2] == before[2] and not np.allclose(after[:2], before[:2])
    # Zoomed in 4.5 times, the corner is 4.5 times nearer the centre than at zoom 1: a smaller turn.
    assert seen[1][1][2] == pytest.approx(4.5)
    assert abs(seen[1][2][0] - seen[1][1][0]) < 2 * np.degrees(np.arctan(cx / (4.5 * F_MIN_PX)))
    # At the pan limit: the pan stops there, the tilt is the one that centres the point's ray (depression).
    fov, before, after = seen[2]
    ray = rotation_world_to_camera(before[0], before[1]).T @ [fov[0] * cx / F_MIN_PX, 0.0, 1.0]
    assert before[0] < 170.0 and after[0] == 170.0
    assert after[1] == pytest.approx(np.degrees(np.arcsin(-ray[2] / np.linalg.norm(ray))), abs=1e-9)

    async def refused(client, token: str):
        ptz = await client.create_ptz_service()
        options = await ptz.GetConfigurationOptions({"ConfigurationToken": "PTZ_Config_1"})
        translation = {"PanTilt": {"x": 0.5, "y": 0.0, "space": PAN_TILT_FOV}}
        with pytest.raises(zeep.exceptions.Fault) as fault:
            await ptz.RelativeMove({"ProfileToken": token, "Translation": translation})
        return [space.URI for space in options.Spaces.RelativePanTiltTranslationSpace], fault.value

    with camera(f_min_px=None) as cam:
        spaces, fault = call(cam.onvif_port, refused)
    assert PAN_TILT_FOV not in spaces
    assert [subcode.text for subcode in fault.subcodes][-1] == f"{{{ERRORS}}}SpaceNotSupported"
    assert "Translation.PanTilt space" in fault.message


READER = """
import sys, cv2
timeouts = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, 8000, cv2.CAP_PROP_READ_TIMEOUT_MSEC, 8000]
capture = cv2.VideoCapture(sys.argv[1], cv2.CAP_FFMPEG, timeouts)
read, frame = capture.read()
capture.release()
sys.exit(0 if read and cv2.imwrite(sys.argv[2], frame) else 1)
"""


def test_rtsp_streams_over_udp_and_tcp_to_opencv(tmp_path, caplog):
    """OpenCV's ffmpeg reads the stream with rtsp_transport udp (an RTP/AVP session, relayed from
    sockets on 127.0.0.1) and with tcp (interleaved); both frames are the rendered image."""
    caplog.set_level(logging.DEBUG, logger="ptztrack.onvif_server")

    async def stream_uri(client, token: str) -> str:
        media = await client.create_media_service()
        setup = {"Stream": "RTP-Unicast", "Transport": {"Protocol": "UDP"}}
        return (await media.GetStreamUri({"StreamSetup": setup, "ProfileToken": token})).Uri

    with camera() as cam:
        assert cam.rtsp_port is not None, "ffmpeg is not on the PATH: the camera has no RTSP stream"
        uri = call(cam.onvif_port, stream_uri)
        for transport in ("udp", "tcp"):
            environment = {**os.environ, "OPENCV_FFMPEG_CAPTURE_OPTIONS": f"rtsp_transport;{transport}"}
            path = tmp_path / f"{transport}.png"
            reader = subprocess.run([sys.executable, "-c", READER, uri, str(path)], env=environment, timeout=60)
            assert reader.returncode == 0, f"no frame over {transport}"
            frame = cv2.imread(str(path))
            assert frame.shape == (HEIGHT_PX, WIDTH_PX, 3)
            assert np.abs(frame.astype(float) - render(np.array(START_POSE), 0.0)).mean() < 10.0, transport
    udp_sessions = [record.getMessage() for record in caplog.records if "RTP over UDP" in record.getMessage()]
    assert len(udp_sessions) == 1 and f"from {HOST}:" in udp_sessions[0], udp_sessions


def noise(pose, elapsed_s: float) -> np.ndarray:
    """A 2880 x 2160 image of noise: its JPEG, about 5 MB, outlasts a socket's send buffer (Linux's
    default limit is 4 MB), so that the snapshot is still being written when its client resets."""
    return np.random.default_rng(int(elapsed_s * 1000)).integers(0, 256, (2160, 2880, 3), dtype=np.uint8)


def reset(connection: socket.socket) -> None:
    """Close with a TCP reset, as a client that dies does."""
    connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    connection.close()


def rtsp_request(connection: socket.socket, request: str) -> str:
    connection.sendall(request.encode())
    answer = b""
    while b"\r\n\r\n" not in answer:
        answer += connection.recv(4096)
    return answer.decode(errors="replace")


def test_clients_that_go_away_mid_answer_leave_no_traceback_and_no_warning(caplog, capfd, monkeypatch):
    """Clients reset their connections in the middle of a snapshot, an MJPEG stream, a SOAP request and
    an RTSP stream (TCP-interleaved), and one leaves a UDP session to a closed port: nothing is logged
    at WARNING or above, no thread dies of an exception, nothing reaches stderr, and the server noted
    the two clients it was reading from or writing to going away (at debug level)."""
    caplog.set_level(logging.DEBUG)
    thread_errors = []
    monkeypatch.setattr(threading, "excepthook", thread_errors.append)
    basic = "Basic " + base64.b64encode(f"{USER}:{PASSWORD}".encode()).decode()
    big = VirtualONVIFCamera(
        noise, SPACES, FAST, START_POSE, (2880, 2160), username=USER, password=PASSWORD, frame_rate_hz=2.0, rtsp=False
    )
    with big, camera() as cam:
        for path in ("/snapshot.jpg", "/stream.mjpeg"):
            client = socket.socket()
            client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # before connect: a small window
            client.connect((HOST, big.onvif_port))
            client.sendall(f"GET {path} HTTP/1.1\r\nHost: {HOST}\r\nAuthorization: {basic}\r\n\r\n".encode())
            assert client.recv(1024).startswith(b"HTTP/1.0 200")
            time.sleep(0.3)  # the server is writing
            reset(client)
        with socket.create_connection((HOST, cam.onvif_port)) as client:
            client.sendall(b"POST /onvif/device_service HTTP/1.1\r\nContent-Length: 5000\r\n\r\n<s:Envelope")
            time.sleep(0.2)  # the server is reading the body
            reset(client)
        rtsp = socket.create_connection((HOST, cam.rtsp_port), timeout=5)
        base = f"rtsp://{HOST}:{cam.rtsp_port}/video_main"
        setup = rtsp_request(
            rtsp,
            f"SETUP {base}/trackID=0 RTSP/1.0\r\nCSeq: 1\r\nTransport: RTP/AVP/TCP;unicast;interleaved=0-1\r\n\r\n",
        )
        session = re.search(r"Session: (\w+)", setup).group(1)
        rtsp_request(rtsp, f"PLAY {base} RTSP/1.0\r\nCSeq: 2\r\nSession: {session}\r\n\r\n")
        received = b""
        while b"$\x00" not in received:  # an interleaved RTP packet
            received += rtsp.recv(4096)
        reset(rtsp)
        closed = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        closed.bind((HOST, 0))
        port = closed.getsockname()[1]
        closed.close()
        with socket.create_connection((HOST, cam.rtsp_port), timeout=5) as rtsp:
            transport = f"RTP/AVP;unicast;client_port={port}-{port + 1}"
            setup = rtsp_request(rtsp, f"SETUP {base}/trackID=0 RTSP/1.0\r\nCSeq: 1\r\nTransport: {transport}\r\n\r\n")
            session = re.search(r"Session: (\w+)", setup).group(1)
            rtsp_request(rtsp, f"PLAY {base} RTSP/1.0\r\nCSeq: 2\r\nSession: {session}\r\n\r\n")
            time.sleep(1.0)  # ffmpeg starts and RTP goes to the closed port
        time.sleep(0.3)
    loud = [f"{record.name}: {record.getMessage()}" for record in caplog.records if record.levelno >= logging.WARNING]
    assert not loud and not thread_errors, (loud, thread_errors)
    assert "Traceback" not in capfd.readouterr().err
    # The snapshot's write and the SOAP request's read met the reset (MJPEG and RTSP are ipycam's to end).
    assert sum("went away" in record.getMessage() for record in caplog.records) == 2


def test_an_onvif_client_ptztrack_does_not_use_runs_a_session_with_a_fov_move_and_a_digest_snapshot():
    """onveef (its own SOAP and XML, httpx for HTTP) connects, reads the capabilities, profiles, video
    sources, stream URI and status, moves in the FOV space, sees the head arrive, and gets a snapshot
    (HTTP Digest)."""
    with camera() as cam, onveef.OnvifClient(HOST, cam.onvif_port, USER, PASSWORD, timeout_s=5.0) as client:
        services = client.get_capabilities()
        profile = client.get_profiles()[0]
        sources = client.get_video_sources()
        uri = client.get_stream_uri(profile_token=profile["token"])
        before = client.ptz_get_status(profile_token=profile["token"])
        move = (
            f"<tptz:RelativeMove><tptz:ProfileToken>{profile['token']}</tptz:ProfileToken><tptz:Translation>"
            f'<tt:PanTilt x="0.5" y="0" space="{PAN_TILT_FOV}"/></tptz:Translation></tptz:RelativeMove>'
        )
        client.call(service="ptz", operation="RelativeMove", body_inner=move)
        moving = client.ptz_get_status(profile_token=profile["token"])
        deadline = time.monotonic() + 5.0
        while (after := client.ptz_get_status(profile_token=profile["token"]))["move_status"]["pan_tilt"] != "IDLE":
            assert time.monotonic() < deadline
            time.sleep(0.02)
        jpeg, content_type = client.get_snapshot(profile_token=profile["token"])
    assert set(services) >= {"device", "media", "ptz"}
    assert profile["video_encoder"]["width"] == WIDTH_PX and profile["ptz"]["token"] == "PTZ_Config_1"
    assert sources == [{"token": "VS_1", "framerate": 10.0, "width": WIDTH_PX, "height": HEIGHT_PX}]
    assert uri == f"rtsp://{HOST}:{cam.rtsp_port}/video_main"
    assert before["move_status"]["pan_tilt"] == "IDLE" and moving["move_status"]["pan_tilt"] == "MOVING"
    # x = 0.5 is 80 px right of the centre at zoom 1, a ray a = 80 / 300 to the right of the optical axis;
    # looking down 20 degrees, centring it turns the pan by atan(a / cos 20 deg) = 15.84 degrees (of 340).
    turn = (after["pan"] - before["pan"]) * 170.0
    offset = 0.5 * WIDTH_PX / 2.0 / F_MIN_PX
    assert turn == pytest.approx(np.degrees(np.arctan(offset / np.cos(np.radians(START_POSE[1])))), abs=1e-9)
    assert content_type == "image/jpeg" and cv2.imdecode(np.frombuffer(jpeg, np.uint8), 1).shape == (240, 320, 3)
