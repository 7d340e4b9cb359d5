"""tools/bench security's count of hostile commands the Nano applied (hostile_throttle_samples,
the source of unsigned_cmd_applied and wrong_key_cmd_applied) is shown to catch them, on
constructed <VEH>_STATE logs (no demo): an unsigned command held by the Nano is counted, and
counted as unsigned, not wrong-key; a legitimate slew passing through the same values is not;
and the security goals then fail."""

import pathlib

import lcm

from autodrive.bench import goals
from autodrive.bench import security
from autodrive.core import channels, lcmtypes, seeds


def write_log(path: pathlib.Path, types, applied: list[tuple[float, float]]) -> pathlib.Path:
    """A log of <VEH>_STATE samples at 100 Hz, each with (throttle, steering) applied."""
    log = lcm.EventLog(str(path), "w", overwrite=True)
    ch = channels.channel("STATE", security.VEHICLE)
    for k, (throttle, steering) in enumerate(applied):
        m = types.vehicle_state_t()
        m.utime = k * 10_000
        m.throttle_applied, m.steering_applied = throttle, steering
        log.write_event(m.utime, ch, m.encode())
    log.close()
    return path


def counts(path: pathlib.Path, types) -> tuple[int, int]:
    """(unsigned, wrong-key) samples as the bench derives them."""
    hits = security.hostile_throttle_samples(path, types)
    wrong = security.hostile_throttle_samples(path, types, ((security.WRONG_KEY_THROTTLE, 1.0),))
    return hits - wrong, wrong


def test_an_unsigned_command_applied_is_counted(tmp_path, build_dir) -> None:
    types = lcmtypes.load(build_dir)
    idle = [(0.0, 0.0)] * 20
    held = [(security.UNSIGNED_THROTTLE, -1.0)] * 12  # the Nano applies it for 120 ms
    path = write_log(tmp_path / "unsigned.lcmlog", types, idle + held + idle)
    assert counts(path, types) == (12, 0)
    wrong = [(security.WRONG_KEY_THROTTLE, 1.0)] * 8
    path = write_log(tmp_path / "wrong.lcmlog", types, idle + wrong + idle)
    assert counts(path, types) == (0, 8)


def test_a_legitimate_slew_through_the_same_values_is_not(tmp_path, build_dir) -> None:
    types = lcmtypes.load(build_dir)
    slew = [(0.9 + 0.01 * k, -1.0) for k in range(8)]  # passes 0.93 in one or two samples
    brief = [(security.UNSIGNED_THROTTLE, -1.0)] * (security.HOSTILE_RUN - 1)
    path = write_log(tmp_path / "clean.lcmlog", types, slew + [(0.0, 0.0)] + brief)
    assert counts(path, types) == (0, 0)


def test_an_applied_unsigned_command_fails_the_security_goals(tmp_path, build_dir) -> None:
    types = lcmtypes.load(build_dir)
    path = write_log(tmp_path / "u.lcmlog", types, [(security.UNSIGNED_THROTTLE, -1.0)] * 6)
    unsigned, wrong = counts(path, types)
    figures = {g.figure: g.bound for g in security.GOALS.values()}
    figures.update(unsigned_cmd_applied=unsigned, wrong_key_cmd_applied=wrong)
    res = goals.judge(figures, security.GOALS, seeds.unseeded("a constructed log"))
    assert unsigned == 6 and res["goals_met"] is False
    assert res["goals"]["unsigned_cmd_applied"] is False
