"""autodrive-marl on real LCM UDP multicast, scripted cases of two cars on Intersection School's
west_to_east lane: NIGEL1's own pose (<VEH>_POSE_MAP) and NIGEL2's V2V state, one signed
<VEH>_COMMAND out. Head-on 0.45 m apart and closing: the shield brakes (throttle 0, still
engaged, signed by source "marl"); with --no-shield the policy's throttle goes out; the same
head-on peer stamped 500 ms old is dropped as stale (reported in the status) and does not brake
the car; a peer far away does not brake it; --v2v-loss 1 loses every state; a 100 ms delay
still brakes. The program runs on the test's own SIM_CLOCK (--clock sim), 50 ms of sim time per
round of inputs, so staleness, delay and the control period are judged on sim time and a loaded
machine only slows the run. argv: autodrive-marl, build dir, LCM port."""

import os
import select
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

from autodrive.core import channels
from autodrive.core import v2x_auth, v2x_ca
from autodrive.core import lcmtypes
from autodrive.core.settings import REPO_ROOT

sys.path.insert(0, str(Path(__file__).parent))
from marl_test_policy import LOOKAHEAD_M, make_policy  # noqa: E402

SIM_STEP_US = 50_000  # sim time per round of inputs [us]: 20 Hz, as the runtimes broadcast V2V
HANG_BACKSTOP_S = 300.0  # wall time [s]: ends a program that never drives, never a figure


def test_shield_and_stale_v2v(
    program: Callable[[str], str], build_dir: Path, lcm_port: int, lcm_url: str
) -> None:
    exe, build, port = program("autodrive-marl"), build_dir, lcm_port
    url = lcm_url
    types = lcmtypes.load(build)
    MAP_JSON = REPO_ROOT / "maps" / "intersection_school.json"
    THROTTLE = 1.0  # the trained policies' (autodrive.learn.marl.export)
    keys = tempfile.TemporaryDirectory(prefix="marl-keys-")
    os.environ["AUTODRIVE_KEY_DIR"] = keys.name
    v2x_ca.ensure_run_keys(["NIGEL1", "NIGEL2"], print)  # and NIGEL2's V2V certificate
    peer_signer = v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL2"))

    def run_case(policy: Path, peer_xy_yaw, peer_age_s: float, *extra: str):
        """Runs autodrive-marl with the scripted inputs for >= 2.5 s of sim time and 40 engaged
        commands; returns (commands, last status)."""
        proc = subprocess.Popen(
            [exe, "--vehicle", "NIGEL1", "--lcm-url", url, "--policy", str(policy)]
            + ["--map-json", str(MAP_JSON), "--route", "west_to_east", "--clock", "sim"]
            + ["--waypoint-lookahead-m", str(LOOKAHEAD_M), *extra],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        lc = lcmtypes.bus(url)
        commands, status = [], []
        engaged = 0  # engaged commands so far, counted as they arrive

        def on_command(_c: str, d: bytes) -> None:
            nonlocal engaged
            commands.append(d)
            engaged += types.vehicle_command_t.decode(d).engaged

        lc.subscribe(channels.channel("COMMAND", "NIGEL1"), on_command)
        lc.subscribe(channels.channel("MISSION", "NIGEL1"), lambda _c, d: status.append(d))
        sim_t0_us = sim_us = 1_000_000  # the test's SIM_CLOCK [us]
        seq = 0
        backstop = time.monotonic() + HANG_BACKSTOP_S

        # At least 2.5 s of sim time and 40 engaged commands: the count is what the asserts need
        # (a loaded machine starts the program late); the wall backstop only ends a hung program.
        while time.monotonic() < backstop and (sim_us - sim_t0_us < 2_500_000 or engaged < 40):
            sim_us += SIM_STEP_US
            now_us = sim_us
            tick = types.sim_clock_t()
            tick.utime, tick.real_time_factor, tick.paused = sim_us, 1.0, False
            lc.publish(channels.channel("SIM_CLOCK"), tick.encode())
            pose = types.odometry_t()
            pose.utime, pose.vehicle, pose.frame_id = now_us, "NIGEL1", "map"
            pose.x_m, pose.y_m, pose.yaw_rad, pose.vx_m_s = -1.0, -0.14, 0.0, 0.15
            lc.publish(channels.channel("POSE_MAP", "NIGEL1"), pose.encode())
            v = types.v2v_state_t()
            v.utime = now_us - int(peer_age_s * 1e6)
            v.seq, v.vehicle = seq, "NIGEL2"
            v.x_m, v.y_m, v.yaw_rad = peer_xy_yaw
            v.speed_m_s, v.route, v.route_s_m = 0.2, "east_to_west", -1.0
            # signed when sent (now); the pose in it may be old: the peer table judges that
            peer_signer.sign(channels.channel("V2V"), v, now_us)
            lc.publish(channels.channel("V2V"), v.encode())
            seq += 1
            end = time.monotonic() + SIM_STEP_US * 1e-6  # paced near real time: 20 Hz of V2V
            while (left := end - time.monotonic()) > 0:
                if select.select([lc.fileno()], [], [], left)[0]:
                    lc.handle()
        proc.send_signal(2)
        out, _ = proc.communicate(timeout=20)
        assert proc.returncode == 0, out
        cmds = [types.vehicle_command_t.decode(d) for d in commands]
        cmds = [c for c in cmds if c.engaged]
        assert len(cmds) >= 20, (len(cmds), out)
        st = types.mission_status_t.decode(status[-1]) if status else None
        return cmds[5:], st, out

    with tempfile.TemporaryDirectory(prefix="marl-shield-") as tmp:
        policy, _net = make_policy(Path(tmp), throttle=THROTTLE)
        head_on = (-0.55, -0.14, 3.14159)  # NIGEL2 0.45 m ahead in the same lane, coming at it

        cmds, st, out = run_case(policy, head_on, 0.0)
        assert all(c.throttle == 0.0 for c in cmds), [c.throttle for c in cmds]
        assert all(c.source == "marl" and any(c.mac) for c in cmds)
        assert st is not None and "shield_interventions" in st.detail, st
        n = int(st.detail.split("shield_interventions ")[1].split()[0])
        assert n >= 20, (n, st.detail)  # the status lags the commands by up to 0.5 s
        print(f"head-on: {len(cmds)} commands all braked (throttle 0); status: {st.detail}")

        cmds, st, out = run_case(policy, head_on, 0.0, "--no-shield")
        assert all(abs(c.throttle - THROTTLE) < 1e-6 for c in cmds), [c.throttle for c in cmds]
        print(f"head-on, --no-shield: {len(cmds)} commands at throttle {THROTTLE}")

        cmds, st, out = run_case(policy, head_on, 0.5)
        assert all(abs(c.throttle - THROTTLE) < 1e-6 for c in cmds), [c.throttle for c in cmds]
        stale = int(st.detail.split("v2v_dropped_stale ")[1].split()[0])
        peers = int(st.detail.split("peers ")[1].split()[0])
        assert stale >= 10 and peers == 0, st.detail
        print(f"head-on peer 500 ms old: dropped as stale ({stale}), no brake; status: {st.detail}")

        cmds, st, out = run_case(policy, (2.5, 2.5, 0.0), 0.0)
        assert all(abs(c.throttle - THROTTLE) < 1e-6 for c in cmds)
        assert int(st.detail.split("peers ")[1].split()[0]) == 1, st.detail
        print(f"peer far away: fresh (1 peer), no brake: {len(cmds)} commands at {THROTTLE}")
        cmds, st, out = run_case(policy, head_on, 0.0, "--v2v-loss", "1", "--seed", "5")
        lost = int(st.detail.split("v2v_lost ")[1].split()[0])
        got = int(st.detail.split("v2v_received ")[1].split()[0])
        assert lost == got > 0 and all(abs(c.throttle - THROTTLE) < 1e-6 for c in cmds), st.detail
        print(f"--v2v-loss 1: every state lost ({lost}/{got}), so nothing to brake for")

        cmds, st, out = run_case(policy, head_on, 0.0, "--v2v-delay-ms", "100")
        assert all(c.throttle == 0.0 for c in cmds), [c.throttle for c in cmds]
        print(
            "--v2v-delay-ms 100 (the demo's degraded link; under the 200 ms stale limit): still brakes"
        )
    print("ok")
