# The portable firmware core's sources and include dirs, shared by the host build
# (firmware/nano/CMakeLists.txt) and the AVR build. Excludes proto.c (target nano_proto).
set(_nano_lib "${CMAKE_CURRENT_LIST_DIR}")
set(NANO_CORE_SOURCES
  ${_nano_lib}/nigel/nigel_core.c
  ${_nano_lib}/fs/fs.c
  ${_nano_lib}/act/act.c
  ${_nano_lib}/lights/lights.c
  ${_nano_lib}/batt/batt.c
  ${_nano_lib}/wspd/wspd.c
  ${_nano_lib}/ahrs/ahrs.c)
set(NANO_PROTO_SOURCES ${_nano_lib}/proto/proto.c)
set(NANO_CORE_INCLUDE_DIRS
  ${_nano_lib}/nigel ${_nano_lib}/proto ${_nano_lib}/fs ${_nano_lib}/act ${_nano_lib}/lights
  ${_nano_lib}/batt ${_nano_lib}/wspd ${_nano_lib}/ahrs ${_nano_lib}/enc)
