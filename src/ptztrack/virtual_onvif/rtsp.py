"""RTSP for the virtual ONVIF camera: ipycam's ffmpeg-backed server on 127.0.0.1, RTP over TCP or UDP.

Each session's ffmpeg encodes the images to H.264 and sends RTP and RTCP to two UDP sockets of this
process on 127.0.0.1, from which forwarder threads pass each datagram on: inside the RTSP connection
(TCP-interleaved, RFC 2326 10.12) or, for RTP/AVP over UDP, from two UDP sockets bound to 127.0.0.1
(the SETUP answer's server_port) to the client_port pair of the client's Transport header on
127.0.0.1. Every socket, ffmpeg's included, is bound to 127.0.0.1. RTSP has no authentication.
"""

import contextlib
import logging
import re
import secrets
import socket
import threading
from dataclasses import dataclass

from ipycam import NativeRTSPServer
from ipycam.rtsp import RTSPSession, RTSPState

from ptztrack.names import LOOPBACK

log = logging.getLogger("ptztrack.onvif_server")

HOST = LOOPBACK
# The session timeout the SETUP answers give (s): clients keep the session alive within it.
SESSION_TIMEOUT_S = 60.0
# What stop() waits for each thread: the longest is an ffmpeg encoder's exit (ipycam waits 2 s for it).
_JOIN_S = 5.0
_RTP, _RTCP = 0, 1  # the forwarders' channels of a UDP session


@dataclass
class _UDPPeer:
    """A UDP session's sockets on 127.0.0.1 and the client's (RTP, RTCP) ports it sends to."""

    sockets: tuple[socket.socket, socket.socket]
    client_ports: tuple[int, int]


class RTSPServer(NativeRTSPServer):
    """ipycam's RTSP server on 127.0.0.1 with RTP over UDP too, and a stop() that ends it all."""

    def __init__(self) -> None:
        super().__init__(port=0, host=HOST)
        self._threads_lock = threading.Lock()
        self._clients: set[tuple[threading.Thread, socket.socket]] = set()
        self._forwarders: set[threading.Thread] = set()
        self._udp: dict[str, _UDPPeer] = {}  # session id -> its UDP sockets

    def start(self) -> bool:
        started = super().start()
        if started:
            self.port = self._server_socket.getsockname()[1]
        return started

    def _handle_setup(self, uri, stream_name, headers, cseq, client_socket, client_address, session_id):
        # The first transport the client lists is the one it prefers.
        transport = headers.get("Transport", "").split(",")[0]
        profile = transport.split(";")[0].strip().upper()
        if profile == "RTP/AVP/TCP" or "interleaved" in transport:
            return super()._handle_setup(uri, stream_name, headers, cseq, client_socket, client_address, session_id)
        ports = re.search(r"client_port=(\d+)-(\d+)", transport)
        if profile not in ("RTP/AVP", "RTP/AVP/UDP") or "multicast" in transport or ports is None:
            return self._error_response(461, "Unsupported Transport", cseq), session_id
        return self._setup_udp(stream_name, cseq, client_socket, client_address, session_id, ports)

    def _setup_udp(self, stream_name, cseq, client_socket, client_address, session_id, ports):
        """SETUP of RTP/AVP over UDP: two sockets on 127.0.0.1 that will send to the client's ports."""
        session_id = session_id or secrets.token_hex(8)
        session = self._sessions.get(session_id)
        if session is None:
            session = RTSPSession(session_id, client_socket, client_address, ssrc=secrets.randbits(32))
            with self._lock:
                self._sessions[session_id] = session
        peer = self._udp.get(session_id)
        if peer is None:
            pair = []
            for _ in range(2):
                udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                udp.bind((HOST, 0))
                pair.append(udp)
            peer = self._udp[session_id] = _UDPPeer((pair[0], pair[1]), (int(ports[1]), int(ports[2])))
        # ipycam's encoder loop relays through local sockets (ffmpeg -> forwarders) only for interleaved
        # sessions; a UDP session is relayed likewise, its forwarders sending datagrams (_tcp_rtp_forwarder).
        session.interleaved, session.interleaved_channel, session.interleaved_channel_rtcp = True, _RTP, _RTCP
        session.state, session.stream_name = RTSPState.READY, stream_name
        server_ports = "-".join(str(udp.getsockname()[1]) for udp in peer.sockets)
        log.debug(
            "RTSP session %s: RTP over UDP from %s:%s to ports %d-%d",
            session_id,
            HOST,
            server_ports,
            *peer.client_ports,
        )
        session.transport = f"RTP/AVP;unicast;client_port={ports[1]}-{ports[2]};server_port={server_ports}"
        return (
            f"RTSP/1.0 200 OK\r\nCSeq: {cseq}\r\nSession: {session_id};timeout={SESSION_TIMEOUT_S:g}\r\n"
            f"Transport: {session.transport}\r\n\r\n"
        ), session_id

    def _build_ffmpeg_rtp_cmd_tcp_local(self, stream_info, local_port, rtcp_port=None):
        # Progress lines would fill ffmpeg's unread error pipe and stall it; its sockets bind 127.0.0.1.
        command = super()._build_ffmpeg_rtp_cmd_tcp_local(stream_info, local_port, rtcp_port)
        command[1:1] = ["-nostats", "-loglevel", "error"]
        command[-1] += ("&" if "?" in command[-1] else "?") + f"localaddr={HOST}"
        return command

    def _handle_client(self, client_socket, client_address):
        # ipycam ends a session whose connection is silent for its 30 s receive timeout; clients keep it
        # alive within the session timeout the SETUP gave.
        client_socket.settimeout(SESSION_TIMEOUT_S + 5.0)
        client = (threading.current_thread(), client_socket)
        with self._threads_lock:
            self._clients.add(client)
        try:
            super()._handle_client(client_socket, client_address)
        finally:
            with self._threads_lock:
                self._clients.discard(client)

    def _tcp_rtp_forwarder(self, local_socket, session, channel=None):
        with self._threads_lock:
            self._forwarders.add(threading.current_thread())
        try:
            peer = self._udp.get(session.session_id)
            if peer is None:
                super()._tcp_rtp_forwarder(local_socket, session, channel)
            else:
                self._udp_forwarder(local_socket, session, peer, channel)
        finally:
            with self._threads_lock:
                self._forwarders.discard(threading.current_thread())

    def _udp_forwarder(self, local_socket: socket.socket, session: RTSPSession, peer: _UDPPeer, channel: int) -> None:
        """Pass ffmpeg's datagrams of ``channel`` (RTP or RTCP) on to the client's port, while the session plays."""
        sender, port = peer.sockets[channel], peer.client_ports[channel]
        while self._is_running and session.state == RTSPState.PLAYING:
            try:
                data = local_socket.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return  # the session was closed under us
            try:
                sender.sendto(data, (HOST, port))
            except OSError as error:  # the session was closed under us
                log.debug("RTSP session %s: UDP forwarding to port %d stopped: %s", session.session_id, port, error)
                return

    def _close_session(self, session) -> None:
        session.state = RTSPState.TEARDOWN  # ends the session's encoder loop, which then ends its ffmpeg
        for key, thread in list(self._rtp_threads.items()):
            if key.startswith(session.session_id):
                thread.join(_JOIN_S)
        super()._close_session(session)
        peer = self._udp.pop(session.session_id, None)
        for udp in () if peer is None else peer.sockets:
            udp.close()

    def stop(self) -> None:
        # Not running first, so that the accept loop takes the shutdown below for the end.
        self._is_running = False
        if self._server_socket is not None:
            with contextlib.suppress(OSError):
                self._server_socket.shutdown(socket.SHUT_RDWR)  # wakes accept() at once, not after its 1 s poll
        super().stop()  # ends the sessions and their ffmpeg encoders, closes the listening socket
        with self._threads_lock:
            clients, forwarders = list(self._clients), list(self._forwarders)
        for _, client_socket in clients:
            with contextlib.suppress(OSError):
                client_socket.shutdown(socket.SHUT_RDWR)  # wakes its thread's recv()
        for thread in [
            self._accept_thread,
            *(thread for thread, _ in clients),
            *self._rtp_threads.values(),
            *forwarders,
        ]:
            if thread is not None:
                thread.join(_JOIN_S)
