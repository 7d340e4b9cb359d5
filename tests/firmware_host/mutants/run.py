#!/usr/bin/env python3
"""Mutation test of the safety logic: applies one small bug at a time to a copy of the
firmware core (failsafe, command handling, actuators, battery), rebuilds the host tests against
it and checks that the tests catch it. Prints each mutant and "killed" or "SURVIVED"; the last
line is JSON. Usage: tests/firmware_host/mutants/run.py [--keep] [workdir]
Exit status 1 if a mutant survives (the tests missed a bug)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CORE = os.path.join(ROOT, "firmware", "nano", "core")
TESTS = os.path.join(ROOT, "tests", "firmware_host")
MODULES = [
    "nano_core",
    "protocol",
    "failsafe",
    "actuation",
    "lights",
    "battery",
    "wheel_speed",
    "ahrs",
    "encoder",
]
C_SOURCES = [
    "protocol/protocol.c",
    "nano_core/nano_core.c",
    "failsafe/failsafe.c",
    "actuation/actuation.c",
    "lights/lights.c",
    "battery/battery.c",
    "wheel_speed/wheel_speed.c",
    "ahrs/ahrs.c",
]

# (file, exact text, replacement, what the bug means)
MUTANTS = [
    (
        "failsafe/failsafe.c",
        "< f->timeout_us) return;",
        "<= f->timeout_us) return;",
        "timeout one tick late",
    ),
    ("failsafe/failsafe.c", "    f->link_lost = 1;\n", "", "link loss not latched"),
    (
        "failsafe/failsafe.c",
        "  failsafe_update(f, now_us);\n  f->last_cmd_us",
        "  f->last_cmd_us",
        "late command hides the gap",
    ),
    (
        "failsafe/failsafe.c",
        "  if (!f->prev_disengaged) return 0;",
        "",
        "arming without the engaged=0 edge",
    ),
    (
        "failsafe/failsafe.c",
        "  f->prev_disengaged = 0;\n  if (f->mode == PROTOCOL_MODE_ENGAGED) {",
        "  if (f->mode == PROTOCOL_MODE_ENGAGED) {",
        "stale engaged=0 still arms",
    ),
    (
        "failsafe/failsafe.c",
        "    if (f->mode == PROTOCOL_MODE_ENGAGED) f->mode = PROTOCOL_MODE_DISARMED;",
        "",
        "disengage ignored",
    ),
    (
        "failsafe/failsafe.c",
        "  f->link_lost = 0;\n  return 1;",
        "  return 1;",
        "re-arm keeps the fault",
    ),
    (
        "failsafe/failsafe.c",
        "    f->mode = PROTOCOL_MODE_FAILSAFE;",
        "    f->mode = PROTOCOL_MODE_DISARMED;",
        "link loss without failsafe mode",
    ),
    (
        "nano_core/nano_core.c",
        "  if (!protocol_command_valid(&c)) {",
        "  if (0) {",
        "no range check",
    ),
    (
        "nano_core/nano_core.c",
        "    n->faults_latched |= PROTOCOL_FAULT_CMD_INVALID;\n",
        "",
        "invalid command not flagged",
    ),
    ("nano_core/nano_core.c", "  n->cmd = c;\n}", "}", "valid command not applied"),
    (
        "nano_core/nano_core.c",
        "  if (n->battery.cutoff) actuation_flags |= ACTUATION_STOP;",
        "",
        "battery cut-off ignored",
    ),
    (
        "nano_core/nano_core.c",
        "  if (!failsafe_may_drive(&n->failsafe)) actuation_flags = ACTUATION_STOP | ACTUATION_HOLD_STEERING;",
        "  if (!failsafe_may_drive(&n->failsafe)) actuation_flags = ACTUATION_HOLD_STEERING;",
        "drives while not engaged",
    ),
    (
        "nano_core/nano_core.c",
        "n->failsafe.mode == PROTOCOL_MODE_FAILSAFE ? 3u : n->cmd.indicators",
        "n->cmd.indicators",
        "no hazards in failsafe",
    ),
    (
        "nano_core/nano_core.c",
        "  failsafe_update(&n->failsafe, now_us);\n",
        "",
        "failsafe not checked in the loop",
    ),
    (
        "nano_core/nano_core.c",
        "  failsafe_set_timeout_ms(&n->failsafe, c.failsafe_timeout_ms);",
        "",
        "timeout config ignored",
    ),
    (
        "nano_core/nano_core.c",
        "  if (!protocol_config_valid(&c)) {",
        "  if (0) {",
        "config not validated",
    ),
    (
        "actuation/actuation.c",
        "    a->throttle_u = 0; /* stopping is never slew-limited */",
        "    a->throttle_u = move_toward(a->throttle_u, 0, (int32_t)dt_us * 4);",
        "stop is slew-limited",
    ),
    (
        "actuation/actuation.c",
        "  a->brake = (uint8_t)(stop || a->duty == 0u);",
        "  a->brake = (uint8_t)(a->duty == 0u && !stop);",
        "no brake on stop",
    ),
    (
        "actuation/actuation.c",
        "(int32_t)dt_us * (ACTUATION_THROTTLE_SLEW_PER_S / 1000000L)",
        "(int32_t)dt_us * 40",
        "slew limit 10x too loose",
    ),
    (
        "actuation/actuation.c",
        "(int32_t)((dt_us * (uint32_t)ACTUATION_STEER_RATE_Q14) >> 14)",
        "(int32_t)((dt_us * (uint32_t)ACTUATION_STEER_RATE_Q14) >> 12)",
        "steering rate 4x too fast",
    ),
    (
        "actuation/actuation.c",
        "  if (pulse > ACTUATION_SERVO_MAX_US) pulse = ACTUATION_SERVO_MAX_US;",
        "",
        "no servo saturation",
    ),
    (
        "battery/battery.c",
        "  else if (mv > BATTERY_CUTOFF_CLEAR_MV)\n    b->cutoff = 0;",
        "  else\n    b->cutoff = 0;",
        "no cut-off hysteresis",
    ),
    ("lights/lights.c", "  if (braking) lamps |= NANO_CORE_LAMP_TAIL;", "", "no taillights"),
    ("protocol/protocol.c", "    if (crc != crc_rx) {", "    if (0) {", "CRC not checked"),
]


def run(cmd, cwd=None):
    return subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def main():
    args = [a for a in sys.argv[1:] if a != "--keep"]
    if any(a in ("-h", "--help") for a in args):
        print(__doc__)
        return 0
    work = args[0] if args else tempfile.mkdtemp(prefix="fw-mutants-")
    os.makedirs(work, exist_ok=True)
    incs = []
    # test objects once (they do not change between mutants)
    objs = []
    for t in ["test_codec.cpp", "test_core.cpp", "test_modules.cpp"]:
        o = os.path.join(work, t + ".o")
        r = run(
            ["g++", "-std=c++17", "-O1", "-c", os.path.join(TESTS, t), "-o", o, "-I" + TESTS]
            + ["-I" + os.path.join(CORE, m) for m in MODULES]
        )
        if r.returncode != 0:
            print(r.stdout)
            return 2
        objs.append(o)
    results = []
    # the unmutated core first: it must pass, or every "kill" below would mean nothing
    baseline = [("failsafe/failsafe.c", "", "", "baseline (no mutation)")]
    for i, (f, old, new, what) in enumerate(baseline + MUTANTS):
        i -= 1
        lib = os.path.join(work, "lib%d" % i)
        if os.path.exists(lib):
            shutil.rmtree(lib)
        shutil.copytree(CORE, lib)
        path = os.path.join(lib, f)
        src = open(path).read()
        if i >= 0 and src.count(old) != 1:
            print(
                "mutant %d (%s): text not found exactly once in %s: fix the mutant list"
                % (i, what, f)
            )
            return 2
        if i >= 0:
            open(path, "w").write(src.replace(old, new))
        exe = os.path.join(work, "t%d" % i)
        cmd = (
            ["g++", "-O1", "-o", exe]
            + objs
            + ["-x", "c", "-std=c99"]
            + [os.path.join(lib, s) for s in C_SOURCES]
            + ["-I" + os.path.join(lib, m) for m in MODULES]
            + ["-x", "none", "-lgtest", "-lgtest_main", "-lpthread", "-lm"]
        )
        r = run(cmd)
        if r.returncode != 0:
            status = "killed (does not build)"
        else:
            r = run([exe, "--gtest_brief=1"])
            status = "killed" if r.returncode != 0 else "SURVIVED"
        if i < 0:
            print(
                "[baseline ] unmutated core: %s"
                % ("tests pass" if status == "SURVIVED" else "TESTS FAIL"),
                flush=True,
            )
            if status != "SURVIVED":
                return 2
            continue
        results.append((f, what, status))
        print("[mutant %2d] %-26s %-36s %s" % (i, f, what, status), flush=True)
        if "--keep" not in sys.argv:
            shutil.rmtree(lib)
    killed = sum(1 for r in results if r[2].startswith("killed"))
    print(
        json.dumps({"mutants": len(results), "killed": killed, "survived": len(results) - killed})
    )
    return 0 if killed == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
