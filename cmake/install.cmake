# Installation and the package files of the collide library.
#
# Design notes
# ------------
# * Three libraries, one package: the core collide::collide and the
#   components io (collide::io) and eval (collide::eval), each static by
#   default, shared with -DBUILD_SHARED_LIBS=ON (CMake's own switch).
#   find_package(collide COMPONENTS io eval) asks for the components; the
#   core alone needs neither (and a build with -DCOLLIDE_BUILD_IO=OFF installs
#   the core alone).
# * What a consumer needs is exactly the public link interface:
#     - the headers (C++17, no TBB: it is used only in .cpp files);
#     - for a static archive, TBB (and for io, libdeflate) as well, because an
#       archive cannot carry its own dependencies. The exported targets say so
#       ($<LINK_ONLY:TBB::tbb>, $<LINK_ONLY:PkgConfig::LIBDEFLATE>, which CMake
#       adds for a PRIVATE dependency of a static library), so the config file
#       calls find_dependency(TBB) and finds libdeflate through pkg-config in
#       that case only. No library uses Eigen (only the tests and the
#       benchmarks do), and tests/package checks that nothing installed asks
#       for it.
# * Three ways in, the same names: find_package(collide) and add_subdirectory
#   both give collide::collide, collide::io and collide::eval; pkg-config gives
#   collide.pc, collide-io.pc and collide-eval.pc (each Requires the one below
#   it), whose -ltbb, -ldeflate and -lquadmath sit in Libs.private for a static
#   install (`pkg-config --static`), as pkg-config intends private
#   dependencies to be spelled.
# * The .pc file locates its prefix from its own directory (${pcfiledir}), so
#   `cmake --install build --prefix anywhere` gives a working file without
#   reconfiguring.
# * Install rules are generated when collide is the top-level project, or when
#   an embedding project asks for them (COLLIDE_INSTALL=ON, cmake/options.cmake).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_target_property(COLLIDE_LIBRARY_TYPE collide TYPE)

# The libraries of this build, and their export names (collide::<name>).
set(COLLIDE_PACKAGE_LIBRARIES collide)
if(TARGET collide_io)
  list(APPEND COLLIDE_PACKAGE_LIBRARIES collide_io)
  set_target_properties(collide_io PROPERTIES EXPORT_NAME io)
endif()
if(TARGET collide_eval)
  list(APPEND COLLIDE_PACKAGE_LIBRARIES collide_eval)
  set_target_properties(collide_eval PROPERTIES EXPORT_NAME eval)
endif()
set_target_properties(collide PROPERTIES EXPORT_NAME collide)

foreach(lib IN LISTS COLLIDE_PACKAGE_LIBRARIES)
  # A static archive is often linked into a consumer's shared library, which
  # needs position-independent code; the kernels lose nothing measurable by
  # it on x86-64 (RIP-relative addressing). A caller's
  # CMAKE_POSITION_INDEPENDENT_CODE wins.
  if(NOT DEFINED CMAKE_POSITION_INDEPENDENT_CODE)
    set_target_properties(${lib} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
  # 0.x: a minor release may break the ABI, so the soname carries major.minor.
  set_target_properties(${lib} PROPERTIES
    VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
endforeach()

if(NOT COLLIDE_INSTALL)
  return()
endif()

set(COLLIDE_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/collide)

install(TARGETS ${COLLIDE_PACKAGE_LIBRARIES} EXPORT collideTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# One include/collide/ tree: the core's headers, collide/io/ and collide/eval/.
set(_collide_header_roots ${PROJECT_SOURCE_DIR}/core/include/collide)
if(TARGET collide_io)
  list(APPEND _collide_header_roots ${PROJECT_SOURCE_DIR}/io/include/collide)
endif()
if(TARGET collide_eval)
  list(APPEND _collide_header_roots ${PROJECT_SOURCE_DIR}/eval/include/collide)
endif()
install(DIRECTORY ${_collide_header_roots}
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")

# The command-line tool, when built. A shared build finds its library relative
# to its own location, so the installed tree can be moved.
if(TARGET collide_cli)
  if(COLLIDE_LIBRARY_TYPE STREQUAL "SHARED_LIBRARY")
    file(RELATIVE_PATH _collide_bin_to_lib ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_LIBDIR})
    set_target_properties(collide_cli PROPERTIES INSTALL_RPATH "$ORIGIN/${_collide_bin_to_lib}")
  endif()
  install(TARGETS collide_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# --- CMake package: collideConfig.cmake, collideConfigVersion.cmake ---------
install(EXPORT collideTargets
  NAMESPACE collide::
  FILE collideTargets.cmake
  DESTINATION ${COLLIDE_CMAKE_INSTALL_DIR})

if(COLLIDE_LIBRARY_TYPE STREQUAL "STATIC_LIBRARY")
  set(COLLIDE_NEEDS_TBB ON)
else()
  set(COLLIDE_NEEDS_TBB OFF)
endif()
set(COLLIDE_NEEDS_DEFLATE OFF)
if(COLLIDE_NEEDS_TBB AND TARGET collide_io)
  set(COLLIDE_NEEDS_DEFLATE ON)
endif()
# collide_SIMD of the config file: the SIMD kernels the library holds, among
# which it chooses at run time (COLLIDE_KERNEL_ISAS; "native" where the target
# has one kernel for its own lanes).
set(COLLIDE_SIMD "${COLLIDE_KERNEL_ISAS}")
if(NOT COLLIDE_SIMD)
  set(COLLIDE_SIMD native)
endif()
set(COLLIDE_COMPONENTS "")
if(TARGET collide_io)
  list(APPEND COLLIDE_COMPONENTS io)
endif()
if(TARGET collide_eval)
  list(APPEND COLLIDE_COMPONENTS eval)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/collideConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/collideConfig.cmake
  INSTALL_DESTINATION ${COLLIDE_CMAKE_INSTALL_DIR})
# 0.x: only the same major.minor is promised to be compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/collideConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/package/collideConfig.cmake
  ${PROJECT_BINARY_DIR}/package/collideConfigVersion.cmake
  DESTINATION ${COLLIDE_CMAKE_INSTALL_DIR})

# --- pkg-config: collide.pc --------------------------------------------------
set(COLLIDE_PC_DIR ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(COLLIDE_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(COLLIDE_PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
  set(COLLIDE_PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
else()
  # Path from <prefix>/<libdir>/pkgconfig back to <prefix>, e.g. "../.." or, for
  # Debian's multiarch libdir, "../../..".
  file(RELATIVE_PATH _collide_pc_up /prefix/${COLLIDE_PC_DIR} /prefix)
  string(REGEX REPLACE "/$" "" _collide_pc_up "${_collide_pc_up}")
  set(COLLIDE_PC_PREFIX "\${pcfiledir}/${_collide_pc_up}")
  set(COLLIDE_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
  set(COLLIDE_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()

# Libs.private of a static install: what each archive needs beyond the ones
# its Requires names.
set(_collide_pc_tbb "")
set(_collide_pc_quadmath "")
set(_collide_pc_deflate "")
if(COLLIDE_NEEDS_TBB)
  # -L only when TBB is not in a directory the linker searches anyway.
  get_target_property(_collide_tbb_location TBB::tbb IMPORTED_LOCATION_RELEASE)
  if(NOT _collide_tbb_location)
    get_target_property(_collide_tbb_location TBB::tbb IMPORTED_LOCATION)
  endif()
  if(_collide_tbb_location)
    get_filename_component(_collide_tbb_dir ${_collide_tbb_location} DIRECTORY)
    if(NOT _collide_tbb_dir IN_LIST CMAKE_CXX_IMPLICIT_LINK_DIRECTORIES)
      string(APPEND _collide_pc_tbb "-L${_collide_tbb_dir} ")
    endif()
  endif()
  string(APPEND _collide_pc_tbb "-ltbb")
  # libquadmath: the __float128 buffers and reference (eval only); GCC's own
  # runtime, in the linker's default path.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
    set(_collide_pc_quadmath "-lquadmath")
  endif()
  # libdeflate: the .npz writer's CRC-32 (io); its own pkg-config flags, which
  # carry a -L where it is not in the linker's path.
  if(TARGET collide_io)
    list(JOIN LIBDEFLATE_LDFLAGS " " _collide_pc_deflate)
  endif()
endif()

# collide_pc_file(<file> <name> <description> <library> <requires> <libs.private>)
function(collide_pc_file file name description library requires libs_private)
  set(COLLIDE_PC_NAME "${name}")
  set(COLLIDE_PC_DESCRIPTION "${description}")
  set(COLLIDE_PC_LIBRARY "${library}")
  set(COLLIDE_PC_REQUIRES "${requires}")
  set(COLLIDE_PC_LIBS_PRIVATE "${libs_private}")
  configure_file(${PROJECT_SOURCE_DIR}/cmake/collide.pc.in ${PROJECT_BINARY_DIR}/package/${file} @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/package/${file} DESTINATION ${COLLIDE_PC_DIR})
endfunction()
collide_pc_file(collide.pc collide "${PROJECT_DESCRIPTION}" collide "" "${_collide_pc_tbb}")
if(TARGET collide_io)
  collide_pc_file(collide-io.pc collide-io "collide scene files (CSV, .npz) and scene generators" collide_io
                  "collide = ${PROJECT_VERSION}" "${_collide_pc_tbb} ${_collide_pc_deflate}")
endif()
if(TARGET collide_eval)
  collide_pc_file(collide-eval.pc collide-eval "collide reference solver, error measures and hard scenes" collide_eval
                  "collide-io = ${PROJECT_VERSION}" "${_collide_pc_tbb} ${_collide_pc_quadmath}")
endif()
