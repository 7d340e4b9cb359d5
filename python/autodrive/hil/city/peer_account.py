"""The city drivers' per-peer accounts, read from their logs: for each V2V peer a driver ever
accepted (by name and the serial of the certificate that signed it), the messages accepted, the
seconds of car time the peer was in its fresh peer table and the seconds it was the reason the
car held or slowed (autodrive::v2v::PeerAccount, printed once as the driver stops:
"[city-driver] NIGEL1: peer account: [...]"). A ghost is any peer that is not a real car: a name
no car has, or a real name under another certificate than that car's own."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

ACCOUNT_LINE = re.compile(r"^\[city-driver\] (\S+): peer account: (\[.*\])\s*$")


class AccountError(ValueError):
    """A driver log without its peer account, or with one that does not parse; the message
    names the file."""


@dataclass(frozen=True)
class PeerRecord:
    car: str  # the receiving car
    name: str  # the peer's name
    serial: int  # its certificate's serial
    accepted: int  # states accepted [count]
    in_table_s: float  # [s of car time] in the fresh peer table
    held_s: float  # [s of car time] the reason the car held or slowed


def read(log: Path) -> list[PeerRecord]:
    """The peer account of one driver's log; AccountError when the log has none (the driver
    did not stop cleanly: nothing measured) or a broken one."""
    for line in reversed(log.read_text(errors="replace").splitlines()):
        m = ACCOUNT_LINE.match(line)
        if not m:
            continue
        try:
            return [
                PeerRecord(m.group(1), str(r["name"]), int(r["serial"]), int(r["accepted"]),
                           float(r["in_table_s"]), float(r["held_s"]))
                for r in json.loads(m.group(2))
            ]  # fmt: skip
        except (ValueError, KeyError, TypeError) as e:
            raise AccountError(f"{log}: the peer account does not parse: {e}") from e
    raise AccountError(f"{log}: no peer account line (the driver did not stop cleanly)")


def ghosts(records: list[PeerRecord], real: dict[str, int]) -> list[PeerRecord]:
    """The records of peers that are not real cars; real: each real car's name -> its
    certificate's serial."""
    return [r for r in records if real.get(r.name) != r.serial]


def charges(logs: list[Path], real: dict[str, int]) -> dict[str, float | int]:
    """Over every driver log: the held and in-table seconds and the accepted messages of ghost
    peers, and the held seconds real peers caused (AccountError when a log has no account)."""
    records = [r for log in logs for r in read(log)]
    fake = ghosts(records, real)
    return {
        "ghost_held_s": sum(r.held_s for r in fake),
        "ghost_in_table_s": sum(r.in_table_s for r in fake),
        "ghost_accepted": sum(r.accepted for r in fake),
        "real_peer_held_s": sum(r.held_s for r in records if r not in fake),
    }


def read_marl(log: Path) -> tuple[list[PeerRecord], dict[str, int]]:
    """An autodrive-marl log's per-peer account and its V2V refusals by reason [count] (its
    summary, the last JSON line, printed as it stops: "peer_account" and "v2v_refused");
    AccountError when the log has no summary (the node did not stop cleanly) or a broken one."""
    for line in reversed(log.read_text(errors="replace").splitlines()):
        if not line.startswith("{"):
            continue
        try:
            s = json.loads(line)
            car = str(s["vehicle"])
            records = [
                PeerRecord(car, str(r["name"]), int(r["serial"]), int(r["accepted"]),
                           float(r["in_table_s"]), float(r["held_s"]))
                for r in s["peer_account"]
            ]  # fmt: skip
            refused = {str(k): int(v) for k, v in s["v2v_refused"].items()}
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            raise AccountError(f"{log}: the summary's peer account does not parse: {e}") from e
        return records, refused
    raise AccountError(f"{log}: no summary line (autodrive-marl did not stop cleanly)")


def replays_accepted(
    records: list[PeerRecord], real: dict[str, int], originals: dict[str, int]
) -> int:
    """States of real cars one receiver accepted beyond the originals those cars sent (each an
    envelope of its own; originals: per car name, in the receiver's run) [count]: a receiver
    takes an original once, so anything more is a replay that got in. (A replay accepted in
    place of an original the receiver lost is not seen: on loopback none is lost.)"""
    extra = 0
    for r in records:
        if real.get(r.name) == r.serial:
            extra += max(0, r.accepted - originals.get(r.name, 0))
    return extra
