"""HIL integration: the full demo (tools/demo.py --mission parking): simulator + unchanged
runtime + autodrive-autonomy over real UDP LCM. It must map, localise, plan and park without a
collision, and end near the slot by the simulator's ground truth."""
import json
import pathlib
import subprocess
import sys
import tempfile

root, build, port = pathlib.Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
with tempfile.TemporaryDirectory(prefix="hil-park-") as tmp:
    r = subprocess.run([sys.executable, str(root / "tools" / "demo.py"), "--build", build,
                        "--out", tmp, "--mission", "parking", "--realtime", "--headless",
                        "--timeout", "200", "--lcm-url", f"udpm://239.255.76.67:{port}?ttl=0"],
                       timeout=280)
    report = json.loads((pathlib.Path(tmp) / "report.json").read_text())
    print(json.dumps(report, indent=2))
    assert r.returncode == 0, f"demo exited {r.returncode}"
    assert report["success"], "the mission did not end PARKED"
    assert report["collisions"] == 0
    # The goals are 0.02 m / 2 deg; this bound catches a broken chain, not tuning.
    assert report["final_pos_error_m"] < 0.08, "parked far from the slot"
    assert report["final_heading_error_deg"] < 8.0
    assert (pathlib.Path(tmp) / "parking.png").stat().st_size > 1000, "parking plot missing"
print("hil parking ok")
