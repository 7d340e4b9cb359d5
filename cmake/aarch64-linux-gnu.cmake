# CMake toolchain for the Jetson (aarch64, Linux) from this amd64 Debian machine: Debian's cross
# gcc (crossbuild-essential-arm64) against the arm64 sysroot tools/setup --aarch64 unpacks into
# build/aarch64/sysroot (Debian bookworm's arm64 -dev packages and their Depends). Test programs
# run under qemu-user (qemu-aarch64-static -L <sysroot>), also for gtest_discover_tests.
# Used by tools/test --aarch64 (tools/lib.sh: build_aarch64).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

get_filename_component(_repo "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(AUTODRIVE_AARCH64_SYSROOT "${_repo}/build/aarch64/sysroot" CACHE PATH "arm64 sysroot")
if(NOT EXISTS "${AUTODRIVE_AARCH64_SYSROOT}/usr/include/aarch64-linux-gnu")
  message(FATAL_ERROR "no arm64 sysroot in ${AUTODRIVE_AARCH64_SYSROOT}: run tools/setup --aarch64")
endif()
set(CMAKE_SYSROOT "${AUTODRIVE_AARCH64_SYSROOT}")

find_program(AARCH64_GCC aarch64-linux-gnu-gcc REQUIRED)
find_program(AARCH64_GXX aarch64-linux-gnu-g++ REQUIRED)
set(CMAKE_C_COMPILER "${AARCH64_GCC}")
set(CMAKE_CXX_COMPILER "${AARCH64_GXX}")

# Host programs (lcm-gen, python) from this machine; headers, libraries, CMake packages only
# from the sysroot.
set(CMAKE_FIND_ROOT_PATH "${AUTODRIVE_AARCH64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${AUTODRIVE_AARCH64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${AUTODRIVE_AARCH64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${AUTODRIVE_AARCH64_SYSROOT}/usr/share/pkgconfig")

# The libraries' own dependencies resolve inside the sysroot at link time.
set(_libdirs "${AUTODRIVE_AARCH64_SYSROOT}/usr/lib/aarch64-linux-gnu"
             "${AUTODRIVE_AARCH64_SYSROOT}/lib/aarch64-linux-gnu")
foreach(d ${_libdirs})
  string(APPEND CMAKE_EXE_LINKER_FLAGS_INIT " -Wl,-rpath-link,${d}")
  string(APPEND CMAKE_SHARED_LINKER_FLAGS_INIT " -Wl,-rpath-link,${d}")
endforeach()

find_program(QEMU_AARCH64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${QEMU_AARCH64};-L;${AUTODRIVE_AARCH64_SYSROOT}")
