"""The virtual ONVIF camera against the standards other ONVIF tools expect: every answer valid against
the ONVIF schemas that onvif-zeep-async ships, SOAP 1.2 faults with their HTTP status, WS-Security
replay protection, HTTP Digest, and the media and PTZ operations that were missing."""

import asyncio
import base64
import hashlib
import http.client
import os
import re
import secrets
import struct
from datetime import UTC, datetime, timedelta

import cv2
import numpy as np
import pytest
from lxml import etree  # zeep's XML library

from onvif_camera import (
    ERRORS,
    F_MIN_PX,
    HEIGHT_PX,
    HOST,
    PASSWORD,
    SOAP,
    SPACES,
    START_POSE,
    USER,
    WIDTH_PX,
    WSDL,
    call,
    camera,
    onvif,
    render,
)
from ptztrack.virtual_onvif.http import HTTPAuth, Verdict
from ptztrack.virtual_onvif.media import DeviceMediaService, MediaSettings
from ptztrack.virtual_onvif.ptz import PAN_TILT_FOV, PTZService
from ptztrack.virtual_onvif.soap import Fault, UsernameTokens

pytestmark = pytest.mark.onvif

XS = "http://www.w3.org/2001/XMLSchema"
WSSE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-secext-1.0.xsd"
WSU = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-utility-1.0.xsd"
TOKEN_PROFILE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-username-token-profile-1.0"
NAMESPACES = {
    "tds": "http://www.onvif.org/ver10/device/wsdl",
    "trt": "http://www.onvif.org/ver10/media/wsdl",
    "tptz": "http://www.onvif.org/ver20/ptz/wsdl",
    "tt": "http://www.onvif.org/ver10/schema",
}


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
    supported = set(DeviceMediaService(settings, ptz).operations()) | set(ptz.operations())
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


@pytest.mark.parametrize(("positions", "absolute_moves"), [(False, True), (True, False)])
def test_a_camera_without_positions_or_absolute_moves_answers_schema_valid_xml_that_says_so(
    schema, positions, absolute_moves
):
    """--no-positions: GetStatus has MoveStatus and UtcTime but no Position, a preset no PTZPosition, and
    the capabilities say StatusPosition="false". --relative-only: no absolute position space in the node
    or the configuration options, no default absolute space or limits in any configuration (a profile's
    included), and AbsoluteMove is the SOAP 1.2 fault env:Receiver ter:ActionNotSupported
    ter:OptionalActionNotSupported (HTTP 500). Every other answer is as before, valid against the schemas."""
    tt, tptz = f"{{{NAMESPACES['tt']}}}", f"{{{NAMESPACES['tptz']}}}"
    answers = {}
    with camera(positions=positions, absolute_moves=absolute_moves) as cam:
        for (prefix, name), body in REQUESTS.items():
            status, answer = soap(cam.onvif_port, body)
            answers[prefix, name] = answer
            if (name, absolute_moves) == ("AbsoluteMove", False):
                assert status == 500
                assert_soap_1_2_fault(answer, "Receiver", ["ActionNotSupported", "OptionalActionNotSupported"])
                assert "AbsoluteMove" in answer.findtext(f".//{{{SOAP}}}Text")
                continue
            assert (status, answer.tag) == (200, f"{{{NAMESPACES[prefix]}}}{name}Response"), (name, status)
            assert schema.validate(answer), (name, str(schema.error_log))
    status = answers["tptz", "GetStatus"].find(f"{tptz}PTZStatus")
    assert [child.tag for child in status] == [
        *([f"{tt}Position"] if positions else []),
        f"{tt}MoveStatus",
        f"{tt}UtcTime",
    ]
    presets = answers["tptz", "GetPresets"].findall(f"{tptz}Preset")  # asked after SetPreset
    assert presets and all((preset.find(f"{tt}PTZPosition") is None) != positions for preset in presets)
    ptz_capabilities = answers["tptz", "GetServiceCapabilities"].find(f"{tptz}Capabilities")
    assert ptz_capabilities.get("StatusPosition") == str(positions).lower()
    assert str(positions).lower() in [
        element.get("StatusPosition") for element in answers["tds", "GetServices"].iter(f"{tptz}Capabilities")
    ]
    absolute = {f"{tt}AbsolutePanTiltPositionSpace", f"{tt}AbsoluteZoomPositionSpace"}
    defaults = {f"{tt}DefaultAbsolutePantTiltPositionSpace", f"{tt}DefaultAbsoluteZoomPositionSpace"}
    limits = {f"{tt}PanTiltLimits", f"{tt}ZoomLimits"}
    for key, element in (
        (("tptz", "GetNodes"), f"{tt}SupportedPTZSpaces"),
        (("tptz", "GetNode"), f"{tt}SupportedPTZSpaces"),
        (("tptz", "GetConfigurationOptions"), f"{tt}Spaces"),
    ):
        spaces = {child.tag for child in answers[key].iter(element) for child in child}
        assert (absolute <= spaces) == absolute_moves and f"{tt}RelativePanTiltTranslationSpace" in spaces, key
    for key, tag in (
        (("tptz", "GetConfigurations"), f"{tptz}PTZConfiguration"),
        (("tptz", "GetConfiguration"), f"{tptz}PTZConfiguration"),
        (("tptz", "GetCompatibleConfigurations"), f"{tptz}PTZConfiguration"),
        (("trt", "GetProfiles"), f"{tt}PTZConfiguration"),
    ):
        configuration = {child.tag for child in next(answers[key].iter(tag))}
        assert ((defaults | limits) <= configuration) == absolute_moves, key
        assert not (defaults | limits) & configuration or absolute_moves, key


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
