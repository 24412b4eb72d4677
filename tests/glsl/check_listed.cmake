# ctest glsl_shared_headers_listed: fails when a header in shaders/shared is not included by
# tests/glsl/shared_headers.comp (so the GLSL compile test cannot silently miss a new header).
# Usage: cmake -DSHADER_DIR=... -DCOMP=... -P check_listed.cmake
file(GLOB headers "${SHADER_DIR}/shared/*.h")
file(READ "${COMP}" comp)
set(missing "")
foreach(h ${headers})
  get_filename_component(name ${h} NAME)
  string(FIND "${comp}" "#include \"shared/${name}\"" at)
  if(at EQUAL -1)
    list(APPEND missing ${name})
  endif()
endforeach()
if(missing)
  message(FATAL_ERROR "shared headers not included by ${COMP}: ${missing}")
endif()
