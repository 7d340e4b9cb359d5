"""LCM's UDP multicast packets read and written by hand, for what the lcm library does not do:
write a packet as a hostile plain-UDP sender would (bench security), and read the kernel's
receive time of each packet (bench eye_latency: when a message reached the bus, whoever reads
it later).

A small message is one datagram: "LC02", a sequence number, the channel, NUL, the payload.
Larger ones come in "LC03" fragments, which WireTap skips."""

from __future__ import annotations

import select
import socket
import struct
import threading
from collections.abc import Callable
from urllib.parse import urlparse

MAGIC_SHORT = 0x4C433032  # "LC02"
HEADER = struct.Struct(">II")  # magic, sequence number
SCM_TIMESTAMPNS = getattr(socket, "SCM_TIMESTAMPNS", 35)  # Linux: SO_TIMESTAMPNS's cmsg type
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
TIMESPEC = struct.Struct("@qq")  # tv_sec, tv_nsec


def packet(channel: str, data: bytes, seqno: int) -> bytes:
    """One LCM small message: what a plain UDP sender writes to look like a publisher."""
    return HEADER.pack(MAGIC_SHORT, seqno) + channel.encode() + b"\0" + data


def parse_short(datagram: bytes) -> tuple[str, bytes] | None:
    """(channel, payload) of a small message; None for a fragment or anything else."""
    if len(datagram) < HEADER.size or HEADER.unpack_from(datagram)[0] != MAGIC_SHORT:
        return None
    end = datagram.find(b"\0", HEADER.size)
    if end < 0:
        return None
    return datagram[HEADER.size : end].decode(errors="replace"), datagram[end + 1 :]


def group_and_port(url: str) -> tuple[str, int]:
    """The multicast group and port of a udpm:// URL; ValueError naming it otherwise."""
    u = urlparse(url)
    if u.scheme != "udpm" or not u.hostname or not u.port:
        raise ValueError(f"{url}: not a udpm://group:port URL")
    return u.hostname, u.port


class WireTap:
    """Small messages of an LCM udpm bus with the kernel's receive time [us, system clock] of
    each: the time the message was on the bus (for loopback, when the sender's kernel handed
    it over), not when this process got round to reading it. Calls on_message(channel,
    payload, receive_us) on its own thread until close()."""

    def __init__(
        self,
        url: str,
        on_message: Callable[[str, bytes, int], None],
        recv_buf_bytes: int = 4 << 20,
    ) -> None:
        group, port = group_and_port(url)
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, recv_buf_bytes)
        s.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        s.bind(("", port))
        mreq = socket.inet_aton(group) + socket.inet_aton("0.0.0.0")
        s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        self.sock, self.on_message = s, on_message
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._pump, daemon=True)
        self.thread.start()

    def _pump(self) -> None:
        cmsg_bytes = socket.CMSG_SPACE(TIMESPEC.size)
        while not self.stop.is_set():
            if not select.select([self.sock], [], [], 0.02)[0]:
                continue
            data, anc, _flags, _addr = self.sock.recvmsg(65536, cmsg_bytes)
            msg = parse_short(data)
            stamps = [
                c for lvl, typ, c in anc if lvl == socket.SOL_SOCKET and typ == SCM_TIMESTAMPNS
            ]
            if msg is None or not stamps:
                continue
            sec, nsec = TIMESPEC.unpack_from(stamps[0])
            self.on_message(msg[0], msg[1], sec * 1_000_000 + nsec // 1000)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()
        self.sock.close()
