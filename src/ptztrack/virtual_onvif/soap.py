"""SOAP 1.2 for the virtual ONVIF camera: envelopes, faults, WS-Security UsernameToken and dispatch.

A request is a SOAP 1.2 envelope whose Body holds one operation, routed by its qualified name. A
fault is SOAP 1.2's (Part 1, 5.4: Code with Value env:Sender or env:Receiver and ONVIF's ``ter:``
subcodes, Reason with an ``xml:lang`` Text) and goes out with the HTTP status of SOAP 1.2's HTTP
binding (Part 2, 7): 400 for env:Sender, 500 for any other code.

WS-Security UsernameToken (OASIS Username Token Profile 1.0, which ONVIF Core requires):

    PasswordDigest = Base64(SHA-1(nonce + Created + password))

with ``nonce`` the Base64-decoded Nonce and Created its text, UTF-8. A token is accepted when the
user name and digest match, Created lies within ``window_s`` of the camera's clock either way, and
its nonce has not been accepted before while that nonce's Created was within the window (a replay).
A refused token is ONVIF Core's env:Sender ter:NotAuthorized with HTTP 400 (section "Authentication
over HTTP and HTTPS": a device that authenticates SOAP by UsernameToken only).
"""

import base64
import binascii
import hashlib
import heapq
import hmac
import logging
import threading
import time
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Collection, Mapping, Sequence
from datetime import UTC, datetime
from xml.sax.saxutils import escape

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import fromstring

log = logging.getLogger("ptztrack.onvif_server")

NAMESPACES = {
    "s": "http://www.w3.org/2003/05/soap-envelope",
    "tds": "http://www.onvif.org/ver10/device/wsdl",
    "trt": "http://www.onvif.org/ver10/media/wsdl",
    "tptz": "http://www.onvif.org/ver20/ptz/wsdl",
    "tt": "http://www.onvif.org/ver10/schema",
    "ter": "http://www.onvif.org/ver10/error",
}
TDS, TRT, TPTZ, TT = NAMESPACES["tds"], NAMESPACES["trt"], NAMESPACES["tptz"], NAMESPACES["tt"]
_SOAP = NAMESPACES["s"]
_SOAP_1_1 = "http://schemas.xmlsoap.org/soap/envelope/"
_WSSE = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-secext-1.0.xsd"
_WSU = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-wssecurity-utility-1.0.xsd"
_PASSWORD_DIGEST = "http://docs.oasis-open.org/wss/2004/01/oasis-200401-wss-username-token-profile-1.0#PasswordDigest"

# An operation: the request's Body child in, the answer's Body content (XML text, prefixes of NAMESPACES) out.
Operation = Callable[[ElementTree.Element], str]


class Fault(Exception):
    """A SOAP fault: ``code`` (Sender, Receiver or VersionMismatch), ONVIF ``subcodes`` (``ter:...``), ``reason``."""

    def __init__(self, code: str, subcodes: Sequence[str], reason: str):
        super().__init__(reason)
        self.code, self.subcodes, self.reason = code, list(subcodes), reason

    @property
    def http_status(self) -> int:
        """SOAP 1.2 HTTP binding: 400 Bad Request for env:Sender, 500 Internal Server Error otherwise."""
        return 400 if self.code == "Sender" else 500


def invalid(subcode: str, reason: str) -> Fault:
    """ONVIF's env:Sender ter:InvalidArgVal fault with the subcode ``ter:{subcode}``."""
    return Fault("Sender", ["ter:InvalidArgVal", f"ter:{subcode}"], reason)


def qualified_name(tag: str) -> tuple[str, str]:
    """(namespace, local name) of an ElementTree tag ``{namespace}name``."""
    namespace, _, name = tag.rpartition("}")
    return namespace.lstrip("{"), name


def child_text(operation: ElementTree.Element, name: str) -> str | None:
    """The stripped text of ``operation``'s child ``name`` (in the operation's own namespace), None if absent."""
    child = operation.find(f"{{{qualified_name(operation.tag)[0]}}}{name}")
    return None if child is None else (child.text or "").strip()


def require_token(operation: ElementTree.Element, element: str, token: str, subcode: str) -> None:
    """Refuse (``ter:{subcode}``) a request whose ``element`` is not ``token``."""
    given = child_text(operation, element)
    if given is None:
        raise invalid(subcode, f"{element} is missing")
    if given != token:
        raise invalid(subcode, f"no {element} {given!r}")


def envelope(body: str) -> bytes:
    """A SOAP 1.2 envelope around the Body content ``body``, every prefix of NAMESPACES declared."""
    declarations = " ".join(f'xmlns:{prefix}="{uri}"' for prefix, uri in NAMESPACES.items())
    text = f'<?xml version="1.0" encoding="UTF-8"?>\n<s:Envelope {declarations}><s:Body>{body}</s:Body></s:Envelope>'
    return text.encode()


def fault_envelope(fault: Fault) -> bytes:
    """The envelope of a SOAP 1.2 fault: the code, its subcodes nested in order, the reason in English."""
    subcodes = "".join(f"<s:Subcode><s:Value>{subcode}</s:Value>" for subcode in fault.subcodes)
    subcodes += "</s:Subcode>" * len(fault.subcodes)
    return envelope(
        f"<s:Fault><s:Code><s:Value>s:{fault.code}</s:Value>{subcodes}</s:Code>"
        f'<s:Reason><s:Text xml:lang="en">{escape(fault.reason)}</s:Text></s:Reason></s:Fault>'
    )


def _not_authorized(reason: str) -> Fault:
    return Fault("Sender", ["ter:NotAuthorized"], f"not authorized: {reason}")


def _parse_created_s(text: str) -> float:
    """POSIX seconds of an xs:dateTime (UTC where it gives no offset)."""
    try:
        created = datetime.fromisoformat(text)
    except ValueError:
        raise _not_authorized(f"wsu:Created {text!r} is not an xs:dateTime") from None
    return (created if created.tzinfo is not None else created.replace(tzinfo=UTC)).timestamp()


_TOKEN_FIELDS = (
    ("wsse", _WSSE, "Username"),
    ("wsse", _WSSE, "Password"),
    ("wsse", _WSSE, "Nonce"),
    ("wsu", _WSU, "Created"),
)


def _token_field(token: ElementTree.Element, prefix: str, namespace: str, name: str) -> ElementTree.Element:
    element = token.find(f"{{{namespace}}}{name}")
    if element is None:
        raise _not_authorized(f"the UsernameToken has no {prefix}:{name}")
    return element


class UsernameTokens:
    """Checks WS-Security UsernameTokens (PasswordDigest) and refuses replays (module docstring).

    window_s : how far (seconds) a token's Created may be from ``clock()`` either way, and how long an
        accepted nonce is remembered after its Created; clock : POSIX seconds now.
    ``len()`` is the number of nonces remembered: those accepted whose Created is within the window.
    """

    def __init__(self, username: str, password: str, window_s: float = 300.0, clock: Callable[[], float] = time.time):
        self._username, self._password = username, password
        self.window_s, self._clock = window_s, clock
        self._lock = threading.Lock()
        self._seen: dict[bytes, float] = {}  # nonce -> when it may be used again (its Created + window), POSIX s
        self._expiries: list[tuple[float, bytes]] = []  # a heap of the same

    def __len__(self) -> int:
        with self._lock:
            self._forget(self._clock())
            return len(self._seen)

    def verify(self, header: ElementTree.Element | None) -> None:
        """Accept the UsernameToken of the SOAP Header ``header`` or raise the ter:NotAuthorized Fault."""
        security = None if header is None else header.find(f"{{{_WSSE}}}Security")
        token = None if security is None else security.find(f"{{{_WSSE}}}UsernameToken")
        if token is None:
            raise _not_authorized("the request has no WS-Security UsernameToken")
        username, password, nonce_text, created_text = (
            _token_field(token, prefix, namespace, name) for prefix, namespace, name in _TOKEN_FIELDS
        )
        if password.get("Type") != _PASSWORD_DIGEST:
            raise _not_authorized("the UsernameToken's wsse:Password is not of Type PasswordDigest")
        created = (created_text.text or "").strip()
        try:
            nonce = base64.b64decode((nonce_text.text or "").strip(), validate=True)
        except binascii.Error:
            raise _not_authorized("wsse:Nonce is not Base64") from None
        digest = base64.b64encode(hashlib.sha1(nonce + created.encode() + self._password.encode()).digest())
        user_ok = hmac.compare_digest((username.text or "").strip().encode(), self._username.encode())
        digest_ok = hmac.compare_digest((password.text or "").strip().encode(), digest)
        if not (user_ok and digest_ok):
            raise _not_authorized("the user name or the password digest is wrong")
        now_s, created_s = self._clock(), _parse_created_s(created)
        if abs(now_s - created_s) > self.window_s:
            raise _not_authorized(f"wsu:Created {created} is more than {self.window_s:g} s from the camera's clock")
        with self._lock:
            self._forget(now_s)
            if nonce in self._seen:
                raise _not_authorized("wsse:Nonce was already used (a replayed UsernameToken)")
            self._seen[nonce] = created_s + self.window_s
            heapq.heappush(self._expiries, (created_s + self.window_s, nonce))

    def _forget(self, now_s: float) -> None:
        """Drop the nonces whose Created has left the window: a token carrying one is refused for its Created."""
        while self._expiries and self._expiries[0][0] < now_s:
            _, nonce = heapq.heappop(self._expiries)
            del self._seen[nonce]


def _parse(request: bytes) -> tuple[ElementTree.Element | None, ElementTree.Element]:
    """The Header (None if absent) and the Body's child of a SOAP 1.2 envelope."""
    try:
        # SOAP 1.2 forbids a DTD in a message (Part 1, 5); defusedxml refuses them and entity tricks.
        root = fromstring(request, forbid_dtd=True)
    except (ElementTree.ParseError, DefusedXmlException) as error:
        raise Fault(
            "Sender", ["ter:WellFormed"], f"the request is not well-formed XML without a DTD: {error}"
        ) from None
    if root.tag == f"{{{_SOAP_1_1}}}Envelope":
        raise Fault("VersionMismatch", [], "the envelope is SOAP 1.1; this camera speaks SOAP 1.2")
    body = root.find(f"{{{_SOAP}}}Body")
    if root.tag != f"{{{_SOAP}}}Envelope" or body is None or len(body) != 1:
        raise Fault(
            "Sender", ["ter:WellFormed"], "the request is not a SOAP 1.2 Envelope whose Body holds one operation"
        )
    return root.find(f"{{{_SOAP}}}Header"), body[0]


class SOAPService:
    """Answers SOAP requests: authenticates them, routes them to ``operations`` by qualified name
    ((namespace, local name) -> Operation) and turns refusals into faults.

    tokens : the UsernameToken check, None for no authentication; pre_auth : the operations answered
    without one (ONVIF Core's access class PRE_AUTH).
    """

    def __init__(
        self,
        operations: Mapping[tuple[str, str], Operation],
        tokens: UsernameTokens | None,
        pre_auth: Collection[tuple[str, str]],
    ):
        self.operations, self.tokens, self.pre_auth = operations, tokens, pre_auth

    def answer(self, request: bytes) -> tuple[int, bytes]:
        """(HTTP status, SOAP envelope) answering the envelope ``request``."""
        name = "a request"
        try:
            header, operation = _parse(request)
            key = qualified_name(operation.tag)
            name = key[1]
            if self.tokens is not None and key not in self.pre_auth:
                self.tokens.verify(header)
            if key not in self.operations:
                raise Fault("Receiver", ["ter:ActionNotSupported"], f"{name} is not supported")
            return 200, envelope(self.operations[key](operation))
        except Fault as fault:
            # A refused token is the one fault worth an operator's attention (a wrong password or an attack).
            level = logging.WARNING if "ter:NotAuthorized" in fault.subcodes else logging.DEBUG
            log.log(level, "refused %s: %s", name, fault.reason)
            return fault.http_status, fault_envelope(fault)
        except Exception:
            log.exception("%s failed", name)
            return 500, fault_envelope(Fault("Receiver", ["ter:Action"], f"the camera failed to answer {name}"))
