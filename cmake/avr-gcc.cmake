# CMake toolchain for the Arduino Nano (ATmega328P, 16 MHz) with Debian's avr-gcc 5.4.
# Used by firmware/nano/avr (tools/lib.sh: build_avr). Only the compilers are set here; the
# MCU flags live in firmware/nano/avr/CMakeLists.txt so one place owns them.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR avr)

find_program(AVR_GCC avr-gcc REQUIRED)
find_program(AVR_GXX avr-g++ REQUIRED)
find_program(AVR_OBJCOPY avr-objcopy REQUIRED)
find_program(AVR_SIZE avr-size REQUIRED)
set(CMAKE_C_COMPILER "${AVR_GCC}")
set(CMAKE_CXX_COMPILER "${AVR_GXX}")
set(CMAKE_ASM_COMPILER "${AVR_GCC}")
# The LTO-aware archiver, so -flto objects in static libraries keep their IR.
find_program(CMAKE_AR avr-gcc-ar REQUIRED)
find_program(CMAKE_RANLIB avr-gcc-ranlib REQUIRED)

# No host libraries or headers may leak into the AVR build.
set(CMAKE_FIND_ROOT_PATH /usr/lib/avr)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
# A cross compiler cannot link a test program without MCU flags: check with a static library.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
