# Installation and the Debian package.
#
# `cmake --install build --prefix PREFIX` installs:
#   PREFIX/bin/partsim                            the command line
#   PREFIX/lib/<multiarch>/libpartsim.so          the C++ library (every layer's library whole)
#   PREFIX/include/partsim/                       its headers (they need Eigen only)
#   PREFIX/lib/<multiarch>/cmake/partsim/         find_package(partsim) -> partsim::partsim
#   PREFIX/lib/python3/dist-packages/partsim/     the Python package (Debian's path for /usr)
#   PREFIX/share/partsim/web/                     the viewer's web bundle, when built
# `cpack -G DEB` in build/ makes partsim_<version>_<arch>.deb of the same files under /usr; its
# dependencies are computed from the libraries the binaries link (dpkg-shlibdeps).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# libpartsim.so: the static core whole, for C++ programs that link partsim
file(WRITE ${CMAKE_BINARY_DIR}/partsim_shared.cc
     "// libpartsim.so holds the objects of every layer; this file only gives it a source.\n")
add_library(partsim SHARED ${CMAKE_BINARY_DIR}/partsim_shared.cc)
add_library(partsim::partsim ALIAS partsim)
# every layer's archive whole (each once: a layer is also a dependency of the ones above it, so
# CMake's own WHOLE_ARCHIVE feature would list it twice), then the layers and their external
# libraries as usual
set(PARTSIM_LAYER_LIBS partsim_core partsim_physics partsim_assets partsim_render partsim_robot
                       partsim_vision partsim_planning partsim_tasks partsim_server
                       partsim_viewer)
set(whole "LINKER:--whole-archive")
foreach(lib ${PARTSIM_LAYER_LIBS})
  list(APPEND whole "$<TARGET_FILE:${lib}>")
endforeach()
list(APPEND whole "LINKER:--no-whole-archive")
target_link_options(partsim PRIVATE ${whole})
target_link_libraries(partsim PRIVATE partsim_all)
target_link_libraries(partsim PUBLIC Eigen3::Eigen Threads::Threads)
target_include_directories(partsim PUBLIC $<BUILD_INTERFACE:${CMAKE_SOURCE_DIR}/include>
                                          $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
set_target_properties(partsim PROPERTIES VERSION ${PROJECT_VERSION}
                                         SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})

set(PARTSIM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/partsim)
set(PARTSIM_PYTHON_INSTALL_DIR lib/python3/dist-packages CACHE STRING
    "Where the Python package goes, relative to the prefix (Debian's path under /usr)")

# `partsim learn` runs the Python package: an installed command finds it at this path from the
# prefix (src/tools/learn_command.cc)
# prefix (src/tools/learn_command.cc); the build tree's runs the interpreter it was built for
set_source_files_properties(${CMAKE_SOURCE_DIR}/src/tools/learn_command.cc PROPERTIES
  COMPILE_DEFINITIONS "PARTSIM_PYTHON_INSTALL_DIR=\"${PARTSIM_PYTHON_INSTALL_DIR}\";PARTSIM_BUILD_PYTHON=\"${PYTHON_EXECUTABLE}\"")

install(TARGETS partsim EXPORT partsimTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT partsim)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/include/partsim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT partsim)
install(EXPORT partsimTargets NAMESPACE partsim:: DESTINATION ${PARTSIM_CMAKE_DIR}
        COMPONENT partsim)
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/partsimConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/partsimConfig.cmake
                              INSTALL_DESTINATION ${PARTSIM_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/partsimConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/partsimConfig.cmake ${CMAKE_BINARY_DIR}/partsimConfigVersion.cmake
        DESTINATION ${PARTSIM_CMAKE_DIR} COMPONENT partsim)

# MuJoCo's library (from the venv's mujoco-core wheel, cmake/mujoco.cmake) goes beside
# libpartsim.so, and everything installed finds it there through its RUNPATH: an installed partsim
# runs without the venv
install(FILES ${PARTSIM_MUJOCO_LIBRARY} DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT partsim)
set_target_properties(partsim PROPERTIES INSTALL_RPATH "$ORIGIN")
if(TARGET partsim_cli)
  file(RELATIVE_PATH _bin_to_lib ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}
       ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR})
  set_target_properties(partsim_cli PROPERTIES INSTALL_RPATH "$ORIGIN/${_bin_to_lib}")
  install(TARGETS partsim_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT partsim)
endif()
if(TARGET partsim_py)
  file(RELATIVE_PATH _py_to_lib ${CMAKE_INSTALL_PREFIX}/${PARTSIM_PYTHON_INSTALL_DIR}/partsim
       ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR})
  set_target_properties(partsim_py PROPERTIES INSTALL_RPATH "$ORIGIN/${_py_to_lib}")
  install(TARGETS partsim_py LIBRARY DESTINATION ${PARTSIM_PYTHON_INSTALL_DIR}/partsim
          COMPONENT partsim)
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/python/partsim/
          DESTINATION ${PARTSIM_PYTHON_INSTALL_DIR}/partsim COMPONENT partsim
          PATTERN "__pycache__" EXCLUDE)
endif()
# the browser viewer's web bundle (scripts/build_web.sh builds it into build/web), when built
install(DIRECTORY ${CMAKE_BINARY_DIR}/web/ DESTINATION ${CMAKE_INSTALL_DATADIR}/partsim/web
        COMPONENT partsim OPTIONAL)

# The wheel (pyproject.toml, built by scikit-build-core): component "wheel", installed only when
# asked for by name (EXCLUDE_FROM_ALL: `cmake --install` and the .deb leave it out). Its prefix is
# the wheel's site-packages, and the package folder is a prefix of its own:
#   partsim/                          the Python package, _partsim*.so, the stubs and py.typed
#   partsim/bin/partsim               the command line (the `partsim` entry point runs it)
#   partsim/lib/libmujoco.so.X.Y.Z    MuJoCo, found through the RUNPATHs below
#   partsim/share/partsim/web/        the viewer's page
# The system libraries (Mesa's EGL, Embree, assimp, OMPL, FFmpeg, ...) are not bundled: the wheel
# is for Debian 12 with those packages (partsim/__init__.py names what is missing).
set(PARTSIM_WHEEL_PACKAGE partsim)
if(TARGET partsim_py)
  install(TARGETS partsim_py LIBRARY DESTINATION ${PARTSIM_WHEEL_PACKAGE} COMPONENT wheel
          EXCLUDE_FROM_ALL)
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/python/partsim/ DESTINATION ${PARTSIM_WHEEL_PACKAGE}
          COMPONENT wheel EXCLUDE_FROM_ALL PATTERN "__pycache__" EXCLUDE)
  set_property(TARGET partsim_py APPEND PROPERTY INSTALL_RPATH "$ORIGIN/lib")
endif()
if(TARGET partsim_cli)
  install(TARGETS partsim_cli RUNTIME DESTINATION ${PARTSIM_WHEEL_PACKAGE}/bin COMPONENT wheel
          EXCLUDE_FROM_ALL)
  set_property(TARGET partsim_cli APPEND PROPERTY INSTALL_RPATH "$ORIGIN/../lib")
endif()
install(FILES ${PARTSIM_MUJOCO_LIBRARY} DESTINATION ${PARTSIM_WHEEL_PACKAGE}/lib COMPONENT wheel
        EXCLUDE_FROM_ALL)
install(DIRECTORY ${CMAKE_BINARY_DIR}/web/ DESTINATION ${PARTSIM_WHEEL_PACKAGE}/share/partsim/web
        COMPONENT wheel EXCLUDE_FROM_ALL OPTIONAL)
# the page itself (scripts/build_web.sh: three.js and roslib from npm, bundled into build's web/):
# a target the wheel's build asks for (pyproject.toml); without npm the wheel has no page, and the
# viewer says how to build one
find_program(PARTSIM_NPM npm)
if(PARTSIM_NPM)
  add_custom_target(partsim_web COMMAND ${CMAKE_COMMAND} -E env PARTSIM_WEB_OUT=${CMAKE_BINARY_DIR}/web
                    bash ${CMAKE_SOURCE_DIR}/scripts/build_web.sh VERBATIM)
else()
  add_custom_target(partsim_web COMMAND ${CMAKE_COMMAND} -E echo
                    "partsim: no npm, so no viewer page (scripts/build_web.sh builds it)")
endif()

# the Debian package
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME partsim)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "partsim developers <partsim@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "simulation of robots that open doors, pull drawers and turn knobs, part by part")
set(CPACK_PACKAGE_DESCRIPTION
    "partsim simulates articulated objects and the robots that manipulate them (physics on \
MuJoCo, rendering by rasterizer and path tracer, URDF and PartNet-Mobility assets, door and \
drawer tasks), with a command line, a C++ library and a Python package.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# what the libraries do not say: the Python package's interpreter and modules, the headers' one
# dependency, and Mesa's EGL and CPU rasterizer behind libEGL (the renderer without a GPU)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "python3 (>= 3.11), python3-numpy, libeigen3-dev, libegl-mesa0, libgl1-mesa-dri")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3-pil, python3-torch, python3-matplotlib")
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR})
set(CPACK_OUTPUT_FILE_PREFIX ${CMAKE_BINARY_DIR})
set(CPACK_STRIP_FILES ON)
include(CPack)
