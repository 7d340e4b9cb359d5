/* Vehicle parameter file: "key = value [value...]" lines, '#' comments, SI units in the key
 * names. The MJCF of Nigel and every model constant (motor, servo, tyres, IMU) come from it.
 * A missing, unknown, duplicated or malformed key is an error naming the file and the key. */
#ifndef SIM_VEHICLE_PARAMS_H
#define SIM_VEHICLE_PARAMS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vehicle_params {
  /* body */
  double mass_kg;           /* whole car incl. wheels */
  double yaw_inertia_kg_m2; /* whole car about the CoM */
  double roll_pitch_inertia_kg_m2[2];
  double wheelbase_m, track_m, wheel_radius_m, wheel_width_m, wheel_mass_kg;
  double com_to_front_m;         /* CoM ahead of the rear axle = wheelbase - this */
  double com_height_m;           /* above the axle plane */
  double chassis_size_m[3];      /* collision box x y z, full lengths */
  double chassis_offset_m[3];    /* box centre relative to the rear axle centre */
  double knuckle_armature_kg_m2; /* steering knuckle inertia */
  double wheel_armature_kg_m2;   /* front wheel spin inertia added to the tyre */
  /* drive: one DC gearmotor per rear wheel, figures at the wheel */
  double motor_stall_torque_nm;
  double motor_noload_speed_rad_s; /* at motor_nominal_v */
  double motor_nominal_v;
  double motor_armature_kg_m2; /* rotor inertia reflected through the gearbox */
  double gearbox_friction_nm;  /* static friction of the gear train */
  double brake_hold_torque_nm; /* extra holding friction while the driver brakes */
  /* steering */
  double steer_limit_rad, steer_rate_rad_s;
  double servo_center_us, servo_us_per_full; /* pulse [us] at straight, per full lock */
  double steer_kp_nm_rad, steer_kv_nms_rad;  /* knuckle position loop */
  /* tyres */
  int tyre_model_paper; /* 1: paper slip model, 0: plain MuJoCo contact friction */
  double long_extremum[2], long_asymptote[2]; /* (slip, value) */
  double lat_extremum[2], lat_asymptote[2];   /* (tan slip angle, value) */
  double tyre_v_min_m_s;                      /* slip denominator floor at standstill */
  double tyre_rolling_resistance;             /* [N/N] */
  /* IMU (MPU-9250) */
  double imu_pos_m[3];
  double accel_noise_m_s2, gyro_noise_rad_s, mag_noise_ut;
  double accel_bias_m_s2, gyro_bias_rad_s; /* max |bias| per axis, drawn per car from seed */
  double mag_field_ut[3];                  /* world magnetic field */
  /* battery */
  double battery_v, battery_noise_v;
  /* sensor mounts, for the sensors library */
  double lidar_pos_m[3], tag_pos_m[3], tag_size_m;
  double cam_front_pos_m[3], cam_rear_pos_m[3];
} vehicle_params_t;

/* Loads path into p. Returns 0, or -1 with a message in err ("<file>:<line>: key '<k>': ..."). */
int vehicle_params_load(const char *path, vehicle_params_t *p, char *err, size_t err_sz);

#ifdef __cplusplus
}
#endif
#endif
