# gjkdConfig.cmake: find_package(gjkd) support, installed by ffi/install.sh
# into PREFIX/lib/cmake/gjkd/. Defines
#   gjkd::gjkd         the shared library libgjkd_c.so (the default choice)
#   gjkd::gjkd_static  the static library libgjkd_c.a
# both with the include folder holding gjkd.h and gjkd.hpp. A library built
# without robots (install.sh --no-robots) gives its users GJKD_NO_ROBOTS,
# so that the header hides the robot and mesh functions it lacks.
set(_gjkd_defines "@DEFINES@")
include(CMakeFindDependencyMacro)
find_dependency(Threads)

get_filename_component(_gjkd_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

if(NOT TARGET gjkd::gjkd)
  add_library(gjkd::gjkd SHARED IMPORTED)
  set_target_properties(gjkd::gjkd PROPERTIES
    IMPORTED_LOCATION "${_gjkd_prefix}/lib/libgjkd_c.so"
    INTERFACE_INCLUDE_DIRECTORIES "${_gjkd_prefix}/include"
    INTERFACE_COMPILE_DEFINITIONS "${_gjkd_defines}")
endif()

if(NOT TARGET gjkd::gjkd_static AND EXISTS "${_gjkd_prefix}/lib/libgjkd_c.a")
  add_library(gjkd::gjkd_static STATIC IMPORTED)
  # What a Rust static library needs from the system (rustc's
  # --print native-static-libs).
  set_target_properties(gjkd::gjkd_static PROPERTIES
    IMPORTED_LOCATION "${_gjkd_prefix}/lib/libgjkd_c.a"
    INTERFACE_INCLUDE_DIRECTORIES "${_gjkd_prefix}/include"
    INTERFACE_COMPILE_DEFINITIONS "${_gjkd_defines}"
    INTERFACE_LINK_LIBRARIES "Threads::Threads;gcc_s;util;rt;m;dl")
endif()

unset(_gjkd_prefix)
unset(_gjkd_defines)
set(gjkd_FOUND TRUE)
