# cmake/python.cmake - the Python interpreter of the build, found with
# find_package(Python3): the tests and scripts run by ctest use it, and the
# extension (python/) is built for it.
#
# The tests and the extension's users need NumPy (and pytest, the Dask
# stack): so the interpreter is the first python3 on PATH whose site-packages
# have NumPy, which on Debian is its own /usr/bin/python3 even where another
# python3 (pyenv, a bare venv) comes first on PATH. A caller's
# -DPython3_EXECUTABLE=... wins (setup.py passes the interpreter pip runs).
# With no python3 that has NumPy, FindPython3 chooses as it always does, and
# the tests that need NumPy say so when they run.
if(NOT Python3_EXECUTABLE)
  string(REPLACE ":" ";" _collide_path "$ENV{PATH}")
  foreach(_collide_dir IN LISTS _collide_path)
    if(_collide_dir AND EXISTS "${_collide_dir}/python3" AND NOT IS_DIRECTORY "${_collide_dir}/python3")
      execute_process(COMMAND "${_collide_dir}/python3" -c "import numpy"
                      RESULT_VARIABLE _collide_numpy OUTPUT_QUIET ERROR_QUIET)
      if(_collide_numpy EQUAL 0)
        set(Python3_EXECUTABLE "${_collide_dir}/python3" CACHE FILEPATH "Python interpreter of the tests and the extension")
        break()
      endif()
    endif()
  endforeach()
  unset(_collide_path)
  unset(_collide_dir)
  unset(_collide_numpy)
endif()

# The extension needs the headers of the interpreter's Python (pybind11 then
# builds for the Python3 found here: Python3::Module); without them the build
# has no extension, as without pybind11. The tests need only the interpreter.
if(COLLIDE_BUILD_PYTHON)
  find_package(Python3 3.8 REQUIRED COMPONENTS Interpreter OPTIONAL_COMPONENTS Development.Module)
else()
  find_package(Python3 3.8 REQUIRED COMPONENTS Interpreter)
endif()
