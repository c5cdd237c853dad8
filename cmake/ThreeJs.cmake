# three.js for `inscribe view`: the page embeds three.min.js and OrbitControls.js from the npm
# package three@0.147.0 (the last release with the classic UMD build/three.min.js and
# examples/js/, which attach THREE and THREE.OrbitControls as globals), and three's MIT
# licence text. scripts/fetch-three (run by scripts/install-deps) puts it in deps/three, checked
# against its pinned integrity hash; a global npm install (`npm install -g three@0.147.0`) is
# found too. Nothing is downloaded here. Sets INSCRIBE_THREE_DIR (cache) and
# INSCRIBE_THREE_{JS,ORBIT_CONTROLS,LICENSE}.
include(${CMAKE_CURRENT_LIST_DIR}/EmbedFiles.cmake)

set(INSCRIBE_THREE_VERSION 0.147.0)
if(NOT INSCRIBE_THREE_DIR AND EXISTS ${PROJECT_SOURCE_DIR}/deps/three/package.json)
  set(INSCRIBE_THREE_DIR "${PROJECT_SOURCE_DIR}/deps/three" CACHE PATH
      "Directory of the npm package three@${INSCRIBE_THREE_VERSION} (default: deps/three)")
endif()
if(NOT INSCRIBE_THREE_DIR)
  # Else the global npm package directory. Asked once; the answer is cached.
  find_program(INSCRIBE_NPM npm)
  set(npm_root "")
  if(INSCRIBE_NPM)
    execute_process(COMMAND ${INSCRIBE_NPM} root -g OUTPUT_VARIABLE npm_root
                    RESULT_VARIABLE npm_result OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(NOT npm_result EQUAL 0)
      set(npm_root "")
    endif()
  endif()
  if(npm_root STREQUAL "")
    message(FATAL_ERROR
      "three.js ${INSCRIBE_THREE_VERSION} not found: no deps/three and `npm root -g` gave no "
      "directory: run scripts/fetch-three or set INSCRIBE_THREE_DIR to the package directory")
  endif()
  set(INSCRIBE_THREE_DIR "${npm_root}/three" CACHE PATH
      "Directory of the npm package three@${INSCRIBE_THREE_VERSION} (default: `npm root -g`/three)")
endif()

set(INSCRIBE_THREE_JS ${INSCRIBE_THREE_DIR}/build/three.min.js)
set(INSCRIBE_THREE_ORBIT_CONTROLS ${INSCRIBE_THREE_DIR}/examples/js/controls/OrbitControls.js)
set(INSCRIBE_THREE_LICENSE ${INSCRIBE_THREE_DIR}/LICENSE)
set(three_problem "")
if(NOT EXISTS ${INSCRIBE_THREE_DIR}/package.json)
  set(three_problem "no package.json")
else()
  file(READ ${INSCRIBE_THREE_DIR}/package.json three_package)
  string(JSON three_version ERROR_VARIABLE three_json_error GET "${three_package}" version)
  if(three_json_error)
    set(three_problem "package.json has no version (${three_json_error})")
  elseif(NOT three_version STREQUAL INSCRIBE_THREE_VERSION)
    set(three_problem "package.json says version ${three_version}")
  endif()
  # Re-run the check when the package changes (e.g. another version installed over it).
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${INSCRIBE_THREE_DIR}/package.json)
endif()
foreach(three_file IN ITEMS ${INSCRIBE_THREE_JS} ${INSCRIBE_THREE_ORBIT_CONTROLS}
                            ${INSCRIBE_THREE_LICENSE})
  if(three_problem STREQUAL "" AND NOT EXISTS ${three_file})
    set(three_problem "${three_file} is missing")
  endif()
endforeach()
if(NOT three_problem STREQUAL "")
  message(FATAL_ERROR
    "three.js ${INSCRIBE_THREE_VERSION} not found under ${INSCRIBE_THREE_DIR} (${three_problem}): "
    "run scripts/fetch-three or set INSCRIBE_THREE_DIR")
endif()
message(STATUS "inscribe: three.js ${INSCRIBE_THREE_VERSION} from ${INSCRIBE_THREE_DIR}")
