# AUTODRIVE_SANITIZE=ON builds everything with AddressSanitizer and UndefinedBehaviorSanitizer;
# tools/test runs the host tests that way (preset "asan"). Note: LCM 1.3.1's member-function
# subscribe() hands its callback a null subscription under UBSan: use subscribeFunction
# (lcm_types/include/autodrive_lcm/subscribe.hpp).
option(AUTODRIVE_SANITIZE "Build with ASan + UBSan" OFF)
if(AUTODRIVE_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# AUTODRIVE_LSAN_OPTIONS: LeakSanitizer's options for every sanitized test and the programs it
# starts: the third-party suppressions (tests/lsan.supp), without printing their table (it pushed
# reports out of the log tails tests read). Tests take it as
# ENVIRONMENT_MODIFICATION "LSAN_OPTIONS=set:${AUTODRIVE_LSAN_OPTIONS}". The asan test preset
# (CMakePresets.json) keeps its own copy, since a preset cannot read a CMake variable;
# foundation.single_source checks that the two agree.
set(AUTODRIVE_LSAN_OPTIONS "suppressions=${PROJECT_SOURCE_DIR}/tests/lsan.supp:print_suppressions=0")

# autodrive_python_sanitizer_env(<list var>): appends to the list what a Python test needs to
# dlopen() this build's shared libraries (cffi) when they are sanitized: the ASan runtime (and
# libstdc++, whose __cxa_throw ASan intercepts) preloaded, leak detection on with the third-party
# suppressions (tests/lsan.supp: CPython's own memory at exit among them). Nothing without
# AUTODRIVE_SANITIZE. intercept_tls_get_addr=0: gcc 12's LeakSanitizer died in its own tracer at
# CPython's exit ("Tracer caught signal 11", reading a dynamic-TLS entry of an extension module),
# after the tests had passed, in pilot.train and then marl.ray_train, depending on nothing but the
# code's layout; without that tracking LSan scans no dynamic TLS, which can only add a false leak
# report, never hide one of ours.
function(autodrive_python_sanitizer_env var)
  if(AUTODRIVE_SANITIZE)
    execute_process(COMMAND ${CMAKE_C_COMPILER} -print-file-name=libasan.so
      OUTPUT_VARIABLE asan OUTPUT_STRIP_TRAILING_WHITESPACE)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=libstdc++.so.6
      OUTPUT_VARIABLE stdcxx OUTPUT_STRIP_TRAILING_WHITESPACE)
    set(${var} ${${var}} "LD_PRELOAD=${asan}:${stdcxx}"
      "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:verify_asan_link_order=0:intercept_tls_get_addr=0"
      "LSAN_OPTIONS=${AUTODRIVE_LSAN_OPTIONS}" PARENT_SCOPE)
  endif()
endfunction()
