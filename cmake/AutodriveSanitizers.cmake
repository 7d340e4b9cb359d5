# AUTODRIVE_SANITIZE=ON builds everything with AddressSanitizer and UndefinedBehaviorSanitizer;
# tools/test runs the host tests that way (preset "asan").
option(AUTODRIVE_SANITIZE "Build with ASan + UBSan" OFF)
if(AUTODRIVE_SANITIZE)
  # vptr off: LCM 1.3.1's lcm-cpp.hpp member-function subscribe casts through void* in a way
  # GCC's vptr check rejects (a false report that aborts every C++ LCM subscriber).
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=vptr -fno-omit-frame-pointer
                      -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
