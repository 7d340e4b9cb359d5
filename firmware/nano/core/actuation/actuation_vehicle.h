/* Generated from vehicle/nigel.params by autodrive.devtools.codegen.firmware_header
 * (tools/gen-docs): do not edit. The steering servo's figures as the firmware's integers. */
#ifndef AUTODRIVE_ACTUATION_VEHICLE_H
#define AUTODRIVE_ACTUATION_VEHICLE_H

/* Steering rate 0.805 rad/s over a 0.5236 rad full scale, in full scales per second
 * times 2^14: step [1e-6 full scale] = dt [us] * ACTUATION_STEER_RATE_Q14 >> 14. */
#define ACTUATION_STEER_RATE_Q14 25189L
/* Servo pulses [us]: straight ahead, change at full steering, full right, full left. */
#define ACTUATION_SERVO_CENTER_US 1500
#define ACTUATION_SERVO_HALF_RANGE_US 500
#define ACTUATION_SERVO_MIN_US 1000
#define ACTUATION_SERVO_MAX_US 2000

#endif /* AUTODRIVE_ACTUATION_VEHICLE_H */
