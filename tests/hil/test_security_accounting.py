"""tools/bench security's count of replays applied (applied_beyond_sent) on synthetic buses: no
demo, seconds. The old count compared the gate's drop counters with what the logger had seen
0.5 s before, and reported 20 replays "applied" when the bridge read the bus seconds behind the
logger and either of them lost packets (a loaded machine). Those must count 0; a gate that
applies a replay (a counter twice) or a foreign command must not."""
import pathlib
import random
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.bench.security import applied_beyond_sent  # noqa: E402

S = 1_000_000  # [us]


def bus(seconds: int, lost: float, rng: random.Random) -> list[tuple[int, str, int]]:
    """The valid commands the logger kept, as (counter, source, seq): the autonomy at 25 Hz
    (seq 0, 1, ..., counter = its send time) and a replay of each 0.1 s later (the same
    counter); each packet lost with probability lost, and a burst of 25 commands (with their
    replays) lost after 1 s."""
    out = []
    for seq in range(seconds * 25):
        t = seq * S // 25
        for _copy in range(2):
            if rng.random() >= lost and not 25 <= seq < 50:
                out.append((t, "autonomy", seq))
    return out


def statuses(read_lag_us: int, extra: int = 0, every_us: int = S // 5) -> list[tuple[int, int]]:
    """An honest gate reading the bus read_lag_us behind: it applied each original once, and
    extra more from the second second on."""
    out = []
    for t in range(every_us, 10 * S, every_us):
        read = max(0, t - read_lag_us)
        applied = (read * 25) // S + 1 if read > 0 else 0
        out.append((t, applied + (extra if t > 2 * S else 0)))
    return out


def test_replays_applied_counted_honestly() -> None:
    rng = random.Random(7)
    # An honest gate, in time or 3 s behind, with the logger losing 40 % and a burst: 0.
    for lag_us in (0, 3 * S):
        for lost in (0.0, 0.4):
            got = applied_beyond_sent(bus(10, lost, rng), statuses(lag_us))
            assert got == 0, f"lag {lag_us} us, lost {lost}: {got}"
    # A gate that applied commands beyond those sent (replays, or foreign ones) is caught (a gate
    # reading the bus seconds late hides as many as were sent in its lag) ...
    for lag_us in (0, S // 5):
        for lost in (0.0, 0.4):
            got = applied_beyond_sent(bus(10, lost, rng), statuses(lag_us, extra=20))
            assert got >= 20 - lag_us * 25 // S, f"lag {lag_us} us, lost {lost}: {got}"
    # ... and one that applies every replay is caught however late it reads.
    twice = [(t, 2 * a) for t, a in statuses(3 * S)]
    assert applied_beyond_sent(bus(10, 0.4, rng), twice) > 50
    print("security accounting ok")
