# cmake -DDIR=<generated autodrive_msg> -P python_bytes_default.cmake: Debian's lcm-gen 1.3.1
# starts a Python `byte` array field as "" (a str), which its own encode() cannot write
# (bytearray("") raises). The signed types' `auth` field (empty = unsigned) must encode as
# made, so it starts as b"" here.
file(GLOB files "${DIR}/*_t.py")
foreach(f ${files})
  file(READ "${f}" text)
  string(REPLACE "self.auth = \"\"" "self.auth = b\"\"" fixed "${text}")
  if(NOT fixed STREQUAL text)
    file(WRITE "${f}" "${fixed}")
  endif()
endforeach()
