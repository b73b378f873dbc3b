# cmake/library.cmake - collide_add_library(), the block the three libraries
# of the package (core/, io/, eval/) share, included by the top-level
# CMakeLists.txt after cmake/flags.cmake.
#
#   collide_add_library(<target> ALIAS <namespace>::<name> SOURCES <source>...
#                       [PUBLIC <library>...] [PRIVATE <library>...])
#
# Called from the library's own directory, it gives the target
#   * its alias, the name consumers of find_package and add_subdirectory use
#     (the export name is set with the install rules, cmake/install.cmake);
#   * the public headers of <dir>/include and the private ones of <dir>/src.
#     The installed include dir comes from install(TARGETS ... INCLUDES
#     DESTINATION) in cmake/install.cmake, which honours
#     CMAKE_INSTALL_INCLUDEDIR;
#   * C++20 for its own sources and C++17 for its consumers: the public
#     headers are C++17 (tests/package compiles every one of them as C++17);
#   * the build's flags (collide_build_flags, cmake/flags.cmake) and the
#     private helpers the libraries share (collide_shared, core/), linked
#     through $<BUILD_INTERFACE:...> so that the exported link interface of
#     a static archive does not name these build-only targets;
#   * the PUBLIC and PRIVATE libraries it links beyond those.
# Unity batches follow CMAKE_UNITY_BUILD (cmake/options.cmake).
function(collide_add_library target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "ALIAS" "SOURCES;PUBLIC;PRIVATE")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_ALIAS OR NOT ARG_SOURCES)
    message(FATAL_ERROR "collide_add_library(${target} ALIAS <alias> SOURCES <source>... [PUBLIC <library>...] [PRIVATE <library>...])")
  endif()
  add_library(${target} ${ARG_SOURCES})
  add_library(${ARG_ALIAS} ALIAS ${target})
  target_include_directories(${target}
    PUBLIC  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_compile_features(${target} PUBLIC cxx_std_17 PRIVATE cxx_std_20)
  target_link_libraries(${target}
    PUBLIC  ${ARG_PUBLIC}
    PRIVATE $<BUILD_INTERFACE:collide_build_flags> $<BUILD_INTERFACE:collide_shared> ${ARG_PRIVATE})
endfunction()
