"""HIL: Ctrl-C on tools/demo (autodrive.hil.demo) mid-mission. While the car drives its mapping
route, SIGINT must stop every child (simulator, runtime, autonomy, lcm-logger), leave a readable
report and LCM log, end with a disengaged zero command on the bus, and exit 130. Nothing is
timed: the test waits for the demo's own progress lines."""
import json
import pathlib
import signal
import subprocess
import sys
import tempfile

from hil_demo import start_demo_until
import time

from autodrive.core import lcmtypes
from autodrive.core.channels import channel


def test_ctrl_c_mid_mission(root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int) -> None:
    build, port = str(build_dir), lcm_port
    types = lcmtypes.load(build)

    def alive(pattern):
        r = subprocess.run(["pgrep", "-f", pattern], capture_output=True, text=True)
        return [p for p in r.stdout.split() if p and int(p) != 0]

    with tempfile.TemporaryDirectory(prefix="hil-int-") as tmp:
        # "route leg 1/": the car is engaged and moving
        demo, seen = start_demo_until(build, tmp, port, "route leg 1/", "--timeout", "200")
        assert demo.poll() is None, "the demo ended before the mapping route:\n" + "".join(seen)
        time.sleep(0.5)  # well into the leg
        children = alive(tmp) + alive(f"autodrive-demo-{demo.pid}")
        assert len(children) >= 3, f"expected the demo's children running, found {children}"
        demo.send_signal(signal.SIGINT)
        rest, _ = demo.communicate(timeout=120)
        sys.stdout.write(rest)
        assert demo.returncode == 130, f"demo exited {demo.returncode}, want 130 (interrupted)"
        assert "interrupted" in rest
        left = alive(tmp) + alive(f"autodrive-demo-{demo.pid}")
        assert not left, f"processes left behind: {left}"
        report = json.loads((pathlib.Path(tmp) / "report.json").read_text())
        assert not report.get("ok"), "an interrupted mission must not report ok"
        assert report.get("gt_samples", 0) > 100, "the LCM log lost what was recorded"
        last = None
        for ev in lcmtypes.events(pathlib.Path(tmp) / "run.lcmlog"):
            if ev.channel == channel("COMMAND", "NIGEL1"):
                last = types.vehicle_command_t.decode(ev.data)
        assert last is not None, "no command in the log"
        assert (
            not last.engaged and last.throttle == 0.0
        ), f"last command engaged={last.engaged} throttle={last.throttle}: the autonomy left no stop"
    print("hil demo interrupt ok")
