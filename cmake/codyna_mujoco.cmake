# Finding MuJoCo 2.2.x as packaged by Debian (libmujoco-dev), for the peer
# test (tests/peers_mujoco) and the speed benchmark (bench/mujoco_speed_bench).
#
# codyna_find_mujoco() sets, in the caller's scope,
#   CODYNA_MUJOCO_TARGET  the target to link (empty when MuJoCo is not found)
#   CODYNA_MUJOCO_HOW     how it was found (for a status message)
#
# Debian's package ships /usr/include/mujoco/mujoco.h, libmujoco.so and a CMake
# package config (target mujoco::mujoco), but no pkg-config file. Its config
# needs find_dependency(OpenGL) and lists /usr/include/libqhull_r/ as an
# include directory, which exists only when libqhull-dev is installed (CMake
# rejects an imported target whose include directory is missing). So: use the
# config when it works, drop include directories that do not exist, and fall
# back to finding the header and the library directly. Imported targets are
# local to the directory that creates them, so each caller runs this once.
macro(codyna_find_mujoco)
  set(CODYNA_MUJOCO_TARGET "")
  set(CODYNA_MUJOCO_HOW "")
  find_package(mujoco CONFIG QUIET)
  if(TARGET mujoco::mujoco)
    get_target_property(_mj_inc mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
    set(_mj_inc_ok "")
    foreach(_mj_d IN LISTS _mj_inc)
      if(EXISTS "${_mj_d}")
        list(APPEND _mj_inc_ok "${_mj_d}")
      endif()
    endforeach()
    set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_mj_inc_ok}")
    set(CODYNA_MUJOCO_TARGET mujoco::mujoco)
    set(CODYNA_MUJOCO_HOW "CMake config ${mujoco_DIR}")
  else()
    find_path(MUJOCO_INCLUDE_DIR mujoco/mujoco.h)
    find_library(MUJOCO_LIBRARY NAMES mujoco)
    if(MUJOCO_INCLUDE_DIR AND MUJOCO_LIBRARY)
      if(NOT TARGET codyna_mujoco)
        add_library(codyna_mujoco UNKNOWN IMPORTED)
        set_target_properties(codyna_mujoco PROPERTIES
          IMPORTED_LOCATION "${MUJOCO_LIBRARY}"
          INTERFACE_INCLUDE_DIRECTORIES "${MUJOCO_INCLUDE_DIR}")
      endif()
      set(CODYNA_MUJOCO_TARGET codyna_mujoco)
      set(CODYNA_MUJOCO_HOW "${MUJOCO_LIBRARY}")
    endif()
  endif()
endmacro()
