"""inspect.foxglove_live: tools/foxglove-live on real LCM (UDP multicast on loopback) serves
Foxglove's WebSocket protocol; a WebSocket client subscribes to every advertised channel and
decodes one message of each kind (protobuf with the advertised schema, or JSON)."""

from __future__ import annotations

import asyncio
import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import websockets
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from autodrive.core import channels
from autodrive.core import lcmtypes

# Each message published this many times (10 per second of the publisher's own pace) without
# every topic reaching the client is a failure.
PUBLISH_ROUNDS = 600


def test_websocket_client_decodes_every_channel(build_dir: Path, lcm_port: int) -> None:
    build, port_lcm = build_dir, lcm_port
    URL = f"udpm://239.255.76.67:{port_lcm}?ttl=0"
    VEH = "NIGEL1"
    t = lcmtypes.load(build)

    def messages() -> list[tuple[str, Any]]:
        scan = t.lidar_scan_t()
        scan.utime, scan.frame_id, scan.num_ranges = 2_000_000, "laser", 360
        scan.angle_increment_rad = 2 * math.pi / 360
        scan.angle_max_rad = scan.angle_increment_rad * 359
        scan.ranges_m, scan.intensities = [2.0] * 360, [47.0] * 360
        odom = t.odometry_t()
        odom.utime, odom.vehicle, odom.frame_id, odom.child_frame_id = (
            2_000_000,
            VEH,
            "odom",
            "base_link",
        )
        odom.x_m, odom.y_m, odom.yaw_rad = 0.3, 0.1, 0.2
        eye = t.pose2d_t()
        eye.utime, eye.vehicle, eye.frame_id, eye.x_m, eye.y_m, eye.yaw_rad = (
            2_000_000,
            VEH,
            "map",
            1.5,
            -0.25,
            0.5,
        )
        img = t.compressed_image_t()
        img.utime, img.frame_id, img.format, img.data = (
            2_000_000,
            "camera_front",
            "jpeg",
            b"\xff\xd8jpeg",
        )
        img.size_bytes = len(img.data)
        path = t.path2d_t()
        path.utime, path.vehicle, path.frame_id, path.purpose, path.num_poses = (
            2_000_000,
            VEH,
            "map",
            "parking",
            2,
        )
        path.x_m, path.y_m, path.yaw_rad, path.direction, path.curvature_1pm = (
            [0, 1],
            [0, 0],
            [0, 0],
            [1, 1],
            [0, 0],
        )
        clock = t.sim_clock_t()
        clock.utime, clock.real_time_factor = 2_000_000, 4.0
        return [
            ("LIDAR", scan),
            ("ODOM", odom),
            ("POSE_EYE", eye),
            ("CAM_FRONT", img),
            ("PATH", path),
            ("SIM_CLOCK", clock),
        ]

    rounds = [0]  # how many times every message has been published

    def publish_until(stop: threading.Event) -> None:
        bus = lcmtypes.bus(URL)
        table = channels.load()
        while not stop.is_set():
            for cid, m in messages():
                ch = table.by_id(cid)
                bus.publish(ch.resolve(VEH if ch.per_vehicle else None), m.encode())
            rounds[0] += 1
            time.sleep(0.1)

    def decoder(ch: dict[str, Any]) -> Any:
        if ch["encoding"] == "json":
            return lambda data: json.loads(data)
        fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(ch["schema"]))
        pool = descriptor_pool.DescriptorPool()
        for f in fds.file:
            pool.Add(f)
        cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(ch["schemaName"]))
        return lambda data: cls.FromString(data)

    async def collect(port: int, want: set[str], max_rounds: int) -> dict[str, Any]:
        """Every wanted topic's first message, until each message has been published max_rounds
        times (event order, not wall time: a loaded machine slows the publisher as well)."""
        got: dict[str, Any] = {}
        subprotocols = ["foxglove.sdk.v1", "foxglove.websocket.v1"]
        async with websockets.connect(f"ws://127.0.0.1:{port}", subprotocols=subprotocols) as ws:
            subs: dict[int, tuple[str, Any]] = {}
            while rounds[0] < max_rounds and not want <= set(got):
                try:
                    frame = await asyncio.wait_for(ws.recv(), timeout=1.0)
                except asyncio.TimeoutError:
                    continue
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op.get("op") == "advertise":
                        new = []
                        for ch in op["channels"]:
                            sid = 1000 + ch["id"]
                            subs[sid] = (ch["topic"], decoder(ch))
                            new.append({"id": sid, "channelId": ch["id"]})
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": new}))
                elif frame[0] == 0x01:  # messageData: subscription id u32, log time u64, payload
                    (sid,) = struct.unpack_from("<I", frame, 1)
                    topic, dec = subs[sid]
                    if topic not in got:
                        got[topic] = dec(frame[13:])
        return got

    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "map.pgm").write_bytes(
            b"P5\n4 2\n255\n" + bytes([0, 254, 205, 0, 254, 254, 0, 0])
        )
        (Path(tmp) / "map.yaml").write_text(
            "image: map.pgm\nresolution: 0.05\norigin: [-1.0, -0.5, 0.0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.196\nnegate: 0\n"
        )
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "autodrive.devtools.inspect.foxglove_live",
                "--lcm-url",
                URL,
                "--port",
                "0",
                "--build",
                str(build),
                "--map",
                str(Path(tmp) / "map.yaml"),
                "--duration",
                "900",  # a hang guard only: the test stops it
            ],
            stdout=subprocess.PIPE,
            text=True,
            env=env,
        )
        stop = threading.Event()
        pub = threading.Thread(target=publish_until, args=(stop,), daemon=True)
        try:
            assert proc.stdout is not None
            line = proc.stdout.readline()
            assert "serving ws://" in line, f"foxglove-live did not start: {line!r}"
            port = int(line.split("ws://")[1].split()[0].rsplit(":", 1)[1])
            pub.start()
            want = {
                "/nigel1/lidar",
                "/nigel1/odom",
                "/nigel1/pose_eye",
                "/nigel1/cam_front",
                "/nigel1/path",
                "/sim_clock",
                "/tf",
                "/map",
            }
            got = asyncio.run(collect(port, want, PUBLISH_ROUNDS))
        finally:
            stop.set()
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
        assert want <= set(got), f"missing topics: {want - set(got)} (got {sorted(got)})"
        scan = got["/nigel1/lidar"]
        assert scan.frame_id == "nigel1/laser" and len(scan.ranges) == 360 and scan.ranges[5] == 2.0
        assert (
            got["/nigel1/odom"].pose.position.x == 0.3
            and got["/nigel1/odom"].frame_id == "nigel1/odom"
        )
        assert abs(got["/nigel1/pose_eye"].pose.position.y + 0.25) < 1e-12
        assert (
            got["/nigel1/cam_front"].data == b"\xff\xd8jpeg"
            and got["/nigel1/cam_front"].format == "jpeg"
        )
        assert len(got["/nigel1/path"].poses) == 2
        assert got["/sim_clock"]["real_time_factor"] == 4.0
        tf = got["/tf"]
        assert tf.parent_frame_id and tf.child_frame_id.startswith("nigel1/"), tf
        grid = got["/map"]
        assert (
            grid.column_count == 4 and len(grid.data) == 8 and abs(grid.cell_size.x - 0.05) < 1e-9
        )
        # PGM rows run top down, the grid's bottom up: the top-left black pixel is cell (0, 1);
        # occupancy in percent, so the PGM's unknown grey (205) is 20
        assert list(grid.data) == [0, 0, 100, 100, 100, 0, 20, 100], list(grid.data)
    print("foxglove_live ok:", sorted(got))
