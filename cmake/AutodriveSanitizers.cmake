# AUTODRIVE_SANITIZE=ON builds everything with AddressSanitizer and UndefinedBehaviorSanitizer;
# tools/test runs the host tests that way (preset "asan").
option(AUTODRIVE_SANITIZE "Build with ASan + UBSan" OFF)
if(AUTODRIVE_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
