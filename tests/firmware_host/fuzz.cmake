# libFuzzer target for the parser + core receive path, built with Debian's clang-14 outside
# the gcc build (tools/fuzz-parser --build holds the one compile command). The ctest smoke run
# is ~10 s; longer runs: tools/fuzz-parser <seconds>.
find_program(AUTODRIVE_CLANG14 clang-14)
file(GLOB _fuzz_rt_found "/usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a")
if(NOT CMAKE_CROSSCOMPILING AND AUTODRIVE_CLANG14 AND _fuzz_rt_found)
  set(_fuzz_bin "${CMAKE_CURRENT_BINARY_DIR}/fuzz/fuzz_parser")
  add_custom_command(
    OUTPUT ${_fuzz_bin}
    COMMAND ${AUTODRIVE_ROOT}/tools/fuzz-parser --build ${_fuzz_bin}
    DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/fuzz_parser.c ${AUTODRIVE_ROOT}/tools/fuzz-parser
            ${NANO_CORE_SOURCES} ${NANO_PROTOCOL_SOURCES}
    COMMENT "clang-14 libFuzzer build: fuzz_parser"
    VERBATIM)
  add_custom_target(fuzz_parser ALL DEPENDS ${_fuzz_bin})
  set(_corpus "${CMAKE_CURRENT_BINARY_DIR}/fuzz/corpus")
  file(MAKE_DIRECTORY ${_corpus})
  add_test(NAME firmware.fuzz_parser_smoke
    COMMAND ${_fuzz_bin} -max_total_time=10 -seed=1 -timeout=5 -print_final_stats=1 ${_corpus}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
  set_tests_properties(firmware.fuzz_parser_smoke PROPERTIES TIMEOUT 120)
else()
  message(WARNING "clang-14 / libFuzzer runtime not found: firmware.fuzz_parser_smoke skipped "
                  "(install clang-14 and libclang-rt-14-dev)")
endif()
