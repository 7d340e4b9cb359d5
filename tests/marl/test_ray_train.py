"""tools/marl train --address on a real Ray cluster on loopback (one `ray start --head` node with
2 CPUs, in a temp dir): a short PPO run (one rollout of 1024 agent steps, one car) whose two
rollout workers are Ray actors on that cluster; it must exit 0, say where its rollouts ran,
and write the ONNX policy and its report. A bad address exits 2 with a message naming it. The
cluster is stopped in a finally block, bounded in time (tests/pyhelpers/ray_cluster.py)."""

from __future__ import annotations

import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

from pyhelpers import REPO_ROOT
from pyhelpers.ray_cluster import ENV, free_port, start_cluster, stop_cluster

PY = REPO_ROOT / ".venv" / "bin" / "python"
RAY = REPO_ROOT / ".venv" / "bin" / "ray"


def train(tmp: pathlib.Path, address: str) -> subprocess.CompletedProcess[str]:
    argv = [str(PY), "-m", "autodrive.learn.marl", "train", "--address", address]
    argv += ["--stages", "1:1024", "--copies", "2", "--workers", "2"]
    argv += ["--onnx", str(tmp / "policy.onnx"), "--out", str(tmp / "out")]
    r = subprocess.run(argv, capture_output=True, text=True, timeout=900, env=ENV)
    print(r.stderr, file=sys.stderr)
    return r


def test_train_on_ray_cluster() -> None:
    tmp = tempfile.mkdtemp(prefix="adray-m", dir="/tmp")  # short: Ray's sockets live under it
    nodes: list[subprocess.Popen[bytes]] = []
    try:
        bad = train(pathlib.Path(tmp), f"127.0.0.1:{free_port()}")
        assert bad.returncode == 2 and "--address 127.0.0.1:" in bad.stderr, bad.stderr[-500:]
        address = start_cluster(RAY, tmp, [2], nodes)
        print(f"Ray cluster at {address}: 1 node, 2 CPUs", flush=True)
        r = train(pathlib.Path(tmp), address)
        assert r.returncode == 0, f"train --address exited {r.returncode}"
        assert f"rollouts on Ray cluster at {address}" in r.stderr, r.stderr[-800:]
        report = json.loads((pathlib.Path(tmp) / "out" / "train_report.json").read_text())
        assert report["agent_steps_done"] >= 1024, report["agent_steps_done"]
        assert report["config"]["ray_address"] == address, report["config"]
        assert (pathlib.Path(tmp) / "policy.onnx").stat().st_size > 1000
        print(f"trained {report['agent_steps_done']} agent steps on Ray actors at {address}")
    finally:
        stop_cluster(nodes, tmp)
        shutil.rmtree(tmp, ignore_errors=True)
