# MuJoCo from PyPI: the mujoco-core wheel that scripts/setup.sh installs into the project's venv
# (.venv) from requirements.lock carries libmujoco.so.X.Y.Z and include/mujoco/*.h in its package
# folder. This file makes them the imported target mujoco::mujoco; nothing here downloads, and
# Debian's libmujoco is never looked at.
#
#   PARTSIM_MUJOCO_DIR  the package folder (site-packages/mujoco); by default asked of the venv's
#                       interpreter (PARTSIM_VENV_PYTHON, default .venv/bin/python, or for a
#                       wheel's build without .venv the interpreter that builds it)
#
# The version is the one requirements.lock pins (the one place that names it): the library found
# must be that version's, or configuration stops and says what to run.
file(STRINGS ${CMAKE_SOURCE_DIR}/requirements.lock _mujoco_pin REGEX "^mujoco-core==")
string(REGEX REPLACE "^mujoco-core==([0-9.]+).*" "\\1" PARTSIM_MUJOCO_VERSION "${_mujoco_pin}")
if(NOT PARTSIM_MUJOCO_VERSION MATCHES "^[0-9]+\\.[0-9]+\\.[0-9]+$")
  message(FATAL_ERROR "requirements.lock pins no mujoco-core==X.Y.Z")
endif()

# a wheel's build (pip install ., scikit-build-core) asks its own interpreter, whose build
# environment holds mujoco-core (pyproject.toml's build requirements)
if(SKBUILD AND NOT EXISTS ${CMAKE_SOURCE_DIR}/.venv/bin/python)
  set(_venv_python ${Python_EXECUTABLE})
else()
  set(_venv_python ${CMAKE_SOURCE_DIR}/.venv/bin/python)
endif()
set(PARTSIM_VENV_PYTHON ${_venv_python} CACHE FILEPATH
    "The project venv's interpreter (scripts/setup.sh makes it)")
if(NOT PARTSIM_MUJOCO_DIR)
  if(NOT EXISTS ${PARTSIM_VENV_PYTHON})
    message(FATAL_ERROR "partsim: no Python venv at ${PARTSIM_VENV_PYTHON}, where MuJoCo "
            "${PARTSIM_MUJOCO_VERSION} comes from: run `bash scripts/setup.sh` (or make a venv "
            "and `pip install --require-hashes --no-deps -r requirements.lock`, then pass "
            "-DPARTSIM_VENV_PYTHON=VENV/bin/python or -DPARTSIM_MUJOCO_DIR=SITE-PACKAGES/mujoco)")
  endif()
  # the package's folder, found without importing it (that would load its Python bindings)
  execute_process(
    COMMAND ${PARTSIM_VENV_PYTHON} -c
            "import importlib.util as u; s = u.find_spec('mujoco'); print(list(s.submodule_search_locations)[0] if s else '')"
    OUTPUT_VARIABLE _mujoco_dir OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _mujoco_rc)
  if(NOT _mujoco_rc EQUAL 0 OR NOT _mujoco_dir)
    message(FATAL_ERROR "partsim: ${PARTSIM_VENV_PYTHON} has no mujoco package: run "
            "`bash scripts/setup.sh` (it installs requirements.lock)")
  endif()
  set(PARTSIM_MUJOCO_DIR ${_mujoco_dir} CACHE PATH "The mujoco package folder (site-packages/mujoco)")
endif()

set(PARTSIM_MUJOCO_LIBRARY ${PARTSIM_MUJOCO_DIR}/libmujoco.so.${PARTSIM_MUJOCO_VERSION})
if(NOT EXISTS ${PARTSIM_MUJOCO_LIBRARY} OR NOT EXISTS ${PARTSIM_MUJOCO_DIR}/include/mujoco/mujoco.h)
  file(GLOB _found ${PARTSIM_MUJOCO_DIR}/libmujoco.so.*)
  message(FATAL_ERROR "partsim: requirements.lock pins MuJoCo ${PARTSIM_MUJOCO_VERSION}, but "
          "${PARTSIM_MUJOCO_DIR} holds '${_found}' (and needs include/mujoco/mujoco.h): run `bash scripts/setup.sh` to install the pinned version")
endif()
add_library(mujoco::mujoco SHARED IMPORTED GLOBAL)
set_target_properties(mujoco::mujoco PROPERTIES
  IMPORTED_LOCATION ${PARTSIM_MUJOCO_LIBRARY}
  IMPORTED_SONAME libmujoco.so.${PARTSIM_MUJOCO_VERSION}
  INTERFACE_INCLUDE_DIRECTORIES ${PARTSIM_MUJOCO_DIR}/include)
message(STATUS "partsim: MuJoCo ${PARTSIM_MUJOCO_VERSION} from ${PARTSIM_MUJOCO_DIR}")
