# SPDX-License-Identifier: MIT
# Install step (cmake/install.cmake): in every header under MLC_HEADER_ROOT, an include of one of
# our folders, #include "core/x.hpp", becomes #include "mlcontact/core/x.hpp". Idempotent.
string(REPLACE ";" "|" _alt "${MLC_FOLDERS}")
file(GLOB_RECURSE _headers "${MLC_HEADER_ROOT}/*.hpp")
foreach(h ${_headers})
  file(READ "${h}" _text)
  string(REGEX REPLACE "#include \"(${_alt})/" "#include \"mlcontact/\\1/" _new "${_text}")
  if(NOT _new STREQUAL _text)
    file(WRITE "${h}" "${_new}")
  endif()
endforeach()
