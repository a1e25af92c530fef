# Decides SOFTSIGHT_BUILD_PYTHON (the `softsight` Python module, python/) before the libraries are
# defined, because the module needs them compiled as position-independent code.
#
# The interpreter: Python3_EXECUTABLE when given, else the first of `python3` on PATH and
# /usr/bin/python3 that imports numpy (a pyenv or virtualenv shim first on PATH often lacks the
# Debian packages python3-numpy, python3-pytest, python3-dask install for /usr/bin/python3).

set(_softsight_python_default OFF)
# Chosen in every tree, the sanitizer's too: the program embeds this interpreter for --hook
# (src/app), and a hook's frame is a numpy array.
if(NOT Python3_EXECUTABLE)
  find_program(_softsight_path_python3 NAMES python3 NO_CACHE)
  foreach(candidate IN ITEMS ${_softsight_path_python3} /usr/bin/python3)
    if(EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy"
                      RESULT_VARIABLE _softsight_numpy_rc OUTPUT_QUIET ERROR_QUIET)
      if(_softsight_numpy_rc EQUAL 0)
        set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "Python for the softsight module")
        break()
      endif()
    endif()
  endforeach()
endif()
if(NOT SOFTSIGHT_SANITIZE)  # An ASan-built module cannot be loaded by an uninstrumented python.
  if(Python3_EXECUTABLE)
    find_package(Python3 3.8 COMPONENTS Interpreter Development.Module NumPy)
    set(PYBIND11_FINDPYTHON ON)
    find_package(pybind11 2.6 CONFIG QUIET)
    if(Python3_FOUND AND Python3_NumPy_FOUND AND pybind11_FOUND)
      set(_softsight_python_default ON)
    endif()
  endif()
endif()
option(SOFTSIGHT_BUILD_PYTHON
       "Build the softsight Python module (pybind11, numpy); default: on when they are found"
       ${_softsight_python_default})
if(SOFTSIGHT_SANITIZE)
  # Skipped, whatever the cache says: the sanitizer build tests the C++ code.
  set(SOFTSIGHT_BUILD_PYTHON OFF)
elseif(SOFTSIGHT_BUILD_PYTHON AND NOT _softsight_python_default)
  message(FATAL_ERROR "SOFTSIGHT_BUILD_PYTHON=ON, but pybind11 (pybind11-dev) or a python3 with "
                      "numpy (python3-dev, python3-numpy) was not found: run scripts/setup.sh")
endif()
if(SOFTSIGHT_BUILD_PYTHON)
  message(STATUS "softsight Python module: on (${Python3_EXECUTABLE}, pybind11 ${pybind11_VERSION})")
else()
  message(STATUS "softsight Python module: off (SOFTSIGHT_SANITIZE, or pybind11/numpy not found)")
endif()
