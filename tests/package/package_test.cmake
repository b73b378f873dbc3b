# package_test.cmake - the steps of the package tests (see CMakeLists.txt here),
# run as `cmake -DMODE=<mode> -D... -P package_test.cmake`.
#
# Every step starts from an empty directory, so a stale build or install cannot
# make a test pass. A failing command stops the script with its output.
cmake_minimum_required(VERSION 3.21)

cmake_host_system_information(RESULT JOBS QUERY NUMBER_OF_LOGICAL_CORES)

# run(<what> COMMAND ...): runs a command, fails the test when it fails.
function(run what)
  cmake_parse_arguments(PARSE_ARGV 1 R "" "WORKING_DIRECTORY" "COMMAND;ENV")
  if(NOT R_WORKING_DIRECTORY)
    set(R_WORKING_DIRECTORY ${WORK_DIR})
  endif()
  message(STATUS "${what}: ${R_COMMAND}")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${R_ENV} ${R_COMMAND}
    WORKING_DIRECTORY ${R_WORKING_DIRECTORY}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

function(fresh_dir dir)
  file(REMOVE_RECURSE ${dir})
  file(MAKE_DIRECTORY ${dir})
endfunction()

# Checks that the files a consumer relies on are installed in `prefix`.
# `components` is "all" (core, io, eval) or "core" (and then io and eval must
# be absent).
function(check_installed prefix library_type components)
  set(files
    include/collide/solve.hpp
    lib/cmake/collide/collideConfig.cmake
    lib/cmake/collide/collideConfigVersion.cmake
    lib/cmake/collide/collideTargets.cmake
    lib/pkgconfig/collide.pc)
  set(component_files
    include/collide/io/scene_npz.hpp
    include/collide/eval/reference.hpp
    lib/pkgconfig/collide-io.pc
    lib/pkgconfig/collide-eval.pc)
  if(library_type STREQUAL "STATIC_LIBRARY")
    list(APPEND files lib/libcollide.a)
    list(APPEND component_files lib/libcollide_io.a lib/libcollide_eval.a)
  else()
    list(APPEND files lib/libcollide.so)
    list(APPEND component_files lib/libcollide_io.so lib/libcollide_eval.so)
  endif()
  if(components STREQUAL "all")
    list(APPEND files ${component_files})
  else()
    foreach(f IN LISTS component_files)
      if(EXISTS ${prefix}/${f})
        message(FATAL_ERROR "the core alone installed ${prefix}/${f}")
      endif()
    endforeach()
  endif()
  foreach(f IN LISTS files)
    if(NOT EXISTS ${prefix}/${f})
      message(FATAL_ERROR "not installed: ${prefix}/${f}")
    endif()
  endforeach()
  # Eigen is private to the library: nothing installed may ask consumers for it.
  file(GLOB cmake_files ${prefix}/lib/cmake/collide/*.cmake)
  foreach(f IN LISTS cmake_files ITEMS ${prefix}/lib/pkgconfig/collide.pc)
    file(STRINGS ${f} lines REGEX "^[^#]*([Ee]igen)")
    if(lines)
      message(FATAL_ERROR "${f} refers to Eigen, which consumers must not need")
    endif()
  endforeach()
endfunction()

# Configures, builds and runs the consumer project with extra cache arguments.
function(build_and_run_consumer dir)
  fresh_dir(${dir})
  # The compiler launcher of the build under test (ccache, scripts/build.sh),
  # so that a re-run compiles only what changed.
  set(launcher "")
  if(LAUNCHER)
    set(launcher "-DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}")
  endif()
  run("configure consumer" COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${dir} -G ${GENERATOR}
      -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=Release ${launcher} ${ARGN})
  run("build consumer" COMMAND ${CMAKE_COMMAND} --build ${dir} -j ${JOBS})
  run("run consumer" COMMAND ${dir}/consumer)
  message(STATUS "${last_output}")
endfunction()

# Compiles the consumer with the flags pkg-config gives for `prefix`, runs it.
# `module` is collide-eval (the consumer with every component) or collide (the
# core alone).
function(pkg_config_consumer prefix library_type dir module)
  if(NOT PKG_CONFIG)
    message(FATAL_ERROR "pkg-config not found (scripts/install-deps.sh installs it)")
  endif()
  fresh_dir(${dir})
  set(env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig)
  # A static archive does not carry its dependencies: --static adds Libs.private.
  set(static "")
  set(rpath "")
  if(library_type STREQUAL "STATIC_LIBRARY")
    set(static --static)
  else()
    set(rpath -Wl,-rpath,${prefix}/lib)
  endif()
  run("pkg-config" ENV ${env} COMMAND ${PKG_CONFIG} ${static} --cflags --libs ${module})
  string(STRIP "${last_output}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(defs "")
  if(module STREQUAL "collide")
    set(defs -DCOLLIDE_CONSUMER_CORE_ONLY)
  endif()
  run("compile with pkg-config flags" COMMAND ${CXX} -std=c++17 -O2 -Wall -Wextra -Wpedantic -Werror ${defs}
      ${CONSUMER_DIR}/main.cpp -o ${dir}/consumer ${flags} ${rpath})
  run("run consumer" COMMAND ${dir}/consumer)
  message(STATUS "${last_output}")
endfunction()

file(MAKE_DIRECTORY ${WORK_DIR})

if(MODE STREQUAL "install")
  file(REMOVE_RECURSE ${PREFIX})
  run("install" COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${PREFIX} --config ${CONFIG})
  check_installed(${PREFIX} ${LIBRARY_TYPE} all)

elseif(MODE STREQUAL "find_package")
  # Eigen3 is disabled for the consumer: a package that needed it would fail.
  build_and_run_consumer(${WORK_DIR}/find_package -DCMAKE_PREFIX_PATH=${PREFIX}
                         -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON)
  # A component the package does not have is an error of find_package.
  fresh_dir(${WORK_DIR}/find_package_missing)
  file(WRITE ${WORK_DIR}/find_package_missing/CMakeLists.txt
       "cmake_minimum_required(VERSION 3.16)\nproject(missing LANGUAGES CXX)\nfind_package(collide REQUIRED COMPONENTS nonesuch)\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/find_package_missing -B ${WORK_DIR}/find_package_missing/b
                          -DCMAKE_PREFIX_PATH=${PREFIX} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "nonesuch")
    message(FATAL_ERROR "find_package(collide COMPONENTS nonesuch) did not fail naming the component:\n${err}")
  endif()

elseif(MODE STREQUAL "pkg_config")
  pkg_config_consumer(${PREFIX} ${LIBRARY_TYPE} ${WORK_DIR}/pkg_config collide-eval)
  # The core alone from the same install: `pkg-config collide` names no io or
  # eval library.
  pkg_config_consumer(${PREFIX} ${LIBRARY_TYPE} ${WORK_DIR}/pkg_config_core collide)

elseif(MODE STREQUAL "add_subdirectory")
  # The embedding project builds the core alone (CONSUMER_CORE_ONLY turns
  # io and eval off), shared, then installs it from its own build
  # (COLLIDE_INSTALL=ON) into a second prefix that find_package and pkg-config
  # consume: the core builds, installs and links without the other libraries,
  # and the shared-library package is tested, at the cost of one core build.
  # That build has only the baseline kernel (COLLIDE_KERNEL_ISAS=sse2, as an
  # embedding project may choose): this test is about the packaging, the
  # per-ISA kernels are tested in the main build, and each one more would
  # cost minutes of CI time. (It stays a Release build: unoptimised, the
  # kernel's forced inlining and its debug information take longer still to
  # compile: docs/decisions/0032-the-double-accurate-law-out-of-line.md.)
  #
  # The embedded tree is a copy of the checkout's files with the consumer's
  # build directory one level under it, as build/ is under the checkout, and
  # the compiler cache's base directory at the copy. Ninja compiles from the
  # top of the build directory, so the kernel units' compile commands are
  # then, relative to it, those of the build under test, and a cache that
  # build filled (scripts/build.sh) serves them (the object's own path is
  # not part of ccache's key). Outside a git checkout the tree itself is
  # added and everything compiles.
  set(shared_prefix ${WORK_DIR}/shared-prefix)
  set(tree ${WORK_DIR}/embedded-src)
  fresh_dir(${tree})
  execute_process(COMMAND git -C ${SOURCE_DIR} ls-files --cached --others --exclude-standard
                  RESULT_VARIABLE rc OUTPUT_VARIABLE listed ERROR_QUIET)
  if(rc EQUAL 0 AND listed)
    string(REPLACE "\n" ";" listed "${listed}")
    foreach(f IN LISTS listed)
      if(f AND EXISTS ${SOURCE_DIR}/${f} AND NOT IS_DIRECTORY ${SOURCE_DIR}/${f})
        get_filename_component(sub ${f} DIRECTORY)
        file(COPY ${SOURCE_DIR}/${f} DESTINATION ${tree}/${sub})
      endif()
    endforeach()
    set(ENV{CCACHE_BASEDIR} ${tree})
    set(dir ${tree}/build)
  else()
    set(tree ${SOURCE_DIR})
    set(dir ${WORK_DIR}/add_subdirectory)
  endif()
  build_and_run_consumer(${dir} -DCOLLIDE_SOURCE_DIR=${tree} -DCONSUMER_CORE_ONLY=ON
                         -DBUILD_SHARED_LIBS=ON -DCOLLIDE_INSTALL=ON -DCOLLIDE_KERNEL_ISAS=sse2)
  file(REMOVE_RECURSE ${shared_prefix})
  run("install shared collide" COMMAND ${CMAKE_COMMAND} --install ${dir} --prefix ${shared_prefix})
  check_installed(${shared_prefix} SHARED_LIBRARY core)
  # Neither Eigen nor TBB (nor libdeflate) is needed by a consumer of the
  # shared core.
  build_and_run_consumer(${WORK_DIR}/shared_find_package -DCMAKE_PREFIX_PATH=${shared_prefix} -DCONSUMER_CORE_ONLY=ON
                         -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON)
  pkg_config_consumer(${shared_prefix} SHARED_LIBRARY ${WORK_DIR}/shared_pkg_config collide)

elseif(MODE STREQUAL "tool_configure")
  # README command 1 (scripts/build.sh --tool: the `tool` preset of
  # CMakePresets.json) installs only the tool's packages
  # (scripts/install-deps.sh --tool) and configures the tests, the
  # benchmarks, Python and the examples off: that configuration must find
  # none of the other packages. The preset itself, configured only (the
  # tool's objects are the main build's) in a directory of its own, with
  # every other package made unfindable.
  set(dir ${WORK_DIR}/tool_configure)
  fresh_dir(${dir})
  run("configure the tool alone" WORKING_DIRECTORY ${SOURCE_DIR}
      COMMAND ${CMAKE_COMMAND} --preset tool -S ${SOURCE_DIR} -B ${dir} -G ${GENERATOR}
      -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON
      -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON -DCMAKE_DISABLE_FIND_PACKAGE_pybind11=ON
      -DCMAKE_DISABLE_FIND_PACKAGE_Python3=ON)
  # ... and it still has the tool to build.
  run("the tool's target" COMMAND ${CMAKE_COMMAND} --build ${dir} --target help)
  if(NOT last_output MATCHES "collide_cli")
    message(FATAL_ERROR "the tool-only configuration has no collide_cli target:\n${last_output}")
  endif()

else()
  message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
