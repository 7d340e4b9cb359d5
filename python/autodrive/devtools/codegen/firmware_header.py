"""vehicle/nigel.params -> firmware/nano/core/actuation/actuation_vehicle.h: the servo figures
the Nano's actuator mapping needs, as integers (the AVR has no FPU, and PlatformIO builds the
firmware without running Python, so this header is generated into the tree and checked for
freshness)."""

from __future__ import annotations

from autodrive.core import vehicle

PATH = "firmware/nano/core/actuation/actuation_vehicle.h"
Q14 = 1 << 14


def steer_rate_q14(car: vehicle.Vehicle) -> int:
    """Servo rate as full scales per second in Q14: rate [rad/s] / limit [rad] * 2^14."""
    return round(car.number("steer_rate_rad_s") / car.number("steer_limit_rad") * Q14)


def render(car: vehicle.Vehicle, source_name: str) -> str:
    center_us = round(car.number("servo_center_us"))
    half_us = round(car.number("servo_us_per_full"))
    rate = car.number("steer_rate_rad_s")
    limit = car.number("steer_limit_rad")
    return "\n".join(
        [
            f"/* Generated from {source_name} by autodrive.devtools.codegen.firmware_header",
            " * (tools/gen-docs): do not edit. The steering servo's figures as the firmware's integers. */",
            "#ifndef AUTODRIVE_ACTUATION_VEHICLE_H",
            "#define AUTODRIVE_ACTUATION_VEHICLE_H",
            "",
            f"/* Steering rate {rate} rad/s over a {limit} rad full scale, in full scales per second",
            " * times 2^14: step [1e-6 full scale] = dt [us] * ACTUATION_STEER_RATE_Q14 >> 14. */",
            f"#define ACTUATION_STEER_RATE_Q14 {steer_rate_q14(car)}L",
            "/* Servo pulses [us]: straight ahead, change at full steering, full right, full left. */",
            f"#define ACTUATION_SERVO_CENTER_US {center_us}",
            f"#define ACTUATION_SERVO_HALF_RANGE_US {half_us}",
            f"#define ACTUATION_SERVO_MIN_US {center_us - half_us}",
            f"#define ACTUATION_SERVO_MAX_US {center_us + half_us}",
            "",
            "#endif /* AUTODRIVE_ACTUATION_VEHICLE_H */",
            "",
        ]
    )
