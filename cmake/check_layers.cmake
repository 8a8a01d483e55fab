# The layers of codyna point one way (docs/ARCHITECTURE.md, "Layers"), and this check holds the
# rule at configure time (CMakeLists.txt includes it) and in CTest (layers.* tests):
#   front ends (app/, gui/, python/)  include from the core only study/ and model/
#   core/model/                       includes nothing of dynamics/, analysis/, control/,
#                                     simulation/, io/ or study/ (it is data and its compilation;
#                                     vehicle/, below it, reads a tire effect's .tir file)
#   core/simulation/                  includes nothing of io/ or study/ (files are read by io/)
#   core/vehicle/                     includes only itself and spatial/ (tire laws and .tir files)
# A violation stops the configuration with every offending file and line named.
# Script mode: cmake -DCODYNA_LAYERS_ROOT=DIR -P cmake/check_layers.cmake
function(codyna_check_layers root)
  set(violations "")
  set(rules
    "app|study,model,gui"
    "gui|study,model,gui"
    "python|study,model"
    "core/model|model,spatial,vehicle"
    "core/simulation|simulation,analysis,dynamics,control,model,spatial"
    "core/vehicle|vehicle,spatial")
  set(core_folders spatial model dynamics analysis control simulation study io gui vehicle)
  foreach(rule ${rules})
    string(REPLACE "|" ";" parts "${rule}")
    list(GET parts 0 folder)
    list(GET parts 1 allowed)
    string(REPLACE "," ";" allowed "${allowed}")
    file(GLOB_RECURSE files "${root}/${folder}/*.cpp" "${root}/${folder}/*.hpp" "${root}/${folder}/*.h")
    foreach(f ${files})
      file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"[A-Za-z0-9_]+/")
      foreach(line ${lines})
        string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([A-Za-z0-9_]+)/.*" "\\1" top "${line}")
        list(FIND core_folders "${top}" is_core)
        list(FIND allowed "${top}" ok)
        if(is_core GREATER -1 AND ok EQUAL -1)
          file(RELATIVE_PATH rel "${root}" "${f}")
          string(STRIP "${line}" line)
          list(JOIN allowed ", " allowed_text)
          string(APPEND violations "\n  ${rel}: ${line} (${folder}/ may include from the core only: ${allowed_text})")
        endif()
      endforeach()
    endforeach()
  endforeach()
  if(violations)
    message(FATAL_ERROR "codyna layers: includes against the rule of docs/ARCHITECTURE.md (front ends go through study/):${violations}")
  endif()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED CODYNA_LAYERS_ROOT)
  codyna_check_layers("${CODYNA_LAYERS_ROOT}")
  message(STATUS "codyna layers: ${CODYNA_LAYERS_ROOT} keeps the rule")
endif()
