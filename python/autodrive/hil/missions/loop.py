"""The loop mission: closes the loop through the whole HIL chain. It follows a stadium-shaped
track (two 1.0 m straights, 0.4 m radius ends, laid out from the car's start pose) with pure
pursuit on the runtime's EKF estimate (<VEH>_POSE_MAP; <VEH>_ODOM in a run without an Eye, whose
map filter has no fix), publishing <VEH>_COMMAND at 50 Hz of sim time: a command per
COMMAND_PERIOD_S of the estimate's own stamps (the runtime stamps on the sim's SIM_CLOCK), so
in lockstep the drive is the same at any real-time factor and a starved driver slows the run
instead of falling behind it. Ground truth is never used to drive; the report compares with it
afterwards."""

from __future__ import annotations

import math
import select
import time
from typing import Any

from autodrive.core import command_auth, lcmtypes, pure_pursuit
from autodrive.core.channels import channel
from autodrive.core.geometry import Point, to_world
from autodrive.hil.missions import MissionContext

LOOKAHEAD_M = 0.25
THROTTLE = 0.7  # normalised; ~0.19 m/s on the flat
COMMAND_PERIOD_S = 0.02  # [s of sim time] between commands: 50 Hz
STEERING_INDICATOR = 0.3  # |steering| above which the indicator blinks
INDICATOR_LEFT, INDICATOR_RIGHT = 1, 2
STATE_TIMEOUT_S = 30.0  # [s wall] a hang guard: no state or pose from the runtime at all
POSE_TIMEOUT_S = 60.0  # [s wall] a hang guard: the runtime stopped publishing poses
STOP_COMMANDS = 10  # disengaged zero commands at the end
STOP_PERIOD_S = 0.02  # [s wall] between them: the car brakes either way
PRINT_PERIOD_S = 2.0  # [s wall] between progress lines


def stadium_track(step_m: float = 0.02) -> tuple[list[Point], list[Point]]:
    """(lead-in, closed lap) in the start frame [m]: straights y=0 and y=-0.8 from x=0.4 to
    1.4, the lead-in from the start to the lap."""
    lead = [(x * step_m, 0.0) for x in range(0, int(0.4 / step_m))]
    lap: list[Point] = []
    n = int(1.0 / step_m)
    lap += [(0.4 + i * step_m, 0.0) for i in range(n)]
    for i in range(int(math.pi * 0.4 / step_m)):
        a = math.pi / 2 - i * step_m / 0.4
        lap.append((1.4 + 0.4 * math.cos(a), -0.4 + 0.4 * math.sin(a)))
    lap += [(1.4 - i * step_m, -0.8) for i in range(n)]
    for i in range(int(math.pi * 0.4 / step_m)):
        a = -math.pi / 2 - i * step_m / 0.4
        lap.append((0.4 + 0.4 * math.cos(a), -0.4 + 0.4 * math.sin(a)))
    return lead, lap


def drive(
    ctx: MissionContext, duration_s: float, rtf: float | None, pose_channel: str = "POSE_MAP"
) -> dict[str, Any]:
    """Drives the stadium track on the EKF's pose_channel (POSE_MAP or ODOM)."""
    types = lcmtypes.load(ctx.build)
    car = pure_pursuit.default_vehicle()
    lc = lcmtypes.bus(ctx.lcm_url)
    try:
        signer = command_auth.signer_for(ctx.vehicle, "demo-loop")
    except ValueError as e:
        raise RuntimeError(str(e)) from None
    pose: dict[str, float] = {}
    state: dict[str, int] = {}
    ch_pose, ch_state, ch_command = (
        channel(c, ctx.vehicle) for c in (pose_channel, "STATE", "COMMAND")
    )

    def on_pose(_ch: str, data: bytes) -> None:
        m = types.odometry_t.decode(data)
        pose.update(x=m.x_m, y=m.y_m, yaw=m.yaw_rad, t=m.utime, heard=time.time())

    def on_state(_ch: str, data: bytes) -> None:
        m = types.vehicle_state_t.decode(data)
        state.update(mode=m.mode, faults=m.fault_flags, n=state.get("n", 0) + 1)

    lc.subscribe(ch_pose, on_pose)
    lc.subscribe(ch_state, on_state)
    ctx.say("waiting for the runtime's state and pose ...")
    t0 = time.time()
    while not (pose and state):
        ctx.procs.check()
        if time.time() - t0 > STATE_TIMEOUT_S:
            raise RuntimeError(f"no {ch_state}/{ch_pose} from the runtime within 30 s")
        if select.select([lc.fileno()], [], [], 0.1)[0]:
            lc.handle()
    start = dict(pose)
    origin = (start["x"], start["y"], start["yaw"])
    lead, lap = stadium_track()
    path = [to_world(origin, (p[0], p[1], 0.0))[:2] for p in lead + lap]
    track = pure_pursuit.Polyline(path)
    idx = 0
    seq = 0
    laps = 0
    mode = "lockstep" if rtf is None else f"rtf {rtf:g}"
    ctx.say(f"driving the stadium track for {duration_s:.0f} s of sim time ({mode}) ...")
    last_print = time.time()
    last_cmd_t = -math.inf  # [us of sim time] the stamp of the pose the last command used

    def command(engaged: bool, throttle: float = 0.0, steering: float = 0.0) -> Any:
        nonlocal seq
        cmd = types.vehicle_command_t()
        cmd.utime = int(time.time() * 1e6)
        cmd.seq = seq
        seq += 1
        cmd.throttle = throttle
        cmd.steering = steering
        cmd.engaged = engaged
        return cmd

    while True:
        # The runtime stamps on the sim clock: elapsed sim time, at any pace of the sim.
        sim_elapsed = (pose["t"] - start["t"]) * 1e-6
        if sim_elapsed >= duration_s or ctx.stop_requested():
            break
        ctx.procs.check()
        if pose["t"] - last_cmd_t < COMMAND_PERIOD_S * 1e6:
            # Wait for the next pose; the only wall time here is the hang guard.
            if select.select([lc.fileno()], [], [], 1.0)[0]:
                lc.handle()
            elif time.time() - pose["heard"] > POSE_TIMEOUT_S:
                raise RuntimeError(f"no {ch_pose} from the runtime for {POSE_TIMEOUT_S:g} s")
            continue
        last_cmd_t = pose["t"]
        # Pure pursuit (the one, in C): the goal is the first sample the lookahead away from
        # the target index on; past the track's end the index goes back to the lap's start.
        x, y, yaw = pose["x"], pose["y"], pose["yaw"]
        while (idx := track.goal_index(idx, x, y, LOOKAHEAD_M)) >= len(path):
            idx = len(lead)
            laps += 1
        delta = pure_pursuit.steer_to((x, y, yaw), path[idx], car)
        cmd = command(True, THROTTLE, delta / car.steer_limit_rad)
        cmd.headlights = 1
        cmd.indicators = (
            INDICATOR_LEFT
            if cmd.steering > STEERING_INDICATOR
            else (INDICATOR_RIGHT if cmd.steering < -STEERING_INDICATOR else 0)
        )
        lc.publish(ch_command, signer.sign(cmd).encode())
        if time.time() - last_print > PRINT_PERIOD_S:
            last_print = time.time()
            ctx.say(
                f"t_sim={sim_elapsed:5.1f}/{duration_s:.0f} s  lap {laps}  "
                f"pose=({x:+.2f}, {y:+.2f}, {math.degrees(yaw):+6.1f} deg)  "
                f"mode={state.get('mode')} faults=0x{state.get('faults', 0):x}"
            )
    # Stop: a few disengaged zero commands, then silence (the firmware brakes either way).
    for _ in range(STOP_COMMANDS):
        lc.publish(ch_command, signer.sign(command(False)).encode())
        time.sleep(STOP_PERIOD_S)
    return {
        "driver": f"pure pursuit on the runtime EKF's {ch_pose} (stadium track)",
        "laps": laps,
        "track_start_map": [start["x"], start["y"], start["yaw"]],
    }
