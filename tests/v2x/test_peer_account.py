"""The city drivers' per-peer accounts as tools/bench v2x reads them (autodrive.hil.city.
peer_account): a ghost is a name no real car has or a real name under another certificate; its
held and in-table seconds are summed, real cars' are not; a log without an account (a driver
that did not stop cleanly) or with a broken one is an error naming the file, never 0 s."""

import json
import pathlib

import pytest

from autodrive.hil.city import peer_account

REAL = {"NIGEL1": 11, "NIGEL2": 22}


def driver_log(tmp: pathlib.Path, car: str, records: list[dict[str, object]]) -> pathlib.Path:
    path = tmp / f"city-driver-{car}.log"
    path.write_text(f"[city-driver] {car} t=2.0 s lap 0\n"
                    f"[city-driver] {car}: stopped; refused V2X messages: unsigned=4\n"
                    f"[city-driver] {car}: peer account: {json.dumps(records)}\n")  # fmt: skip
    return path


def rec(name: str, serial: int, in_table_s: float, held_s: float) -> dict[str, object]:
    return {"name": name, "serial": str(serial), "accepted": 3, "in_table_s": in_table_s,
            "held_s": held_s}  # fmt: skip


def test_ghosts_are_charged_and_real_cars_are_not(tmp_path: pathlib.Path) -> None:
    logs = [
        driver_log(tmp_path, "NIGEL1", [rec("NIGEL2", 22, 29.0, 4.0), rec("NIGEL2", 99, 1.5, 0.5)]),
        driver_log(tmp_path, "NIGEL2", [rec("NIGEL1", 11, 29.0, 0.0), rec("NIGEL9", 7, 2.0, 1.0)]),
    ]
    c = peer_account.charges(logs, REAL)
    assert c["ghost_held_s"] == pytest.approx(1.5)  # the planted ghosts: caught
    assert c["ghost_in_table_s"] == pytest.approx(3.5)
    assert c["ghost_accepted"] == 6
    assert c["real_peer_held_s"] == pytest.approx(4.0)
    clean = [driver_log(tmp_path, "NIGEL1", [rec("NIGEL2", 22, 29.0, 4.0)])]
    assert peer_account.charges(clean, REAL)["ghost_held_s"] == 0.0


def test_a_missing_or_broken_account_is_an_error(tmp_path: pathlib.Path) -> None:
    silent = tmp_path / "city-driver1.log"
    silent.write_text("[city-driver] NIGEL1 t=2.0 s lap 0\n")  # killed before its last words
    with pytest.raises(peer_account.AccountError, match="no peer account line"):
        peer_account.charges([silent], REAL)
    broken = tmp_path / "city-driver2.log"
    broken.write_text('[city-driver] NIGEL2: peer account: [{"name": "NIGEL1"}]\n')
    with pytest.raises(peer_account.AccountError, match="does not parse"):
        peer_account.read(broken)
