# Unity (jumbo) builds (docs/performance.md, "Build time"): a target's .cpp files compiled a
# batch at a time as one translation unit, so that the headers, the precompiled header's load
# and the templates they share (Eigen's expressions, the model's types, GoogleTest's helpers)
# are compiled once per batch instead of once per file. Measured on this project: eight core
# test files in one unity batch compile in 12.5 s of CPU against 76 s one by one.
# -DCODYNA_UNITY_BUILD=OFF builds file by file (the same code: each file still compiles alone,
# as an editor or clang-tidy sees it).
option(CODYNA_UNITY_BUILD "Compile the larger targets in unity batches" ON)

# codyna_unity_build(TARGET BATCH N [ALONE source...]): TARGET in batches of N files; each ALONE
# source compiles by itself (a file too heavy to share a batch, or one whose local helpers would
# meet another's). A file's local functions must not share a name with another's in the same
# target: the test build.unity_names (cmake/unity_names.py) checks it for every such target.
function(codyna_unity_build target)
  cmake_parse_arguments(U "" "BATCH" "ALONE" ${ARGN})
  if(NOT CODYNA_UNITY_BUILD)
    return()
  endif()
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${U_BATCH})
  get_target_property(source_dir ${target} SOURCE_DIR)
  set(alone "")
  foreach(src ${U_ALONE})
    set_source_files_properties(${src} TARGET_DIRECTORY ${target} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
    get_filename_component(path ${src} ABSOLUTE BASE_DIR ${source_dir})
    list(APPEND alone ${path})
  endforeach()
  # the files that share batches, for build.unity_names
  get_target_property(sources ${target} SOURCES)
  set(shared "")
  foreach(src ${sources})
    get_filename_component(path ${src} ABSOLUTE BASE_DIR ${source_dir})
    if(path MATCHES "\\.(cpp|cc|cxx)$" AND NOT path IN_LIST alone)
      list(APPEND shared ${path})
    endif()
  endforeach()
  set(list_file ${PROJECT_BINARY_DIR}/unity_sources/${target}.txt)
  file(WRITE ${list_file} "${shared}")
  set_property(GLOBAL APPEND PROPERTY CODYNA_UNITY_SOURCE_LISTS ${list_file})
endfunction()
