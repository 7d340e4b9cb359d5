"""HIL, the command-security probe as a regression test: the demo's loop drive (sim + unchanged
runtime + the signed pure-pursuit driver, real UDP LCM) while the hostile publisher of
`tools/bench security` attacks for the whole run: unsigned full-throttle full-lock commands by
multicast and by plain unicast UDP to the LCM port, commands signed with a wrong key claiming a
person's authority, and byte-for-byte replays of the driver's own commands. Nothing hostile may
drive: no hostile throttle applied by the Nano, no change of control to another source, the car
drives its track; and the demo's report counts the foreign commands, so the run is not a
success (the old stack reported success: true)."""
import json
import pathlib
import subprocess
import tempfile

from autodrive.core import channels
from autodrive.core import command_auth
from autodrive.core import lcmtypes
from autodrive.bench import security

from hil_demo import demo_command, use_test_keys


def test_nothing_hostile_drives(root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int) -> None:
    build, port = str(build_dir), lcm_port
    types = lcmtypes.load(build)
    hostile = security.Hostile(
        types, f"udpm://239.255.76.67:{port}?ttl=0", port, victim="demo-loop"
    )
    with tempfile.TemporaryDirectory(prefix="hil-attack-") as tmp:
        cmd = demo_command(build, tmp, port, "--mission", "loop", "--duration", "12")
        hostile.start()
        try:
            r = subprocess.run(cmd, timeout=240)
        finally:
            hostile.stop()
        report = json.loads((pathlib.Path(tmp) / "report.json").read_text())
        print(json.dumps(report, indent=2))
        print(f"hostile sent {hostile.sent}, holders seen {sorted(hostile.holders)}")
        assert all(n > 20 for n in hostile.sent.values()), f"the attack did not run: {hostile.sent}"
        hits = security.hostile_throttle_samples(pathlib.Path(tmp) / "run.lcmlog", types)
        assert hits == 0, f"{hits} STATE samples with a hostile throttle applied"
        use_test_keys()  # the demo's (demo_command made them): the log is classified with it
        key = command_auth.load_key(command_auth.default_key_path(channels.vehicle_name(1)))
        beyond = security.log_applied_beyond_sent(pathlib.Path(tmp) / "run.lcmlog", types, key)
        assert beyond == 0, f"the gate applied {beyond} command(s) beyond those the driver sent"
        assert hostile.holders == {"demo-loop"}, f"control went to {sorted(hostile.holders)}"
        assert report["command_holders"] == ["demo-loop"], report["command_holders"]
        # The car drove its track as if alone ...
        assert report["path_length_m"] > 1.0, "the car did not drive the track"
        assert report["collisions"] == 0
        # ... and the report noticed the attack: foreign commands counted, not a success.
        assert report["foreign_unsigned"] > 0 and report["foreign_bad_signature"] > 0
        assert report["foreign_replayed"] > 0
        assert report["foreign_commands"] >= hostile.sent["bad_mac"] // 2
        assert not report["ok"], "a run with foreign commands reported ok"
        assert r.returncode == 1, f"demo exited {r.returncode}, want 1 (not ok)"
    print("hil demo under attack ok")
