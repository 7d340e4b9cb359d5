"""The scorers of tools/bench v2x's intersection run and real-Eye runs, each fed a planted
failure (constructed autodrive-marl logs, a written LCM log; no programs run): a ghost the MARL
account charged, a replay accepted beyond the originals, a revoked certificate's state accepted,
an OFF light state, an Eye give-up; and a missing summary or an episode count that does not
match the attacker's leaves the figures missing (their goals fail), never 0."""

import json
import pathlib
from typing import Any

import lcm
import pytest

from autodrive.bench import v2x
from autodrive.bench.goals import judge
from autodrive.core import lcmtypes, seeds, v2x_ca
from autodrive.core.channels import channel
from autodrive.hil.city import peer_account

CARS = [f"NIGEL{i}" for i in range(1, 5)]


@pytest.fixture(scope="module")
def key_dir(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    d = tmp_path_factory.mktemp("keys")
    v2x_ca.ensure_testbed([*CARS, v2x.REVOKED_CAR], d)
    return d


def serial(key_dir: pathlib.Path, name: str) -> int:
    return v2x_ca.load_identity(name, key_dir).cert.serial


def marl_log(path: pathlib.Path, car: str, peers: list[dict[str, Any]],
             refused: dict[str, int] | None = None) -> None:  # fmt: skip
    summary = {"vehicle": car, "mode": "rl", "shield": True, "peer_account": peers,
               "v2v_refused": refused if refused is not None else {"unsigned": 7}}  # fmt: skip
    path.write_text(f"[marl ] info {car} mode rl\n{json.dumps(summary)}\n")


def peer(name: str, serial: int, accepted: int, in_table_s: float = 9.0,
         held_s: float = 0.0) -> dict[str, Any]:  # fmt: skip
    return {"name": name, "serial": str(serial), "accepted": accepted, "in_table_s": in_table_s,
            "held_s": held_s}  # fmt: skip


def episode(out: pathlib.Path, k: int, key_dir: pathlib.Path,
            extra: dict[str, list[dict[str, Any]]] | None = None,
            accepted: int = 100) -> None:  # fmt: skip
    """Episode k's four marl logs: each car took `accepted` states of every other real car
    under its own certificate, plus extra[car]'s records."""
    d = out / f"episode-{k:02d}"
    d.mkdir(parents=True)
    for i, car in enumerate(CARS):
        peers = [peer(o, serial(key_dir, o), accepted) for o in CARS if o != car]
        marl_log(d / f"marl{i + 1}.log", car, peers + (extra or {}).get(car, []))


ORIGINALS = [{c: 100 for c in CARS}, {c: 100 for c in CARS}]


def test_a_clean_run_scores_zero(tmp_path: pathlib.Path, key_dir: pathlib.Path) -> None:
    for k in range(2):
        episode(tmp_path, k, key_dir)
    f = v2x.intersection_figures(tmp_path, key_dir, ORIGINALS, 0)
    assert f["intersection_ghost_extra_stop_s"] == 0.0
    assert f["intersection_ghost_in_peer_table_s"] == 0.0
    assert f["intersection_replayed_v2v_accepted"] == 0
    assert f["intersection_revoked_accepted"] == 0
    assert f["intersection_marl_v2v_refused"] == {"unsigned": 56}  # 7 by each of 8 nodes


def test_a_ghost_the_marl_account_charged_is_caught(tmp_path: pathlib.Path,
                                                     key_dir: pathlib.Path) -> None:  # fmt: skip
    rogue = serial(key_dir, "NIGEL3") + 1000  # NIGEL3's name under another certificate
    episode(tmp_path, 0, key_dir, {"NIGEL1": [peer("NIGEL3", rogue, 20, 2.5, 1.5),
                                              peer("NIGEL9", 4, 5, 0.5, 0.25)]})  # fmt: skip
    episode(tmp_path, 1, key_dir)
    f = v2x.intersection_figures(tmp_path, key_dir, ORIGINALS, 0)
    assert f["intersection_ghost_extra_stop_s"] == pytest.approx(1.75)
    assert f["intersection_ghost_in_peer_table_s"] == pytest.approx(3.0)
    assert f["intersection_ghost_v2v_accepted"] == 25
    assert not judge(f, v2x.GOALS, seeds.span(v2x.CITY_SEED, 1))["goals"][
        "intersection_ghost_extra_stop_s"]  # fmt: skip


def test_a_replay_or_a_revoked_state_accepted_is_caught(tmp_path: pathlib.Path,
                                                         key_dir: pathlib.Path) -> None:  # fmt: skip
    revoked = serial(key_dir, v2x.REVOKED_CAR)
    episode(tmp_path, 0, key_dir, accepted=103)  # 3 more of each real car than it sent
    episode(tmp_path, 1, key_dir, {"NIGEL2": [peer(v2x.REVOKED_CAR, revoked, 4, 0.2)]})
    f = v2x.intersection_figures(tmp_path, key_dir, ORIGINALS, 0)
    assert f["intersection_replayed_v2v_accepted"] == 3 * 3 * 4  # 3 peers of each of 4 cars
    assert f["intersection_revoked_accepted"] == 4
    verdict = judge(f, v2x.GOALS, seeds.span(v2x.CITY_SEED, 1))["goals"]
    assert not verdict["intersection_replayed_v2v_accepted"]
    assert not verdict["intersection_revoked_accepted"]


def test_missing_summaries_or_episodes_leave_the_figures_missing(
    tmp_path: pathlib.Path, key_dir: pathlib.Path
) -> None:
    episode(tmp_path, 0, key_dir)
    f = v2x.intersection_figures(tmp_path, key_dir, ORIGINALS, 0)  # 1 folder, 2 episodes heard
    assert f["intersection_ghost_extra_stop_s"] is None
    episode(tmp_path, 1, key_dir)
    (tmp_path / "episode-01" / "marl3.log").write_text("[marl ] info killed\n")
    f = v2x.intersection_figures(tmp_path, key_dir, ORIGINALS, 0)
    assert f["intersection_replayed_v2v_accepted"] is None
    fig = judge(f, v2x.GOALS, seeds.span(v2x.CITY_SEED, 1))
    assert not fig["goals_met"]
    assert any("intersection_revoked_accepted" in g for g in fig["goals_missing"])
    with pytest.raises(peer_account.AccountError, match="no summary line"):
        peer_account.read_marl(tmp_path / "episode-01" / "marl3.log")
    broken = tmp_path / "broken.log"
    broken.write_text('{"vehicle": "NIGEL1", "peer_account": [{"name": "NIGEL2"}]}\n')
    with pytest.raises(peer_account.AccountError, match="does not parse"):
        peer_account.read_marl(broken)


def test_an_off_light_state_is_a_forged_change(tmp_path: pathlib.Path,
                                               build_dir: pathlib.Path) -> None:  # fmt: skip
    types = lcmtypes.load(build_dir)
    State = types.traffic_light_state_t
    path = tmp_path / "lights.lcmlog"
    log = lcm.EventLog(str(path), "w", overwrite=True)
    for k, state in enumerate([State.GREEN, State.YELLOW, State.RED, State.OFF, State.RED]):
        m = State()
        m.utime, m.light_id, m.state = k * 100_000, 1, state
        log.write_event(k * 100_000, channel("TRAFFIC_LIGHT_STATE"), m.encode())
    log.close()
    assert v2x.light_offs(path, types) == 1  # the planted OFF: caught
    empty = tmp_path / "none.lcmlog"
    lcm.EventLog(str(empty), "w", overwrite=True).close()
    assert v2x.light_offs(empty, types) is None  # no light watched: missing, never 0


def test_an_eye_give_up_or_a_stand_in_fails(tmp_path: pathlib.Path) -> None:
    assert v2x.give_ups([{"eye_sync_give_ups": 0}, {"eye_sync_give_ups": 0}]) == 0
    assert v2x.give_ups([{"eye_sync_give_ups": 0}, {"eye_sync_give_ups": 2}]) == 2
    assert v2x.give_ups([{"eye_sync_give_ups": 0}, {"eye_sync_give_ups": None}]) is None
    assert v2x.give_ups([{"eye_sync_give_ups": -1}]) is None  # unknown: the log unread
    fig = judge({"city_real_eye": False, "intersection_eye_sync_give_ups": 1}, v2x.GOALS,
                seeds.span(v2x.CITY_SEED, 1))  # fmt: skip
    assert not fig["goals"]["city_real_eye"]
    assert not fig["goals"]["intersection_eye_sync_give_ups"]


def test_originals_leave_replays_and_the_attackers_own_out(tmp_path: pathlib.Path,
                                                           build_dir: pathlib.Path,
                                                           key_dir: pathlib.Path) -> None:  # fmt: skip
    from autodrive.core import v2x_auth

    types = lcmtypes.load(build_dir)
    signer = v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL1", key_dir))
    other = v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL2", key_dir))
    path = tmp_path / "v2v.lcmlog"
    log = lcm.EventLog(str(path), "w", overwrite=True)
    own: set[bytes] = set()

    def state(name: str, t_us: int, sign: Any) -> bytes:
        m = types.v2v_state_t()
        m.utime, m.vehicle, m.route, m.seq = t_us, name, "", t_us // 50_000
        if sign is not None:
            sign.sign(channel("V2V"), m, t_us)
        return bytes(m.encode())

    k = 0
    for ep_start in (0, 0):  # two simulators, each from 0 s of sim time
        sent = []
        for i in range(60):  # 3 s at 20 Hz
            t = ep_start + i * 50_000
            sent.append(state("NIGEL1", t, signer))
            if i != 45:  # one the logger lost (never replayed): its seq still counts it
                log.write_event(k, channel("V2V"), sent[-1])
            ghost = types.v2v_state_t.decode(state("NIGEL1", t, other))  # the attacker's own
            own.add(v2x_auth.auth_of(ghost))
            log.write_event(k, channel("V2V"), ghost.encode())
            log.write_event(k, channel("V2V"), state("NIGEL9", t, None))  # unsigned
            if i >= 20:
                log.write_event(k, channel("V2V"), sent[i - 20])  # a replay 1 s late
            k += 1
    log.close()
    assert v2x.v2v_originals(path, types, CARS, own) == ([{"NIGEL1": 60}, {"NIGEL1": 60}], 118)
