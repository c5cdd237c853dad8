# inscribe_embed_files(OUTPUT <file.cpp> NAMESPACE <ns> FILES <symbol> <path> [<symbol> <path>...])
#
# Adds a build-time rule writing <file.cpp>, which defines for each file
#   extern const unsigned char <symbol>[];   // the file's bytes, then one 0 byte
#   extern const std::size_t <symbol>Size;   // the file's size in bytes (without that 0)
# in namespace <ns>. Regenerated when a file or the generator changes. Declare the symbols
# where they are used (see client/src/cli/viewer_assets.cpp).
set(INSCRIBE_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_files_script.cmake)

function(inscribe_embed_files)
  cmake_parse_arguments(ARG "" "OUTPUT;NAMESPACE" "FILES" ${ARGN})
  list(LENGTH ARG_FILES length)
  math(EXPR odd "${length} % 2")
  if(length EQUAL 0 OR odd)
    message(FATAL_ERROR "inscribe_embed_files: FILES needs <symbol> <path> pairs")
  endif()
  set(symbols "")
  set(paths "")
  math(EXPR last "${length} - 1")
  foreach(i RANGE 0 ${last} 2)
    math(EXPR j "${i} + 1")
    list(GET ARG_FILES ${i} symbol)
    list(GET ARG_FILES ${j} path)
    list(APPEND symbols ${symbol})
    list(APPEND paths ${path})
  endforeach()
  # '|' instead of ';' so that the lists survive the trip through the command line.
  string(REPLACE ";" "|" symbols_arg "${symbols}")
  string(REPLACE ";" "|" paths_arg "${paths}")
  add_custom_command(
    OUTPUT ${ARG_OUTPUT}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${ARG_OUTPUT} -DNAMESPACE=${ARG_NAMESPACE}
            -DSYMBOLS=${symbols_arg} -DPATHS=${paths_arg} -P ${INSCRIBE_EMBED_SCRIPT}
    DEPENDS ${paths} ${INSCRIBE_EMBED_SCRIPT}
    COMMENT "Embedding ${symbols} in ${ARG_OUTPUT}"
    VERBATIM)
endfunction()
