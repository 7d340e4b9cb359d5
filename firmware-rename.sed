# Issue 42, firmware layout: rewrites references to the Nano firmware's old paths and names.
# firmware/nano/lib/<module> -> firmware/nano/core/<spelled-out module>, firmware/nano/src ->
# firmware/nano/hal_avr, and the modules' C prefixes spelled out. Run by firmware-rename.sh
# (GNU sed -E). Idempotent: no new name matches an old pattern, so running it twice is harmless.
# Only the modules' declared API is renamed, word by word; wire fields (enc_counts,
# proto_version, fw_major...) stay, because the schema hash is computed from their names.

# ---- paths: folders and files (files first, then the folders they sit in) ---------------
s#firmware/nano/lib\b#firmware/nano/core#g
s#firmware/nano/src\b#firmware/nano/hal_avr#g
s#\bfs/fs\.([ch])\b#failsafe/failsafe.\1#g
s#\bwspd/wspd\.([ch])\b#wheel_speed/wheel_speed.\1#g
s#\bact/act_vehicle\.h\b#actuation/actuation_vehicle.h#g
s#\bact/act\.([ch])\b#actuation/actuation.\1#g
s#\benc/enc\.h\b#encoder/encoder.h#g
s#\bbatt/batt\.([ch])\b#battery/battery.\1#g
s#\bproto/proto\.([ch])\b#protocol/protocol.\1#g
s#\bnigel/nigel_core\.([ch])\b#nano_core/nano_core.\1#g
s#\bnigel/nigel_hal\.h\b#nano_core/nano_core_hal.h#g
s#(^|[^$A-Za-z0-9_])lib/(fs|wspd|act|enc|batt|proto|nigel)\b#\1core/\2#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/fs\b#\1/failsafe#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/wspd\b#\1/wheel_speed#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/act\b#\1/actuation#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/enc\b#\1/encoder#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/batt\b#\1/battery#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/proto\b#\1/protocol#g
s#(\bcore|\$lib|\$LIB|_nano_lib\})/nigel\b#\1/nano_core#g
# headers as included (flat include directories: #include "fs.h") and named in prose
s#\bfs\.([ch])\b#failsafe.\1#g
s#\bwspd\.([ch])\b#wheel_speed.\1#g
s#\bact_vehicle\.h\b#actuation_vehicle.h#g
s#\bact\.([ch])\b#actuation.\1#g
s#\benc\.h\b#encoder.h#g
s#\bbatt\.([ch])\b#battery.\1#g
s#\bproto\.([ch])\b#protocol.\1#g
s#\bnigel_core\.([ch])\b#nano_core.\1#g
s#\bnigel_hal\.h\b#nano_core_hal.h#g
s#\bfw_enc\.([ch])\b#hal_avr_encoder.\1#g
s#\bfw_(imu|io|pins|twi|uart)\.([ch])\b#hal_avr_\1.\2#g

# ---- CMake targets ----------------------------------------------------------------------
s#\bnano_proto\b#nano_protocol#g
s#\bnano_enc\b#nano_encoder#g
s#\bNANO_PROTO_SOURCES\b#NANO_PROTOCOL_SOURCES#g
s#\bnigel_core_avr\b#nano_core_avr#g

# ---- failsafe (was fs) --------------------------------------------------------------------
s#\bAUTODRIVE_FS_H\b#AUTODRIVE_FAILSAFE_H#g
s#\bFS_DEFAULT_TIMEOUT_MS\b#FAILSAFE_DEFAULT_TIMEOUT_MS#g
s#\bfs_(t|init|set_timeout_ms|on_command|update|may_drive)\b#failsafe_\1#g
s#\bstruct fs\b#struct failsafe#g
# the core's members (nano_core_t.failsafe, .actuation, .battery, .wheel_speed), by their fields
# where the short name is common (->act is MuJoCo's mjData.act)
s#->fs\b#->failsafe#g
s#(&[A-Za-z_][A-Za-z0-9_]*)\.fs\b#\1.failsafe#g
s#\.fs\.(last_cmd_us|timeout_us|mode|fresh|prev_disengaged|link_lost)\b#.failsafe.\1#g
s#(\.|->)act\.(throttle_u|steering_u|last_us|trim_us|servo_us|duty|reverse|brake|decelerating)\b#\1actuation.\2#g
s#(\.|->)batt\.(mv_x256|have|low|cutoff)\b#\1battery.\2#g
s#(\.|->)wspd\.(prev_counts|speed_x16|last_us|have)\b#\1wheel_speed.\2#g
s#\bbatt_next_us\b#battery_next_us#g

# ---- wheel_speed (was wspd) ---------------------------------------------------------------
s#\bAUTODRIVE_WSPD_H\b#AUTODRIVE_WHEEL_SPEED_H#g
s#\bWSPD_(PERIOD_US|FILTER_SHIFT|MAX_DELTA|MRAD_US_PER_COUNT)\b#WHEEL_SPEED_\1#g
s#\bwspd_(t|init|update|mrad_s)\b#wheel_speed_\1#g
s#\bstruct wspd\b#struct wheel_speed#g

# ---- actuation (was act) ------------------------------------------------------------------
s#\bAUTODRIVE_ACT_H\b#AUTODRIVE_ACTUATION_H#g
s#\bAUTODRIVE_ACT_VEHICLE_H\b#AUTODRIVE_ACTUATION_VEHICLE_H#g
s#\bACT_(FULL|THROTTLE_SLEW_PER_S|MAX_DT_US|STOP|HOLD_STEERING|STEER_RATE_Q14|SERVO_CENTER_US|SERVO_HALF_RANGE_US|SERVO_MIN_US|SERVO_MAX_US)\b#ACTUATION_\1#g
s#\bact_(t|init|update|throttle_milli|steering_milli)\b#actuation_\1#g
s#\bstruct act\b#struct actuation#g

# ---- encoder (was enc) --------------------------------------------------------------------
s#\bAUTODRIVE_ENC_H\b#AUTODRIVE_ENCODER_H#g
s#\bENC_COUNTS_PER_REV\b#ENCODER_COUNTS_PER_REV#g
s#\benc_(t|init|edge_a)\b#encoder_\1#g
s#\bstruct enc\b#struct encoder#g

# ---- battery (was batt) -------------------------------------------------------------------
s#\bAUTODRIVE_BATT_H\b#AUTODRIVE_BATTERY_H#g
s#\bBATT_(WARN_MV|WARN_CLEAR_MV|CUTOFF_MV|CUTOFF_CLEAR_MV|PERIOD_US|FILTER_SHIFT)\b#BATTERY_\1#g
s#\bbatt_(t|init|update|mv)\b#battery_\1#g
s#\bstruct batt\b#struct battery#g

# ---- protocol (was proto) -----------------------------------------------------------------
# Every PROTO_ macro and enum, and the prefixes written in comments (PROTO_FAULT_*).
s#\bAUTODRIVE_PROTO_H\b#AUTODRIVE_PROTOCOL_H#g
s#\bPROTO_([A-Z0-9_]*)#PROTOCOL_\1#g
s#\bproto_(command|config|hello|state|nack)_(t|pack|unpack|valid)\b#protocol_\1_\2#g
s#\bproto_(frame_t|frame_cb|frame_encode|parser_t|parser_init|parser_feed|stats_t|crc16|schema_hash)\b#protocol_\1#g
s#\bstruct proto_(command|config|hello|state|nack|frame|stats|parser)\b#struct protocol_\1#g

# ---- nano_core (was nigel): the core object, its HAL and its timing ---------------------
# Kept: NIGEL_FW_MAJOR/MINOR/PATCH, NIGEL_BUILD_ID, NIGEL_FW_TEST_HOOKS, NIGEL_PLATFORMIO,
# NIGEL_ARDUINO_AVR_DIR (the firmware image's identity and build switches) and nigel_nano.elf.
s#\bAUTODRIVE_NIGEL_CORE_H\b#AUTODRIVE_NANO_CORE_H#g
s#\bAUTODRIVE_NIGEL_HAL_H\b#AUTODRIVE_NANO_CORE_HAL_H#g
s#\bNIGEL_LAMP_([A-Z_]*)#NANO_CORE_LAMP_\1#g
s#\bNIGEL_BATT_OFFSET_US\b#NANO_CORE_BATTERY_OFFSET_US#g
s#\bNIGEL_(IMU_PERIOD_US|IMU_OFFSET_US|LOOP_OVERRUN_US|DEFAULT_TELEMETRY_MS)\b#NANO_CORE_\1#g
s#\bnigel_(t|init|rx|step|faults|state|hal_t|imu_raw_t)\b#nano_core_\1#g
s#\bstruct nigel_(hal|imu_raw)\b#struct nano_core_\1#g
s#\bstruct nigel\b#struct nano_core#g

# ---- hal_avr (was src, prefix fw_) ------------------------------------------------------
# Kept: fw_build_id (the build's stamp header and target) and the HELLO fields fw_major...
s#\bNIGEL_FW_(ENC|IMU|IO|PINS|TWI|UART)_H\b#AUTODRIVE_HAL_AVR_\1_H#g
s#\bAUTODRIVE_HAL_AVR_ENC_H\b#AUTODRIVE_HAL_AVR_ENCODER_H#g
s#\bFW_ENC_(LEFT|RIGHT)_INVERT\b#HAL_AVR_ENCODER_\1_INVERT#g
s#\bFW_BATT_(R_TOP_OHM|R_BOTTOM_OHM|ADC_CHANNEL)\b#HAL_AVR_BATTERY_\1#g
s#\bFW_(ADC_REF_MV|F_CPU_HZ|IMU_[A-Z_]+|TWI_[A-Z]+|UART_[A-Z_]+)\b#HAL_AVR_\1#g
s#\bfw_enc_(init|read)\b#hal_avr_encoder_\1#g
s#\bfw_(imu_init|imu_poll|imu_read|io_init|io_capture_mcusr|servo_set_us|motor_set|lamps_set|battery_read_mv|reset_cause|wdt_start|wdt_kick|twi_init|twi_start|twi_status|twi_abort|uart_init|uart_read|uart_rx_pending|uart_write|uart_rx_lost|uart_tx_dropped|loop_once|sleep_until_work|test_hang)\b#hal_avr_\1#g
