# AUTODRIVE_SANITIZE=ON builds everything with AddressSanitizer and UndefinedBehaviorSanitizer;
# tools/test runs the host tests that way (preset "asan"). Note: LCM 1.3.1's member-function
# subscribe() hands its callback a null subscription under UBSan: use subscribeFunction
# (lcm_types/include/autodrive_lcm/subscribe.hpp).
option(AUTODRIVE_SANITIZE "Build with ASan + UBSan" OFF)
if(AUTODRIVE_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
