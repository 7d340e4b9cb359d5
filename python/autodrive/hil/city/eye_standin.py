"""Eye stand-in for the HIL missions (smart-city, intersection): <VEH>_POSE_EYE for each car
from the simulator's ground truth at 10 Hz of sim time, with Gaussian noise (5 mm, 0.5 deg;
seeded), stamped at capture and signed with the Eye's certificate (EYE, role eye: the cars' EKFs
take no other), as runtime-link-bench does for the EKF tests. It stands in for
autodrive-eye on rendered overhead frames (tested on its own in eye/), which this 2-core machine
cannot run for three or four cars beside everything else. Without any Eye the EKF's heading
drifts with the gyro bias (~0.3 deg/s): the smart-city cars leave their lanes within a lap, and
the intersection cars' poses are 0.2-0.3 m off after a turn, which the shield then works on.

CLI: python -m autodrive.hil.city.eye_standin --vehicles NIGEL1,NIGEL2 [--seed N] [--lcm-url]
"""

from __future__ import annotations

import argparse
import random
import select
import signal
import sys
from pathlib import Path
from types import FrameType

from autodrive.core import channels, lcmtypes, v2x_auth, v2x_ca
from autodrive.core.v2x_cert import CertificateError
from autodrive.core.channels import channel
from autodrive.core.settings import RELEASE_BUILD

PERIOD_US = 100_000  # 10 Hz of sim time
NOISE_M = 0.005
NOISE_RAD = 0.0087
EYE_IDENTITY = "EYE"  # the testbed's eye certificate (v2x_ca.TESTBED_IDENTITIES)


def run(vehicles: list[str], url: str, build: Path, seed: int, stop: list[bool]) -> int:
    types = lcmtypes.load(build)
    lc = lcmtypes.bus(url)
    rng = random.Random(seed)
    signer = v2x_auth.MessageSigner(v2x_ca.load_identity(EYE_IDENTITY))
    next_us: dict[str, int] = {}

    def on_truth(_ch: str, data: bytes) -> None:
        m = types.ground_truth_t.decode(data)
        if m.utime < next_us.get(m.vehicle, 0):
            return
        next_us[m.vehicle] = m.utime + PERIOD_US
        p = types.pose2d_t()
        p.utime, p.vehicle, p.frame_id = m.utime, m.vehicle, "map"
        p.source = types.pose2d_t.SOURCE_GROUND_TRUTH  # says what it is in a log
        p.x_m = m.position_m[0] + rng.gauss(0.0, NOISE_M)
        p.y_m = m.position_m[1] + rng.gauss(0.0, NOISE_M)
        p.yaw_rad = m.yaw_rad + rng.gauss(0.0, NOISE_RAD)
        cov = [0.0] * 9
        cov[0] = cov[4] = NOISE_M**2
        cov[8] = NOISE_RAD**2
        p.covariance = cov
        chan = channel("POSE_EYE", m.vehicle)
        lc.publish(chan, signer.sign(chan, p, m.utime).encode())

    for v in vehicles:
        lc.subscribe(channel("GROUND_TRUTH", v), on_truth)
    print(f"[eye-standin] {', '.join(vehicles)}: POSE_EYE at 10 Hz of sim time", flush=True)
    while not stop[0]:
        if select.select([lc.fileno()], [], [], 0.1)[0]:
            lc.handle()
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.hil.city.eye_standin", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("--vehicles", default=channels.vehicle_name(1), help="comma-separated cars")
    p.add_argument("--seed", type=int, default=1, help="noise seed")
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL")
    p.add_argument("--build", default=str(RELEASE_BUILD), help="host build dir (LCM types)")
    args = p.parse_args(argv)
    stop = [False]

    def on_signal(_s: int, _f: FrameType | None) -> None:
        stop[0] = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        return run(args.vehicles.split(","), args.lcm_url, Path(args.build), args.seed, stop)
    except CertificateError as err:  # no car would take unsigned poses
        print(f"[eye-standin] cannot sign as {EYE_IDENTITY}: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
