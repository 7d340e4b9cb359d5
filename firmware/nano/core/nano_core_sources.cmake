# The portable firmware core's sources and include dirs, shared by the host build
# (firmware/nano/CMakeLists.txt) and the AVR build. Excludes protocol.c (target nano_protocol).
set(_nano_core "${CMAKE_CURRENT_LIST_DIR}")
set(NANO_CORE_SOURCES
  ${_nano_core}/nano_core/nano_core.c
  ${_nano_core}/failsafe/failsafe.c
  ${_nano_core}/actuation/actuation.c
  ${_nano_core}/lights/lights.c
  ${_nano_core}/battery/battery.c
  ${_nano_core}/wheel_speed/wheel_speed.c
  ${_nano_core}/ahrs/ahrs.c)
set(NANO_PROTOCOL_SOURCES ${_nano_core}/protocol/protocol.c)
set(NANO_CORE_INCLUDE_DIRS
  ${_nano_core}/nano_core ${_nano_core}/protocol ${_nano_core}/failsafe ${_nano_core}/actuation ${_nano_core}/lights
  ${_nano_core}/battery ${_nano_core}/wheel_speed ${_nano_core}/ahrs ${_nano_core}/encoder)
