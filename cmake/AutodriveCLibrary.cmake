# autodrive_c_library(<name> <include dir> <sources>...): a plain C11 library built twice from
# the same sources: static <name> for the C and C++ programs, and shared <name>_shared
# (lib<name>.so in build/<preset>/lib) for Python's cffi (ABI mode). Links libm; add others to
# both targets with target_link_libraries afterwards.
function(autodrive_c_library name include_dir)
  add_library(${name} STATIC ${ARGN})
  add_library(${name}_shared SHARED ${ARGN})
  foreach(t ${name} ${name}_shared)
    target_include_directories(${t} PUBLIC "${include_dir}")
    set_target_properties(${t} PROPERTIES C_STANDARD 11 C_STANDARD_REQUIRED ON
      POSITION_INDEPENDENT_CODE ON)
    target_link_libraries(${t} PUBLIC m)
    autodrive_warnings(${t})
  endforeach()
  set_target_properties(${name}_shared PROPERTIES OUTPUT_NAME ${name}
    LIBRARY_OUTPUT_DIRECTORY "${CMAKE_BINARY_DIR}/lib")
endfunction()
