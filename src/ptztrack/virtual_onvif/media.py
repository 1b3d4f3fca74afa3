"""The virtual ONVIF camera's device and media services.

Device: who the camera is (GetDeviceInformation, GetScopes), its clock (GetSystemDateAndTime, in
UTC), where its services are and what they can do (GetCapabilities, GetServices,
GetServiceCapabilities). Media: one fixed profile, ``Profile_Main``, made of the video source
``VS_1`` (the rendered images, W x H px at the frame rate), its configuration ``VSC_1``, the H.264
encoder configuration ``VEC_1`` (what the RTSP stream carries) and the PTZ configuration; its RTSP
stream (unicast, RTP over UDP, TCP or RTSP) and JPEG snapshot URIs. The answers follow the ONVIF
schemas shipped with onvif-zeep-async (onvif.xsd 2.4.2, devicemgmt.wsdl, media.wsdl).
"""

import uuid
from dataclasses import dataclass, field
from datetime import UTC, datetime
from urllib.parse import quote
from xml.etree.ElementTree import Element
from xml.sax.saxutils import escape

from ptztrack.names import VERSION
from ptztrack.virtual_onvif import ptz as onvif_ptz
from ptztrack.virtual_onvif.soap import TDS, TPTZ, TRT, TT, Fault, Operation, child_text, invalid, require_token

# The ONVIF version whose schemas the answers follow (2.4, written 2.40 as devices report it).
_VERSION = "<tt:Major>2</tt:Major><tt:Minor>40</tt:Minor>"
_SOURCE, _SOURCE_CONFIGURATION, _ENCODER_CONFIGURATION = "VS_1", "VSC_1", "VEC_1"
# The RTSP session's timeout, as the RTSP server's SETUP answers give it.
_SESSION_TIMEOUT = "PT60S"


@dataclass(frozen=True)
class MediaSettings:
    """What the device and media services describe.

    name : the camera's name (a scope); service_uri : the URI of its SOAP services;
    width_px, height_px : the images' size; frame_rate_hz : the stream's whole frames per second;
    bitrate_kbps : the H.264 bitrate limit; snapshot_uri : the JPEG snapshot's URI;
    stream_uri : the RTSP stream's URI, None without RTSP.
    """

    name: str
    service_uri: str
    width_px: int
    height_px: int
    frame_rate_hz: int
    bitrate_kbps: int
    snapshot_uri: str
    stream_uri: str | None
    serial_number: str = field(default_factory=lambda: str(uuid.uuid4()))


class DeviceMediaService:
    """The device and media operations describing ``settings``, with the PTZ configuration and
    capabilities of ``ptz``."""

    def __init__(self, settings: MediaSettings, ptz: onvif_ptz.PTZService):
        self.settings, self.ptz = settings, ptz

    def operations(self) -> dict[tuple[str, str], Operation]:
        """The device and media services' operations by qualified name."""
        device: dict[str, Operation] = {
            "GetSystemDateAndTime": self._get_system_date_and_time,
            "GetDeviceInformation": self._get_device_information,
            "GetCapabilities": self._get_capabilities,
            "GetServices": self._get_services,
            "GetServiceCapabilities": self._get_device_service_capabilities,
            "GetScopes": self._get_scopes,
        }
        media: dict[str, Operation] = {
            "GetServiceCapabilities": self._get_media_service_capabilities,
            "GetProfiles": self._get_profiles,
            "GetProfile": self._get_profile,
            "GetVideoSources": self._get_video_sources,
            "GetVideoSourceConfigurations": self._get_video_source_configurations,
            "GetVideoSourceConfiguration": self._get_video_source_configuration,
            "GetCompatibleVideoSourceConfigurations": self._get_compatible_video_source_configurations,
            "GetVideoEncoderConfigurations": self._get_video_encoder_configurations,
            "GetVideoEncoderConfiguration": self._get_video_encoder_configuration,
            "GetCompatibleVideoEncoderConfigurations": self._get_compatible_video_encoder_configurations,
            "GetStreamUri": self._get_stream_uri,
            "GetSnapshotUri": self._get_snapshot_uri,
        }
        return {(TDS, name): operation for name, operation in device.items()} | {
            (TRT, name): operation for name, operation in media.items()
        }

    # Device.

    def _get_system_date_and_time(self, operation: Element) -> str:
        now = datetime.now(UTC)
        return (
            "<tds:GetSystemDateAndTimeResponse><tds:SystemDateAndTime>"
            "<tt:DateTimeType>Manual</tt:DateTimeType><tt:DaylightSavings>false</tt:DaylightSavings>"
            "<tt:TimeZone><tt:TZ>UTC0</tt:TZ></tt:TimeZone><tt:UTCDateTime>"
            f"<tt:Time><tt:Hour>{now.hour}</tt:Hour><tt:Minute>{now.minute}</tt:Minute>"
            f"<tt:Second>{now.second}</tt:Second></tt:Time>"
            f"<tt:Date><tt:Year>{now.year}</tt:Year><tt:Month>{now.month}</tt:Month><tt:Day>{now.day}</tt:Day></tt:Date>"
            "</tt:UTCDateTime></tds:SystemDateAndTime></tds:GetSystemDateAndTimeResponse>"
        )

    def _get_device_information(self, operation: Element) -> str:
        return (
            "<tds:GetDeviceInformationResponse><tds:Manufacturer>ptztrack</tds:Manufacturer>"
            f"<tds:Model>VirtualONVIFCamera</tds:Model><tds:FirmwareVersion>{escape(VERSION)}</tds:FirmwareVersion>"
            f"<tds:SerialNumber>{self.settings.serial_number}</tds:SerialNumber>"
            "<tds:HardwareId>virtual</tds:HardwareId></tds:GetDeviceInformationResponse>"
        )

    def _get_capabilities(self, operation: Element) -> str:
        categories = {(category.text or "").strip() for category in operation.iter(f"{{{TDS}}}Category")}
        unsupported = categories - {"All", "Device", "Media", "PTZ"}
        if unsupported:
            raise Fault(
                "Receiver", ["ter:ActionNotSupported", "ter:NoSuchService"], f"no Category {sorted(unsupported)}"
            )
        wanted = {"Device", "Media", "PTZ"} if not categories or "All" in categories else categories
        uri, rtsp = escape(self.settings.service_uri), str(self.settings.stream_uri is not None).lower()
        parts = {
            "Device": f"<tt:Device><tt:XAddr>{uri}</tt:XAddr><tt:Network><tt:IPFilter>false</tt:IPFilter>"
            "<tt:ZeroConfiguration>false</tt:ZeroConfiguration><tt:IPVersion6>false</tt:IPVersion6>"
            "<tt:DynDNS>false</tt:DynDNS></tt:Network><tt:System>"
            + "".join(
                f"<tt:{name}>false</tt:{name}>"
                for name in (
                    "DiscoveryResolve DiscoveryBye RemoteDiscovery SystemBackup SystemLogging FirmwareUpgrade".split()
                )
            )
            + f"<tt:SupportedVersions>{_VERSION}</tt:SupportedVersions></tt:System>"
            "<tt:IO><tt:InputConnectors>0</tt:InputConnectors><tt:RelayOutputs>0</tt:RelayOutputs></tt:IO>"
            "<tt:Security>"
            + "".join(
                f"<tt:{name}>false</tt:{name}>"
                for name in (
                    "TLS1.1 TLS1.2 OnboardKeyGeneration AccessPolicyConfig X.509Token SAMLToken KerberosToken "
                    "RELToken".split()
                )
            )
            + "</tt:Security></tt:Device>",
            "Media": f"<tt:Media><tt:XAddr>{uri}</tt:XAddr><tt:StreamingCapabilities>"
            f"<tt:RTPMulticast>false</tt:RTPMulticast><tt:RTP_TCP>{rtsp}</tt:RTP_TCP>"
            f"<tt:RTP_RTSP_TCP>{rtsp}</tt:RTP_RTSP_TCP></tt:StreamingCapabilities></tt:Media>",
            "PTZ": f"<tt:PTZ><tt:XAddr>{uri}</tt:XAddr></tt:PTZ>",
        }
        # The schema's order: Device, then Media, then PTZ.
        chosen = "".join(xml for category, xml in parts.items() if category in wanted)
        return (
            f"<tds:GetCapabilitiesResponse><tds:Capabilities>{chosen}</tds:Capabilities></tds:GetCapabilitiesResponse>"
        )

    def _device_capabilities_xml(self) -> str:
        return (
            '<tds:Capabilities><tds:Network IPFilter="false" ZeroConfiguration="false" IPVersion6="false" '
            'DynDNS="false"/><tds:Security UsernameToken="true" HttpDigest="false"/>'
            '<tds:System DiscoveryResolve="false" DiscoveryBye="false" RemoteDiscovery="false" '
            'SystemBackup="false" SystemLogging="false" FirmwareUpgrade="false"/></tds:Capabilities>'
        )

    def _media_capabilities_xml(self) -> str:
        rtsp = str(self.settings.stream_uri is not None).lower()
        return (
            '<trt:Capabilities SnapshotUri="true" Rotation="false" VideoSourceMode="false" OSD="false">'
            '<trt:ProfileCapabilities MaximumNumberOfProfiles="1"/><trt:StreamingCapabilities RTPMulticast="false" '
            f'RTP_TCP="{rtsp}" RTP_RTSP_TCP="{rtsp}" NoRTSPStreaming="{str(rtsp == "false").lower()}"/>'
            "</trt:Capabilities>"
        )

    def _get_services(self, operation: Element) -> str:
        include = child_text(operation, "IncludeCapability")
        if include not in ("true", "1", "false", "0"):
            raise Fault("Sender", ["ter:InvalidArgs"], f"IncludeCapability {include!r} is not an xs:boolean")
        capabilities = {
            TDS: self._device_capabilities_xml(),
            TRT: self._media_capabilities_xml(),
            TPTZ: self.ptz.capabilities_xml(),
        }
        return (
            "<tds:GetServicesResponse>"
            + "".join(
                f"<tds:Service><tds:Namespace>{namespace}</tds:Namespace>"
                f"<tds:XAddr>{escape(self.settings.service_uri)}</tds:XAddr>"
                + (f"<tds:Capabilities>{xml}</tds:Capabilities>" if include in ("true", "1") else "")
                + f"<tds:Version>{_VERSION}</tds:Version></tds:Service>"
                for namespace, xml in capabilities.items()
            )
            + "</tds:GetServicesResponse>"
        )

    def _get_device_service_capabilities(self, operation: Element) -> str:
        capabilities = self._device_capabilities_xml()
        return f"<tds:GetServiceCapabilitiesResponse>{capabilities}</tds:GetServiceCapabilitiesResponse>"

    def _get_scopes(self, operation: Element) -> str:
        scopes = [
            ("Fixed", "onvif://www.onvif.org/type/video_encoder"),
            ("Fixed", "onvif://www.onvif.org/type/ptz"),
            ("Fixed", "onvif://www.onvif.org/Profile/Streaming"),
            ("Fixed", "onvif://www.onvif.org/hardware/VirtualONVIFCamera"),
            ("Fixed", f"onvif://www.onvif.org/name/{quote(self.settings.name)}"),
        ]
        return (
            "<tds:GetScopesResponse>"
            + "".join(
                f"<tds:Scopes><tt:ScopeDef>{kind}</tt:ScopeDef><tt:ScopeItem>{escape(item)}</tt:ScopeItem></tds:Scopes>"
                for kind, item in scopes
            )
            + "</tds:GetScopesResponse>"
        )

    # Media: the profile and its parts.

    def _profile(self, operation: Element) -> None:
        require_token(operation, "ProfileToken", onvif_ptz.PROFILE, "NoProfile")

    def _video_source_configuration_xml(self, tag: str) -> str:
        s = self.settings
        return (
            f'<{tag} token="{_SOURCE_CONFIGURATION}"><tt:Name>VideoSource</tt:Name><tt:UseCount>1</tt:UseCount>'
            f'<tt:SourceToken>{_SOURCE}</tt:SourceToken><tt:Bounds x="0" y="0" width="{s.width_px}" '
            f'height="{s.height_px}"/></{tag}>'
        )

    def _video_encoder_configuration_xml(self, tag: str) -> str:
        s = self.settings
        # A keyframe every two seconds, as the RTSP server's encoder is set (ipycam's _gop_size).
        return (
            f'<{tag} token="{_ENCODER_CONFIGURATION}"><tt:Name>H264</tt:Name><tt:UseCount>1</tt:UseCount>'
            "<tt:Encoding>H264</tt:Encoding>"
            f"<tt:Resolution><tt:Width>{s.width_px}</tt:Width><tt:Height>{s.height_px}</tt:Height></tt:Resolution>"
            f"<tt:Quality>5</tt:Quality><tt:RateControl><tt:FrameRateLimit>{s.frame_rate_hz}</tt:FrameRateLimit>"
            f"<tt:EncodingInterval>1</tt:EncodingInterval><tt:BitrateLimit>{s.bitrate_kbps}</tt:BitrateLimit>"
            f"</tt:RateControl><tt:H264><tt:GovLength>{2 * s.frame_rate_hz}</tt:GovLength>"
            "<tt:H264Profile>Baseline</tt:H264Profile></tt:H264>"
            "<tt:Multicast><tt:Address><tt:Type>IPv4</tt:Type><tt:IPv4Address>0.0.0.0</tt:IPv4Address></tt:Address>"
            "<tt:Port>0</tt:Port><tt:TTL>0</tt:TTL><tt:AutoStart>false</tt:AutoStart></tt:Multicast>"
            f"<tt:SessionTimeout>{_SESSION_TIMEOUT}</tt:SessionTimeout></{tag}>"
        )

    def _profile_xml(self, tag: str) -> str:
        return (
            f'<{tag} token="{onvif_ptz.PROFILE}" fixed="true"><tt:Name>Main</tt:Name>'
            f"{self._video_source_configuration_xml('tt:VideoSourceConfiguration')}"
            f"{self._video_encoder_configuration_xml('tt:VideoEncoderConfiguration')}"
            f"{self.ptz.configuration_xml('tt:PTZConfiguration')}</{tag}>"
        )

    def _get_media_service_capabilities(self, operation: Element) -> str:
        return (
            f"<trt:GetServiceCapabilitiesResponse>{self._media_capabilities_xml()}</trt:GetServiceCapabilitiesResponse>"
        )

    def _get_profiles(self, operation: Element) -> str:
        return f"<trt:GetProfilesResponse>{self._profile_xml('trt:Profiles')}</trt:GetProfilesResponse>"

    def _get_profile(self, operation: Element) -> str:
        self._profile(operation)
        return f"<trt:GetProfileResponse>{self._profile_xml('trt:Profile')}</trt:GetProfileResponse>"

    def _get_video_sources(self, operation: Element) -> str:
        s = self.settings
        return (
            f'<trt:GetVideoSourcesResponse><trt:VideoSources token="{_SOURCE}">'
            f"<tt:Framerate>{s.frame_rate_hz}</tt:Framerate><tt:Resolution><tt:Width>{s.width_px}</tt:Width>"
            f"<tt:Height>{s.height_px}</tt:Height></tt:Resolution></trt:VideoSources></trt:GetVideoSourcesResponse>"
        )

    def _get_video_source_configurations(self, operation: Element) -> str:
        configuration = self._video_source_configuration_xml("trt:Configurations")
        return f"<trt:GetVideoSourceConfigurationsResponse>{configuration}</trt:GetVideoSourceConfigurationsResponse>"

    def _get_video_source_configuration(self, operation: Element) -> str:
        require_token(operation, "ConfigurationToken", _SOURCE_CONFIGURATION, "NoConfig")
        configuration = self._video_source_configuration_xml("trt:Configuration")
        return f"<trt:GetVideoSourceConfigurationResponse>{configuration}</trt:GetVideoSourceConfigurationResponse>"

    def _get_compatible_video_source_configurations(self, operation: Element) -> str:
        self._profile(operation)
        configuration = self._video_source_configuration_xml("trt:Configurations")
        return (
            f"<trt:GetCompatibleVideoSourceConfigurationsResponse>{configuration}"
            "</trt:GetCompatibleVideoSourceConfigurationsResponse>"
        )

    def _get_video_encoder_configurations(self, operation: Element) -> str:
        configuration = self._video_encoder_configuration_xml("trt:Configurations")
        return f"<trt:GetVideoEncoderConfigurationsResponse>{configuration}</trt:GetVideoEncoderConfigurationsResponse>"

    def _get_video_encoder_configuration(self, operation: Element) -> str:
        require_token(operation, "ConfigurationToken", _ENCODER_CONFIGURATION, "NoConfig")
        configuration = self._video_encoder_configuration_xml("trt:Configuration")
        return f"<trt:GetVideoEncoderConfigurationResponse>{configuration}</trt:GetVideoEncoderConfigurationResponse>"

    def _get_compatible_video_encoder_configurations(self, operation: Element) -> str:
        self._profile(operation)
        configuration = self._video_encoder_configuration_xml("trt:Configurations")
        return (
            f"<trt:GetCompatibleVideoEncoderConfigurationsResponse>{configuration}"
            "</trt:GetCompatibleVideoEncoderConfigurationsResponse>"
        )

    # Media: the URIs.

    def _get_stream_uri(self, operation: Element) -> str:
        self._profile(operation)
        setup = operation.find(f"{{{TRT}}}StreamSetup")
        stream = None if setup is None else setup.findtext(f"{{{TT}}}Stream", "").strip()
        protocol = None if setup is None else setup.findtext(f"{{{TT}}}Transport/{{{TT}}}Protocol", "").strip()
        if stream != "RTP-Unicast" or protocol not in ("UDP", "TCP", "RTSP"):
            raise invalid(
                "InvalidStreamSetup",
                f"StreamSetup {stream!r} over {protocol!r}: only RTP-Unicast over UDP, TCP or RTSP is served",
            )
        if self.settings.stream_uri is None:
            raise Fault("Receiver", ["ter:ActionNotSupported"], "no RTSP stream (ffmpeg is not on the PATH)")
        return f"<trt:GetStreamUriResponse>{_media_uri_xml(self.settings.stream_uri)}</trt:GetStreamUriResponse>"

    def _get_snapshot_uri(self, operation: Element) -> str:
        self._profile(operation)
        return f"<trt:GetSnapshotUriResponse>{_media_uri_xml(self.settings.snapshot_uri)}</trt:GetSnapshotUriResponse>"


def _media_uri_xml(uri: str) -> str:
    # The ports are chosen anew at each start: a URI is valid until the camera stops.
    return (
        f"<trt:MediaUri><tt:Uri>{escape(uri)}</tt:Uri><tt:InvalidAfterConnect>false</tt:InvalidAfterConnect>"
        "<tt:InvalidAfterReboot>true</tt:InvalidAfterReboot><tt:Timeout>PT0S</tt:Timeout></trt:MediaUri>"
    )
