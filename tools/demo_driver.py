"""Demo driver: closes the loop through the whole HIL chain. It follows a stadium-shaped track
(two 1.0 m straights, 0.4 m radius ends, laid out from the car's start pose) with pure pursuit
on the runtime's EKF estimate (<VEH>_POSE_MAP), publishing <VEH>_COMMAND at 50 Hz. Ground truth
is never used to drive; tools/demo_report.py compares with it afterwards."""
import math
import select
import time

import lcm
from autodrive import odometry_t, vehicle_command_t, vehicle_state_t

WHEELBASE_M = 0.14154
STEER_LIMIT_RAD = 0.5236
LOOKAHEAD_M = 0.25
THROTTLE = 0.7  # normalised; ~0.19 m/s on the flat
COMMAND_PERIOD_S = 0.02  # 50 Hz


def stadium_track(step_m=0.02):
    """Closed track in the start frame [m]: straights y=0 and y=-0.8 from x=0.4 to 1.4."""
    pts = [(x * step_m, 0.0) for x in range(0, int(0.4 / step_m))]  # lead-in from the start
    lap = []
    n = int(1.0 / step_m)
    lap += [(0.4 + i * step_m, 0.0) for i in range(n)]
    for i in range(int(math.pi * 0.4 / step_m)):
        a = math.pi / 2 - i * step_m / 0.4
        lap.append((1.4 + 0.4 * math.cos(a), -0.4 + 0.4 * math.sin(a)))
    lap += [(1.4 - i * step_m, -0.8) for i in range(n)]
    for i in range(int(math.pi * 0.4 / step_m)):
        a = -math.pi / 2 - i * step_m / 0.4
        lap.append((0.4 + 0.4 * math.cos(a), -0.4 + 0.4 * math.sin(a)))
    return pts, lap


def drive(url, veh, duration_s, rtf, procs, stop_requested):
    lc = lcm.LCM(url)
    pose = {}
    state = {}

    def on_pose(_ch, data):
        m = odometry_t.decode(data)
        pose.update(x=m.x_m, y=m.y_m, yaw=m.yaw_rad, t=m.utime)

    def on_state(_ch, data):
        m = vehicle_state_t.decode(data)
        state.update(mode=m.mode, faults=m.fault_flags, n=state.get("n", 0) + 1)

    lc.subscribe(f"{veh}_POSE_MAP", on_pose)
    lc.subscribe(f"{veh}_STATE", on_state)
    print("[demo] waiting for the runtime's state and pose ...", flush=True)
    t0 = time.time()
    while not (pose and state):
        procs.check()
        if time.time() - t0 > 30:
            raise RuntimeError(f"no {veh}_STATE/{veh}_POSE_MAP from the runtime within 30 s")
        if select.select([lc.fileno()], [], [], 0.1)[0]:
            lc.handle()
    start = dict(pose)
    c0, s0 = math.cos(start["yaw"]), math.sin(start["yaw"])
    lead, lap = stadium_track()
    to_world = lambda p: (start["x"] + c0 * p[0] - s0 * p[1], start["y"] + s0 * p[0] + c0 * p[1])
    lead, lap = [to_world(p) for p in lead], [to_world(p) for p in lap]
    path = lead + lap
    idx = 0
    seq = 0
    laps = 0
    print(
        f"[demo] driving the stadium track for {duration_s:.0f} s of sim time "
        f"({'lockstep' if rtf is None else f'rtf {rtf:g}'}) ...",
        flush=True,
    )
    t_start = time.time()
    next_cmd = t_start
    last_print = t_start
    while True:
        now = time.time()
        # The runtime stamps on the sim clock: elapsed sim time even when the sim slips.
        sim_elapsed = (pose["t"] - start["t"]) * 1e-6
        if sim_elapsed >= duration_s or stop_requested():
            break
        procs.check()
        if select.select([lc.fileno()], [], [], max(0.0, next_cmd - now))[0]:
            lc.handle()
            continue
        next_cmd += COMMAND_PERIOD_S
        # Pure pursuit: advance the target index along the path to the lookahead distance.
        x, y, yaw = pose["x"], pose["y"], pose["yaw"]
        while math.hypot(path[idx][0] - x, path[idx][1] - y) < LOOKAHEAD_M:
            idx += 1
            if idx >= len(path):
                idx = len(lead)
                laps += 1
        tx, ty = path[idx]
        dx, dy = tx - x, ty - y
        ly = -math.sin(yaw) * dx + math.cos(yaw) * dy
        ld2 = dx * dx + dy * dy
        delta = math.atan(2.0 * WHEELBASE_M * ly / max(ld2, 1e-6))
        cmd = vehicle_command_t()
        cmd.utime = int(now * 1e6)
        cmd.seq = seq
        seq += 1
        cmd.throttle = THROTTLE
        cmd.steering = max(-1.0, min(1.0, delta / STEER_LIMIT_RAD))
        cmd.headlights = 1
        cmd.indicators = 1 if cmd.steering > 0.3 else (2 if cmd.steering < -0.3 else 0)
        cmd.engaged = True
        lc.publish(f"{veh}_COMMAND", cmd.encode())
        if now - last_print > 2.0:
            last_print = now
            print(
                f"[demo] t_sim={sim_elapsed:5.1f}/{duration_s:.0f} s  lap {laps}  "
                f"pose=({x:+.2f}, {y:+.2f}, {math.degrees(yaw):+6.1f} deg)  "
                f"mode={state.get('mode')} faults=0x{state.get('faults', 0):x}",
                flush=True,
            )
    # Stop: a few disengaged zero commands, then silence (the firmware brakes either way).
    for _ in range(10):
        cmd = vehicle_command_t()
        cmd.utime = int(time.time() * 1e6)
        cmd.seq = seq
        seq += 1
        cmd.engaged = False
        lc.publish(f"{veh}_COMMAND", cmd.encode())
        time.sleep(COMMAND_PERIOD_S)
    return {
        "driver": "pure pursuit on the runtime EKF (stadium track)",
        "laps": laps,
        "track_start_map": [start["x"], start["y"], start["yaw"]],
    }
