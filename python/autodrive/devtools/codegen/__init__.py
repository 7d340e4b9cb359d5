"""Build-time code generation from the project's one-place descriptions (like lcm-gen for the
message types): the vehicle description to a C header, the channel table to C and C++ headers
and to docs/reference/channels.md. Run by CMake (cmake/AutodriveCodegen.cmake) and by tools/gen-docs."""
