"""A real Ray cluster on loopback: `ray start --head` (1 CPU) plus a second node joining it
(`ray start --address`, 1 CPU), both in a temp dir; the same 2-seed parking sweep runs through
it (tools/sweep parking --address) and serially (--serial, no Ray), and the two reports agree
(autodrive.learn.sweep.parking.disagreements: same seeds, slots, scenario and success per seed, figures
within tolerance); the jobs ran on the cluster's worker processes and each on its own LCM port.
The cluster is stopped in a finally block, bounded in time: its processes are found by their
temp dir, so nothing else on the machine that runs Ray is touched.
The LCM port (--lcm-port) is the first job's; 2 are used."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys
import shutil
import tempfile
from typing import Any

from autodrive.core import seeds
from autodrive.learn.sweep import parking as sweep

from pyhelpers.ray_cluster import ENV, start_cluster, stop_cluster


def test_cluster_sweep_agrees_with_serial(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int
) -> None:
    build, port = str(build_dir), lcm_port
    RAY = root / ".venv" / "bin" / "ray"
    # Two seeds: one job per node (1 CPU each) runs at once, so both nodes are used, and each job
    # has its own LCM port; four seeds checked the same things in twice the time (~6 min in CI).
    SEEDS = 2
    EDGE_DEG = 1.0  # a final heading this close to the goal may fall either side of it [deg]
    # A short scenario: map standing still, no late box (the default demo is the HIL suite's);
    # paced at half real time: under ASan, two runs at once on a 2-core machine leave the autonomy
    # (not in the sim's lockstep) too far behind a sim that runs as fast as the runtime keeps up,
    # and in real time still missed the goal on a loaded machine.
    SCENARIO = ["--mapping-route", "", "--no-late-box", "--rtf", "0.5", "--timeout", "300"]

    def sweep_run(out: pathlib.Path, how: list[str]) -> dict[str, Any]:
        argv = [
            str(root / ".venv" / "bin" / "python"),
            "-m",
            "autodrive.learn.sweep.cli",
            "parking",
        ]
        argv += ["--seeds", str(SEEDS), "--build", build, "--out", str(out), *how]
        argv += ["--lcm-url", f"udpm://239.255.76.67:{port}?ttl=0", "--extra", *SCENARIO]
        r = subprocess.run(argv, capture_output=True, text=True, timeout=900, env=ENV)
        print(r.stderr, file=sys.stderr)
        assert r.returncode == 0, f"sweep {how} exited {r.returncode}"
        summary: dict[str, Any] = json.loads(r.stdout.strip().splitlines()[-1])
        assert summary == json.loads((out / "summary.json").read_text()), "stdout != summary.json"
        return summary

    def check(on_ray: dict[str, Any], serial: dict[str, Any]) -> None:
        assert on_ray["address"] == address and "Ray cluster" in str(on_ray["pool"]), on_ray["pool"]
        assert serial["pool"] == "serially in this process (no Ray)", serial["pool"]
        # What this test checks is that a sweep's results do not depend on where it ran: every job
        # ran, the sweep parked, and the two reports agree seed by seed (ok flags and final errors,
        # sweep.disagreements). Whether every seed parks is the parking goal of hil.parking_mission
        # and tools/bench parking; a seed that fails in both runs the same way still agrees.
        for s in (on_ray, serial):
            assert s["runs"] == SEEDS and s["successes"] >= 1, (s["runs"], s["per_seed"])
        diff = sweep.disagreements(on_ray, serial)
        if diff and diff[0].startswith("ok:"):
            # Real-time HIL is not bit-repeatable: a seed that ends within EDGE_DEG of the heading
            # goal may land on either side of it from run to run (seed 2 did: 1.3-1.5 deg one run,
            # 2.1-2.8 deg another), and the mission's own verdict on a car that stands in its slot
            # may differ too (seed 2, 2026-11-28: parked at 0.79 deg on Ray; "not parked", exit 1,
            # at 0.2 cm and 1.93 deg serially). Such a seed's ok flag is not compared; its figures
            # still are, within AGREE_TOLERANCE.
            pa, pb = on_ray["per_seed"], serial["per_seed"]
            head, pos = "final_heading_error_deg", "final_pos_error_m"
            for seed, oa, ob, ha, hb, xa, xb in zip(
                pa["seed"], pa["ok"], pb["ok"], pa[head], pb[head], pa[pos], pb[pos]
            ):
                if oa != ob:
                    edge = [h for h in (ha, hb) if h is not None]
                    near = len(edge) == 2 and all(
                        abs(h - sweep.GOAL_HEADING_ERROR_DEG) <= EDGE_DEG for h in edge
                    )
                    in_slot = None not in (ha, hb, xa, xb) and all(
                        h <= sweep.GOAL_HEADING_ERROR_DEG + EDGE_DEG and x <= sweep.GOAL_POS_ERROR_M
                        for h, x in ((ha, xa), (hb, xb))
                    )
                    assert (
                        near or in_slot
                    ), f"seed {seed}: ok {oa} vs {ob}, heading {ha} vs {hb} deg, position {xa} vs {xb} m: {diff}"
                    print(f"seed {seed}: ok {oa} vs {ob} at {ha} vs {hb} deg, {xa} vs {xb} m")
            without_ok = [{"per_seed": {k: v for k, v in x["per_seed"].items() if k != "ok"}}
                          for x in (on_ray, serial)]  # fmt: skip
            diff = sweep.disagreements(*without_ok)
        assert not diff, f"the Ray and the serial sweep disagree: {diff}"
        per_ray, per_serial = on_ray["per_seed"], serial["per_seed"]
        assert len(set(per_ray["host"])) == 2, f"the jobs did not use both nodes: {per_ray['host']}"
        for k in ("final_pos_error_m", "final_heading_error_deg"):
            print(f"{k}: Ray {per_ray[k]} / serial {per_serial[k]}")
        # Each job on its own LCM port: job i's demo ran on PORT + i.
        first = seeds.DEVELOPMENT_MISSION_SEED  # the sweep's default first seed
        for i, seed in enumerate(range(first, first + SEEDS)):
            cfg = (pathlib.Path(tmp) / "ray" / f"seed{seed}" / "runtime.yaml").read_text()
            assert f":{port + i}?" in cfg, f"seed {seed}: not on port {port + i}"
        print(
            f"{SEEDS}-seed parking sweep on a 2-node Ray cluster agrees with the serial one: {per_ray['ok']}"
        )

    tmp = tempfile.mkdtemp(prefix="adray-t", dir="/tmp")  # short: Ray's sockets live under it
    nodes: list[subprocess.Popen[bytes]] = []
    try:
        address = start_cluster(RAY, tmp, [1, 1], nodes)
        print(f"Ray cluster at {address}: 2 nodes, 1 CPU each", flush=True)

        on_ray = sweep_run(pathlib.Path(tmp) / "ray", ["--address", address])
    finally:
        stop_cluster(nodes, tmp)
    try:
        serial = sweep_run(pathlib.Path(tmp) / "serial", ["--serial"])
        check(on_ray, serial)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
