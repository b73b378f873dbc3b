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
function(check_installed prefix library_type)
  set(files
    include/collide/solve.hpp
    lib/cmake/collide/collideConfig.cmake
    lib/cmake/collide/collideConfigVersion.cmake
    lib/cmake/collide/collideTargets.cmake
    lib/pkgconfig/collide.pc)
  if(library_type STREQUAL "STATIC_LIBRARY")
    list(APPEND files lib/libcollide.a)
  else()
    list(APPEND files lib/libcollide.so)
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
function(pkg_config_consumer prefix library_type dir)
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
  run("pkg-config" ENV ${env} COMMAND ${PKG_CONFIG} ${static} --cflags --libs collide)
  string(STRIP "${last_output}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  run("compile with pkg-config flags" COMMAND ${CXX} -std=c++17 -O2 -Wall -Wextra -Wpedantic -Werror
      ${CONSUMER_DIR}/main.cpp -o ${dir}/consumer ${flags} ${rpath})
  run("run consumer" COMMAND ${dir}/consumer)
  message(STATUS "${last_output}")
endfunction()

file(MAKE_DIRECTORY ${WORK_DIR})

if(MODE STREQUAL "install")
  file(REMOVE_RECURSE ${PREFIX})
  run("install" COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${PREFIX} --config ${CONFIG})
  check_installed(${PREFIX} ${LIBRARY_TYPE})

elseif(MODE STREQUAL "find_package")
  # Eigen3 is disabled for the consumer: a package that needed it would fail.
  build_and_run_consumer(${WORK_DIR}/find_package -DCMAKE_PREFIX_PATH=${PREFIX}
                         -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON)

elseif(MODE STREQUAL "pkg_config")
  pkg_config_consumer(${PREFIX} ${LIBRARY_TYPE} ${WORK_DIR}/pkg_config)

elseif(MODE STREQUAL "add_subdirectory")
  # The embedding project builds collide shared, then installs it from its own
  # build (COLLIDE_INSTALL=ON) into a second prefix that find_package and
  # pkg-config consume: the shared-library package, tested at the cost of one
  # library build. That build has only the baseline kernel
  # (COLLIDE_KERNEL_ISAS=sse2, as an embedding project may choose): this test
  # is about the packaging, the per-ISA kernels are tested in the main build,
  # and each one more would cost minutes of CI time.
  set(dir ${WORK_DIR}/add_subdirectory)
  set(shared_prefix ${WORK_DIR}/shared-prefix)
  build_and_run_consumer(${dir} -DCOLLIDE_SOURCE_DIR=${SOURCE_DIR} -DBUILD_SHARED_LIBS=ON -DCOLLIDE_INSTALL=ON
                         -DCOLLIDE_KERNEL_ISAS=sse2)
  file(REMOVE_RECURSE ${shared_prefix})
  run("install shared collide" COMMAND ${CMAKE_COMMAND} --install ${dir} --prefix ${shared_prefix})
  check_installed(${shared_prefix} SHARED_LIBRARY)
  build_and_run_consumer(${WORK_DIR}/shared_find_package -DCMAKE_PREFIX_PATH=${shared_prefix}
                         -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON)
  pkg_config_consumer(${shared_prefix} SHARED_LIBRARY ${WORK_DIR}/shared_pkg_config)

else()
  message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
