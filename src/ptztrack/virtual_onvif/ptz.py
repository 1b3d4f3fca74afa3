"""The virtual ONVIF camera's PTZ service over a :class:`~ptztrack.virtual_onvif.head.Head`.

Positions, translations and velocities are in ONVIF's generic spaces, mapped to the model's pose by
:class:`~ptztrack.camera.onvif_spaces.CameraSpaces`: a position is the normalised one (pan, tilt in
[-1, 1], zoom in [0, 1]); a generic translation is added to it and clipped (a translation of 1 is
half the pan range); a velocity is a fraction of the axis's full speed, signed in the normalised
space's direction, so that on an axis whose degrees fall from -1 to +1 (ONVIF's tilt, +1 up, over the
model's depression) a positive velocity runs the model's axis down its degrees; a Speed in (0, 1]
scales the full speed (default 1). Presets are kept in memory and, given a file, in it
(:class:`PTZService`).

Two modes leave out what some cameras lack. Without positions, GetStatus has no Position and a
preset no PTZPosition (both optional in the schema), and the capabilities say
``StatusPosition="false"``. Without absolute moves, the node and the configuration options list no
absolute position space, the configuration has no default absolute spaces nor the limits given in
them, and AbsoluteMove is refused with env:Receiver ter:ActionNotSupported
ter:OptionalActionNotSupported: the PTZ Service Specification makes a move whose spaces the node
lacks unavailable ("Capabilities": a node without an AbsolutePanTiltPositionSpace fails AbsoluteMove)
and answers an operation the device does not implement so (GetCompatibleConfigurations); ONVIF Core's
generic fault for an optional action not implemented is env:Receiver ter:ActionNotSupported.

With the focal length ``f_min_px`` the node also offers the relative pan/tilt translation space in
FOV (``.../PanTiltSpaces/TranslationSpaceFov``, ONVIF PTZ Service Specification, "Pan/tilt
Translation Space in FOV"): its origin is the image centre and the upper right corner is (1, 1), and
a move by (x, y) centres the scene point seen there (:func:`fov_target`). Its advertised range is
[-1, 1] on both axes, the current image.
"""

import json
import math
import re
import threading
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from xml.etree.ElementTree import Element
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from ptztrack.camera.onvif_spaces import CameraSpaces
from ptztrack.files import InputError, read_json, write_atomically
from ptztrack.geometry.ptz import rotation_world_to_camera
from ptztrack.virtual_onvif.head import Head
from ptztrack.virtual_onvif.soap import TPTZ, TT, Fault, Operation, child_text, invalid, require_token

_SPACES = "http://www.onvif.org/ver10/tptz/"
PAN_TILT_POSITION = _SPACES + "PanTiltSpaces/PositionGenericSpace"
ZOOM_POSITION = _SPACES + "ZoomSpaces/PositionGenericSpace"
PAN_TILT_TRANSLATION = _SPACES + "PanTiltSpaces/TranslationGenericSpace"
PAN_TILT_FOV = _SPACES + "PanTiltSpaces/TranslationSpaceFov"
ZOOM_TRANSLATION = _SPACES + "ZoomSpaces/TranslationGenericSpace"
PAN_TILT_VELOCITY = _SPACES + "PanTiltSpaces/VelocityGenericSpace"
ZOOM_VELOCITY = _SPACES + "ZoomSpaces/VelocityGenericSpace"
PAN_TILT_SPEED = _SPACES + "PanTiltSpaces/GenericSpeedSpace"
ZOOM_SPEED = _SPACES + "ZoomSpaces/ZoomGenericSpeedSpace"

PROFILE, CONFIGURATION, NODE = "Profile_Main", "PTZ_Config_1", "PTZ_Node_1"
_MAX_PRESETS = 32
_MAX_PRESETS_FILE_BYTES = 1 << 20
# ContinuousMove without a Timeout runs for the configuration's DefaultPTZTimeout; longer ones are refused.
DEFAULT_TIMEOUT_S, MAX_TIMEOUT_S = 10.0, 60.0
# xs:duration from days to seconds (years and months have no fixed length): P1D, PT10S, PT0.5S, PT1M30S.
_DURATION = r"P(?=\d|T\d)(?:(\d+)D)?(?:T(?=\d)(?:(\d+)H)?(?:(\d+)M)?(?:(\d+(?:\.\d+)?)S)?)?"

_Vector = tuple[tuple[float, float, str] | None, float | None]


def fov_target(pose, fov_xy: tuple[float, float], image_size_px: tuple[int, int], f_min_px: float) -> np.ndarray:
    """The (pan_deg, tilt_deg) (2,) that centre the scene point seen at FOV-space position ``fov_xy`` from ``pose``.

    FOV (x, y) is the pixel offset (du, dv) = (x W / 2, -y H / 2) from the principal point (image
    W x H px; x right, y up); its ray in the camera frame is d = (du / f, dv / f, 1), f = zoom f_min_px,
    and in the world d_w = R(pan, tilt)^T d. The model's pan turns from +y towards +x and its tilt is
    the depression (:mod:`ptztrack.geometry.ptz`), so the view along d_w is
        pan' = atan2(d_w,x, d_w,y),   tilt' = asin(-d_w,z / |d_w|),
    pan' taken within 180 degrees of the current pan. The head turns about its optical centre without
    roll, so that point then projects to the principal point exactly.
    """
    pan_deg, tilt_deg, zoom = (float(value) for value in pose)
    focal_px = zoom * f_min_px
    width_px, height_px = image_size_px
    ray = np.array([fov_xy[0] * width_px / 2.0 / focal_px, -fov_xy[1] * height_px / 2.0 / focal_px, 1.0])
    ray_world = rotation_world_to_camera(pan_deg, tilt_deg).T @ ray
    turn_deg = math.degrees(math.atan2(ray_world[0], ray_world[1])) - pan_deg
    return np.array(
        [
            pan_deg + (turn_deg + 180.0) % 360.0 - 180.0,
            math.degrees(math.asin(-ray_world[2] / np.linalg.norm(ray_world))),
        ]
    )


def _range_xml(tag: str, uri: str, x: tuple[float, float], y: tuple[float, float] | None = None) -> str:
    def limits(axis: str, low_high: tuple[float, float]) -> str:
        return f"<tt:{axis}Range><tt:Min>{low_high[0]}</tt:Min><tt:Max>{low_high[1]}</tt:Max></tt:{axis}Range>"

    return f"<tt:{tag}><tt:URI>{uri}</tt:URI>{limits('X', x)}{limits('Y', y) if y else ''}</tt:{tag}>"


def _position_xml(tag: str, position: np.ndarray) -> str:
    x, y, zoom = (repr(float(value)) for value in position)
    return (
        f'<{tag}><tt:PanTilt x="{x}" y="{y}" space="{PAN_TILT_POSITION}"/>'
        f'<tt:Zoom x="{zoom}" space="{ZOOM_POSITION}"/></{tag}>'
    )


def read_presets(path: Path) -> dict[str, tuple[str, np.ndarray]]:
    """The presets kept in ``path`` (none if there is no such file), token -> (name, pose (3,) pan_deg,
    tilt_deg, zoom); an :class:`InputError` of one line naming the file if it is not a presets file.

    The file is JSON: ``{"presets": [{"token": "1", "name": "door", "pose": [pan_deg, tilt_deg, zoom]}, ...]}``,
    the poses the head's own (the model's), so that a preset keeps its view whatever the spaces.
    """
    if not path.exists():
        return {}
    document = read_json(path, "presets", _MAX_PRESETS_FILE_BYTES)
    expected = f'{path}: expected {{"presets": [{{"token": ..., "name": ..., "pose": [pan_deg, tilt_deg, zoom]}}]}}'
    entries = document.get("presets") if isinstance(document, dict) else None
    if not isinstance(entries, list) or len(entries) > _MAX_PRESETS:
        raise InputError(f"{expected}, at most {_MAX_PRESETS} presets")
    presets = {}
    for entry in entries:
        token, name, pose = (entry.get(key) if isinstance(entry, dict) else None for key in ("token", "name", "pose"))
        numbers = isinstance(pose, list) and len(pose) == 3 and all(type(value) in (int, float) for value in pose)
        if not (isinstance(token, str) and token and isinstance(name, str) and numbers) or token in presets:
            raise InputError(f"{expected}, each token a different non-empty string; not {entry!r:.80}")
        presets[token] = (name, np.array(pose, dtype=float))
    return presets


class PTZService:
    """The PTZ operations over ``head``; positions through ``spaces``; ``home_pose`` (3,) is the home.

    image_size_px : (width, height) of the images; f_min_px : the focal length in pixels at zoom 1,
    None for a node without the FOV translation space; positions : GetStatus and GetPresets give
    positions; absolute_moves : the node has the absolute position spaces and AbsoluteMove (module
    docstring); presets_path : the JSON file the presets are read from at the start and written to,
    atomically, on every change (:func:`read_presets`), None to keep them in memory only.
    """

    def __init__(
        self,
        head: Head,
        spaces: CameraSpaces,
        home_pose: np.ndarray,
        image_size_px: tuple[int, int],
        f_min_px: float | None,
        positions: bool = True,
        absolute_moves: bool = True,
        presets_path: Path | None = None,
    ):
        self.head, self.spaces, self.home_pose = head, spaces, home_pose
        self.image_size_px, self.f_min_px = image_size_px, f_min_px
        self.positions, self.absolute_moves, self.presets_path = positions, absolute_moves, presets_path
        # token -> (name, pose (3,))
        self._presets = {} if presets_path is None else read_presets(presets_path)
        self._presets_lock = threading.Lock()
        self._next_preset = 1 + max((int(token) for token in self._presets if token.isdecimal()), default=0)
        # The sign of each axis's degrees from normalised -1 to +1: a velocity's direction in the model's.
        self._directions = (
            float(np.sign(spaces.pan_deg[1] - spaces.pan_deg[0])),
            float(np.sign(spaces.tilt_deg[1] - spaces.tilt_deg[0])),
            1.0,
        )

    def configuration_xml(self, tag: str) -> str:
        """The PTZ configuration as the element ``tag`` (tt:PTZConfiguration type): without absolute moves,
        no default absolute spaces and no limits (which are given in the absolute position space)."""
        absolute = (
            f"<tt:DefaultAbsolutePantTiltPositionSpace>{PAN_TILT_POSITION}</tt:DefaultAbsolutePantTiltPositionSpace>"
            f"<tt:DefaultAbsoluteZoomPositionSpace>{ZOOM_POSITION}</tt:DefaultAbsoluteZoomPositionSpace>"
        )
        limits = (
            f"<tt:PanTiltLimits>{_range_xml('Range', PAN_TILT_POSITION, (-1.0, 1.0), (-1.0, 1.0))}</tt:PanTiltLimits>"
            f"<tt:ZoomLimits>{_range_xml('Range', ZOOM_POSITION, (0.0, 1.0))}</tt:ZoomLimits>"
        )
        # "PantTilt" is the ONVIF schema's own spelling.
        return (
            f'<{tag} token="{CONFIGURATION}"><tt:Name>PTZ</tt:Name><tt:UseCount>1</tt:UseCount>'
            f"<tt:NodeToken>{NODE}</tt:NodeToken>"
            f"{absolute if self.absolute_moves else ''}"
            f"<tt:DefaultRelativePanTiltTranslationSpace>{PAN_TILT_TRANSLATION}</tt:DefaultRelativePanTiltTranslationSpace>"
            f"<tt:DefaultRelativeZoomTranslationSpace>{ZOOM_TRANSLATION}</tt:DefaultRelativeZoomTranslationSpace>"
            f"<tt:DefaultContinuousPanTiltVelocitySpace>{PAN_TILT_VELOCITY}</tt:DefaultContinuousPanTiltVelocitySpace>"
            f"<tt:DefaultContinuousZoomVelocitySpace>{ZOOM_VELOCITY}</tt:DefaultContinuousZoomVelocitySpace>"
            f'<tt:DefaultPTZSpeed><tt:PanTilt x="1.0" y="1.0" space="{PAN_TILT_SPEED}"/>'
            f'<tt:Zoom x="1.0" space="{ZOOM_SPEED}"/></tt:DefaultPTZSpeed>'
            f"<tt:DefaultPTZTimeout>PT{DEFAULT_TIMEOUT_S:g}S</tt:DefaultPTZTimeout>"
            f"{limits if self.absolute_moves else ''}</{tag}>"
        )

    def capabilities_xml(self) -> str:
        """The PTZ service's capabilities (tptz:Capabilities); MoveStatus and StatusPosition are later
        versions' attributes, which this schema's anyAttribute admits."""
        return (
            '<tptz:Capabilities EFlip="false" Reverse="false" GetCompatibleConfigurations="true" '
            f'MoveStatus="true" StatusPosition="{str(self.positions).lower()}"/>'
        )

    def operations(self) -> dict[tuple[str, str], Operation]:
        """The PTZ service's operations by qualified name."""
        operations: dict[str, Operation] = {
            "GetServiceCapabilities": self._get_service_capabilities,
            "GetNodes": self._get_nodes,
            "GetNode": self._get_node,
            "GetConfigurations": self._get_configurations,
            "GetConfiguration": self._get_configuration,
            "GetConfigurationOptions": self._get_configuration_options,
            "GetCompatibleConfigurations": self._get_compatible_configurations,
            "GetStatus": self._get_status,
            "AbsoluteMove": self._absolute_move,
            "RelativeMove": self._relative_move,
            "ContinuousMove": self._continuous_move,
            "Stop": self._stop,
            "GotoHomePosition": self._goto_home_position,
            "SetPreset": self._set_preset,
            "GetPresets": self._get_presets,
            "GotoPreset": self._goto_preset,
            "RemovePreset": self._remove_preset,
        }
        return {(TPTZ, name): operation for name, operation in operations.items()}

    # The request's parts.

    def _profile(self, operation: Element) -> None:
        require_token(operation, "ProfileToken", PROFILE, "NoProfile")

    def _vector(
        self, operation: Element, element: str, pan_tilt_spaces: Sequence[str], zoom_space: str, required: bool = True
    ) -> _Vector:
        """((x, y, space) of the PanTilt, x of the Zoom) of ``element`` (None where absent); a PanTilt is in
        one of ``pan_tilt_spaces`` (the first if it names none), a Zoom in ``zoom_space``; ``element`` is
        refused if ``required`` and absent."""
        vector = operation.find(f"{{{TPTZ}}}{element}")
        if vector is None and required:
            raise Fault("Sender", ["ter:InvalidArgs"], f"{element} is missing")
        parts = [None if vector is None else vector.find(f"{{{TT}}}{part}") for part in ("PanTilt", "Zoom")]
        pan_tilt, zoom = parts
        for part, name, spaces in ((pan_tilt, "PanTilt", pan_tilt_spaces), (zoom, "Zoom", [zoom_space])):
            if part is not None and part.get("space", spaces[0]) not in spaces:
                raise invalid("SpaceNotSupported", f"{element}.{name} space {part.get('space')!r}: one of {spaces}")
        if pan_tilt is None:
            return None, None if zoom is None else _number(zoom, element, "x")
        x, y = _number(pan_tilt, element, "x"), _number(pan_tilt, element, "y")
        return (x, y, pan_tilt.get("space", pan_tilt_spaces[0])), None if zoom is None else _number(zoom, element, "x")

    def _speed(self, operation: Element) -> list[float]:
        """The Speed's fractions (3,) of full speed, each in (0, 1], 1 where not given."""
        pan_tilt, zoom = self._vector(operation, "Speed", [PAN_TILT_SPEED], ZOOM_SPEED, required=False)
        speed = [*(pan_tilt[:2] if pan_tilt else (1.0, 1.0)), 1.0 if zoom is None else zoom]
        if not all(0.0 < fraction <= 1.0 for fraction in speed):
            raise invalid("InvalidSpeed", f"Speed {speed} is not in (0, 1]")
        return speed

    def _target(self, normalised: Sequence[float | None]) -> list[float | None]:
        """The pose of each axis with a normalised position (None: left as it is)."""
        _, pose, _ = self.head.now()
        here = self.spaces.normalised(pose)
        target = self.spaces.pose([here[axis] if value is None else value for axis, value in enumerate(normalised)])
        return [None if value is None else float(target[axis]) for axis, value in enumerate(normalised)]

    # The node and the configuration.

    def _spaces_xml(self) -> str:
        """The spaces: positions pan/tilt [-1, 1], zoom [0, 1] (with absolute moves); translations and
        velocities [-1, 1]; speeds [0, 1]; with a focal length, the FOV translation [-1, 1] x [-1, 1] too."""
        both, zero_one = (-1.0, 1.0), (0.0, 1.0)
        fov = "" if self.f_min_px is None else _range_xml("RelativePanTiltTranslationSpace", PAN_TILT_FOV, both, both)
        absolute = _range_xml("AbsolutePanTiltPositionSpace", PAN_TILT_POSITION, both, both) + _range_xml(
            "AbsoluteZoomPositionSpace", ZOOM_POSITION, zero_one
        )
        return (
            (absolute if self.absolute_moves else "")
            + _range_xml("RelativePanTiltTranslationSpace", PAN_TILT_TRANSLATION, both, both)
            + fov
            + _range_xml("RelativeZoomTranslationSpace", ZOOM_TRANSLATION, both)
            + _range_xml("ContinuousPanTiltVelocitySpace", PAN_TILT_VELOCITY, both, both)
            + _range_xml("ContinuousZoomVelocitySpace", ZOOM_VELOCITY, both)
            + _range_xml("PanTiltSpeedSpace", PAN_TILT_SPEED, zero_one)
            + _range_xml("ZoomSpeedSpace", ZOOM_SPEED, zero_one)
        )

    def _node_xml(self, tag: str) -> str:
        return (
            f'<{tag} token="{NODE}" FixedHomePosition="true"><tt:Name>PTZ</tt:Name>'
            f"<tt:SupportedPTZSpaces>{self._spaces_xml()}</tt:SupportedPTZSpaces>"
            f"<tt:MaximumNumberOfPresets>{_MAX_PRESETS}</tt:MaximumNumberOfPresets>"
            f"<tt:HomeSupported>true</tt:HomeSupported></{tag}>"
        )

    def _get_service_capabilities(self, operation: Element) -> str:
        return f"<tptz:GetServiceCapabilitiesResponse>{self.capabilities_xml()}</tptz:GetServiceCapabilitiesResponse>"

    def _get_nodes(self, operation: Element) -> str:
        return f"<tptz:GetNodesResponse>{self._node_xml('tptz:PTZNode')}</tptz:GetNodesResponse>"

    def _get_node(self, operation: Element) -> str:
        require_token(operation, "NodeToken", NODE, "NoEntity")
        return f"<tptz:GetNodeResponse>{self._node_xml('tptz:PTZNode')}</tptz:GetNodeResponse>"

    def _get_configurations(self, operation: Element) -> str:
        configuration = self.configuration_xml("tptz:PTZConfiguration")
        return f"<tptz:GetConfigurationsResponse>{configuration}</tptz:GetConfigurationsResponse>"

    def _get_configuration(self, operation: Element) -> str:
        require_token(operation, "PTZConfigurationToken", CONFIGURATION, "NoConfig")
        configuration = self.configuration_xml("tptz:PTZConfiguration")
        return f"<tptz:GetConfigurationResponse>{configuration}</tptz:GetConfigurationResponse>"

    def _get_compatible_configurations(self, operation: Element) -> str:
        self._profile(operation)
        configuration = self.configuration_xml("tptz:PTZConfiguration")
        return f"<tptz:GetCompatibleConfigurationsResponse>{configuration}</tptz:GetCompatibleConfigurationsResponse>"

    def _get_configuration_options(self, operation: Element) -> str:
        require_token(operation, "ConfigurationToken", CONFIGURATION, "NoConfig")
        return (
            "<tptz:GetConfigurationOptionsResponse><tptz:PTZConfigurationOptions>"
            f"<tt:Spaces>{self._spaces_xml()}</tt:Spaces>"
            f"<tt:PTZTimeout><tt:Min>PT0S</tt:Min><tt:Max>PT{MAX_TIMEOUT_S:g}S</tt:Max></tt:PTZTimeout>"
            "</tptz:PTZConfigurationOptions></tptz:GetConfigurationOptionsResponse>"
        )

    # Status and moves.

    def _get_status(self, operation: Element) -> str:
        self._profile(operation)
        _, pose, moving = self.head.now()
        pan_tilt, zoom = ("MOVING" if axes else "IDLE" for axes in (moving[0] or moving[1], moving[2]))
        utc = datetime.now(UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")
        position = _position_xml("tt:Position", self.spaces.normalised(pose)) if self.positions else ""
        return (
            f"<tptz:GetStatusResponse><tptz:PTZStatus>{position}"
            f"<tt:MoveStatus><tt:PanTilt>{pan_tilt}</tt:PanTilt><tt:Zoom>{zoom}</tt:Zoom></tt:MoveStatus>"
            f"<tt:UtcTime>{utc}</tt:UtcTime></tptz:PTZStatus></tptz:GetStatusResponse>"
        )

    def _absolute_move(self, operation: Element) -> str:
        self._profile(operation)
        if not self.absolute_moves:
            raise Fault(
                "Receiver",
                ["ter:ActionNotSupported", "ter:OptionalActionNotSupported"],
                "AbsoluteMove is not supported: the PTZ node has no absolute position space",
            )
        pan_tilt, zoom = self._vector(operation, "Position", [PAN_TILT_POSITION], ZOOM_POSITION)
        position = [*(pan_tilt[:2] if pan_tilt else (None, None)), zoom]
        lowest, highest = (-1.0, -1.0, 0.0), (1.0, 1.0, 1.0)
        for axis, value in enumerate(position):
            if value is not None and not lowest[axis] <= value <= highest[axis]:
                raise invalid("InvalidPosition", f"Position {value} is not in [{lowest[axis]}, {highest[axis]}]")
        speed = self._speed(operation)
        self.head.move_to(self._target(position), speed)
        return "<tptz:AbsoluteMoveResponse/>"

    def _relative_move(self, operation: Element) -> str:
        self._profile(operation)
        spaces = [PAN_TILT_TRANSLATION] + ([] if self.f_min_px is None else [PAN_TILT_FOV])
        pan_tilt, zoom = self._vector(operation, "Translation", spaces, ZOOM_TRANSLATION)
        for value in [*(pan_tilt[:2] if pan_tilt else ()), *([] if zoom is None else [zoom])]:
            if not -1.0 <= value <= 1.0:
                raise invalid("InvalidTranslation", f"Translation {value} is not in [-1, 1]")
        speed = self._speed(operation)
        _, pose, _ = self.head.now()
        here = self.spaces.normalised(pose)
        target: list[float | None] = [None, None, None]
        if pan_tilt is not None and pan_tilt[2] == PAN_TILT_FOV and self.f_min_px is not None:
            target[:2] = fov_target(pose, pan_tilt[:2], self.image_size_px, self.f_min_px).tolist()
        elif pan_tilt is not None:
            moved = [float(np.clip(here[axis] + pan_tilt[axis], -1.0, 1.0)) for axis in (0, 1)]
            target[:2] = self._target([*moved, None])[:2]
        if zoom is not None:
            target[2] = self._target([None, None, float(np.clip(here[2] + zoom, 0.0, 1.0))])[2]
        self.head.move_to(target, speed)
        return "<tptz:RelativeMoveResponse/>"

    def _continuous_move(self, operation: Element) -> str:
        self._profile(operation)
        pan_tilt, zoom = self._vector(operation, "Velocity", [PAN_TILT_VELOCITY], ZOOM_VELOCITY)
        velocity = [*(pan_tilt[:2] if pan_tilt else (None, None)), zoom]
        if not all(-1.0 <= value <= 1.0 for value in velocity if value is not None):
            raise invalid("InvalidVelocity", f"Velocity {velocity} is not in [-1, 1]")
        model = [
            None if value is None else value * sign for value, sign in zip(velocity, self._directions, strict=True)
        ]
        self.head.run(model, self._timeout_s(operation))
        return "<tptz:ContinuousMoveResponse/>"

    def _timeout_s(self, operation: Element) -> float:
        """The Timeout (xs:duration, days to seconds) in seconds, the default if not given."""
        text = child_text(operation, "Timeout")
        if text is None:
            return DEFAULT_TIMEOUT_S
        match = re.fullmatch(_DURATION, text)
        if match is None:
            raise invalid("TimeoutNotSupported", f"Timeout {text!r} is not an xs:duration of days to seconds")
        days, hours, minutes, seconds = (float(part or 0.0) for part in match.groups())
        timeout_s = ((days * 24.0 + hours) * 60.0 + minutes) * 60.0 + seconds
        if timeout_s > MAX_TIMEOUT_S:
            raise invalid("TimeoutNotSupported", f"Timeout {text} is more than PT{MAX_TIMEOUT_S:g}S")
        return timeout_s

    def _stop(self, operation: Element) -> str:
        self._profile(operation)
        pan_tilt, zoom = (child_text(operation, axis) in (None, "true", "1") for axis in ("PanTilt", "Zoom"))
        self.head.stop([pan_tilt, pan_tilt, zoom])
        return "<tptz:StopResponse/>"

    def _goto_home_position(self, operation: Element) -> str:
        self._profile(operation)
        self.head.move_to(list(self.home_pose), self._speed(operation))
        return "<tptz:GotoHomePositionResponse/>"

    # Presets, in memory and in the presets file.

    def _keep(self, presets: dict[str, tuple[str, np.ndarray]]) -> None:
        """Write ``presets`` into the presets file (if any) and make them the presets; the presets lock held."""
        if self.presets_path is not None:
            document = {
                "presets": [
                    {"token": token, "name": name, "pose": [float(value) for value in pose]}
                    for token, (name, pose) in presets.items()
                ]
            }
            try:
                write_atomically(self.presets_path, (json.dumps(document, indent=1) + "\n").encode())
            except OSError as error:
                raise Fault("Receiver", ["ter:Action"], f"the presets could not be kept: {error.strerror}") from None
        self._presets = presets

    def _set_preset(self, operation: Element) -> str:
        self._profile(operation)
        token, name = child_text(operation, "PresetToken") or "", child_text(operation, "PresetName") or ""
        _, pose, _ = self.head.now()
        with self._presets_lock:
            if token and token not in self._presets:
                raise invalid("NoToken", f"no PresetToken {token!r}")
            if not token:
                if len(self._presets) >= _MAX_PRESETS:
                    raise Fault("Receiver", ["ter:Action", "ter:TooManyPresets"], f"at most {_MAX_PRESETS} presets")
                token, self._next_preset = str(self._next_preset), self._next_preset + 1
            self._keep({**self._presets, token: (name or token, pose)})
        return f"<tptz:SetPresetResponse><tptz:PresetToken>{escape(token)}</tptz:PresetToken></tptz:SetPresetResponse>"

    def _get_presets(self, operation: Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            presets = list(self._presets.items())
        return (
            "<tptz:GetPresetsResponse>"
            + "".join(
                f"<tptz:Preset token={quoteattr(token)}><tt:Name>{escape(name)}</tt:Name>"
                f"{_position_xml('tt:PTZPosition', self.spaces.normalised(pose)) if self.positions else ''}"
                "</tptz:Preset>"
                for token, (name, pose) in presets
            )
            + "</tptz:GetPresetsResponse>"
        )

    def _preset(self, operation: Element) -> str:
        token = child_text(operation, "PresetToken") or ""
        if token not in self._presets:
            raise invalid("NoToken", f"no PresetToken {token!r}")
        return token

    def _goto_preset(self, operation: Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            _, pose = self._presets[self._preset(operation)]
        self.head.move_to(list(pose), self._speed(operation))
        return "<tptz:GotoPresetResponse/>"

    def _remove_preset(self, operation: Element) -> str:
        self._profile(operation)
        with self._presets_lock:
            token = self._preset(operation)
            self._keep({key: preset for key, preset in self._presets.items() if key != token})
        return "<tptz:RemovePresetResponse/>"


def _number(part: Element, element: str, name: str) -> float:
    """The finite number in attribute ``name`` of ``part`` (a PanTilt or Zoom of ``element``)."""
    text = part.get(name)
    tag = part.tag.rpartition("}")[2]
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise invalid(f"Invalid{element}", f"{element}.{tag} needs a finite number {name}, not {text!r}")
    return value
