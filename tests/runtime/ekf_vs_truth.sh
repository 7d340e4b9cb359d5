#!/usr/bin/env bash
# runtime.e2e.ekf_vs_ground_truth: autodrive-sim + autodrive-runtime (bridge, estimator) +
# runtime-link-bench ekf (drives a loop, feeds Eye poses made from ground truth) for a short
# loop; checks the EKF's map-frame errors against the simulator's ground truth. Accuracy, not
# time, is asserted. usage: ekf_vs_truth.sh <bin dir> <repo root> <lcm port> <seconds>
set -euo pipefail
BIN="$1"; ROOT="$2"; PORT="$3"; SECONDS_LOOP="$4"
W="$(mktemp -d /tmp/adr-rt-ekf.XXXXXX)"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; rm -rf "$W"; }
trap cleanup EXIT
URL="udpm://239.255.76.67:$PORT?ttl=0"
# A test key for the car, seen by the runtime's bridge and by runtime-link-bench (mode 0600).
export AUTODRIVE_KEY_DIR="$W/keys"
mkdir -m 700 "$AUTODRIVE_KEY_DIR"
(umask 077; od -An -tx1 -N32 /dev/urandom | tr -d ' \n' > "$AUTODRIVE_KEY_DIR/NIGEL1.key"; echo >> "$AUTODRIVE_KEY_DIR/NIGEL1.key")
# The testbed's authority and certificates: runtime-link-bench signs its Eye poses as EYE.
"$ROOT/tools/keys" testbed --cars 1 >/dev/null
"$BIN/autodrive-sim" --run-dir "$W/sim" --lcm-url "$URL" --no-lidar --quiet >"$W/sim.log" 2>&1 &
PIDS+=($!)
for _ in $(seq 600); do [ -e "$W/sim/nigel1-nano" ] && break; sleep 0.1; done
[ -e "$W/sim/nigel1-nano" ] || { echo "no sim pty"; cat "$W/sim.log"; exit 1; }
sed -e "s#/dev/nigel-nano#$W/sim/nigel1-nano#" -e "s#:7667#:$PORT#" -e '/^lidar:/,/^  range_max_m:/d' \
    -e '/^cameras:/,/^    jpeg_quality:/d' "$ROOT/runtime/jetson/config/nigel_car.yaml" > "$W/rt.yaml"
"$BIN/autodrive-runtime" --config "$W/rt.yaml" --only bridge,estimator --log-level warn >"$W/rt.log" 2>&1 &
PIDS+=($!)
OUT="$("$BIN/runtime-link-bench" ekf --lcm-url "$URL" --seconds "$SECONDS_LOOP")"
echo "$OUT"
python3 - "$OUT" <<'PY'
import json, sys
r = json.loads(sys.argv[1])
ok = True
def check(cond, what):
    global ok
    print(("ok   " if cond else "FAIL ") + what)
    ok = ok and cond
check(r["ekf_samples"] > 100, "map estimates compared: %d" % r["ekf_samples"])
check(r["ekf_path_m"] > 0.1, "car drove: %.2f m" % r["ekf_path_m"])
check(r["ekf_pos_rms_m"] <= 0.03, "Eye-on position RMS %.4f m <= 0.03" % r["ekf_pos_rms_m"])
check(r["ekf_heading_rms_deg"] <= 2.0, "Eye-on heading RMS %.3f deg <= 2" % r["ekf_heading_rms_deg"])
check(r["ekf_pos_rms_m_no_eye"] < 0.5, "odometry-only position RMS %.4f m < 0.5 (sane)" % r["ekf_pos_rms_m_no_eye"])
sys.exit(0 if ok else 1)
PY
