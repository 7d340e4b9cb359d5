# libFuzzer targets for the runtime's receive decoders (bridge_rx: HELLO/STATE/NACK from the
# Nano; rplidar: the A1 decoder), built with Debian's clang-14 outside the gcc build
# (tools/fuzz-runtime --build holds the compile commands). Each ctest smoke run is a fixed
# number of runs (seconds); longer runs: tools/fuzz-runtime <target> <seconds>.
find_program(AUTODRIVE_CLANGXX14 clang++-14)
file(GLOB _rt_fuzz_rt "/usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a")
if(AUTODRIVE_CLANGXX14 AND _rt_fuzz_rt)
  set(_rt "${AUTODRIVE_ROOT}/runtime/jetson")
  set(_bridge ${_rt}/drivers/nano_bridge)
  set(_rplidar ${_rt}/drivers/rplidar)
  set(_deps_bridge_rx ${_bridge}/src/bridge_convert.cpp
      ${_bridge}/include/autodrive/nano_bridge/bridge_convert.hpp
      ${_rt}/core/include/autodrive/core/config.hpp ${AUTODRIVE_ROOT}/firmware/nano/core/protocol/protocol.c)
  set(_deps_rplidar ${_rplidar}/src/rplidar_decoder.cpp
      ${_rplidar}/include/autodrive/rplidar/rplidar_decoder.hpp)
  foreach(t bridge_rx rplidar)
    set(_bin "${CMAKE_CURRENT_BINARY_DIR}/fuzz/fuzz_${t}")
    add_custom_command(
      OUTPUT ${_bin}
      COMMAND ${AUTODRIVE_ROOT}/tools/fuzz-runtime --build ${t} ${_bin} ${CMAKE_BINARY_DIR}
      DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_${t}.cpp ${AUTODRIVE_ROOT}/tools/fuzz-runtime
              ${_deps_${t}}
      COMMENT "clang-14 libFuzzer build: fuzz_${t}"
      VERBATIM)
    add_custom_target(fuzz_${t} ALL DEPENDS ${_bin})
    add_dependencies(fuzz_${t} autodrive_vehicle_gen autodrive_channels_gen autodrive_lcm_gen)
    file(MAKE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}/fuzz/corpus_${t}")
    add_test(NAME runtime.fuzz_${t}_smoke
      COMMAND ${_bin} -runs=200000 -max_total_time=20 -seed=1 -timeout=5 -print_final_stats=1
              ${CMAKE_CURRENT_BINARY_DIR}/fuzz/corpus_${t}
      WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
    set_tests_properties(runtime.fuzz_${t}_smoke PROPERTIES TIMEOUT 120)
  endforeach()
else()
  message(WARNING "clang-14 / libFuzzer runtime not found: runtime.fuzz_*_smoke skipped "
                  "(install clang-14 and libclang-rt-14-dev)")
endif()
