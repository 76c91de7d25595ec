# Native ROS 1 (optional): roscpp, actionlib and the message packages from Debian. control_msgs
# is not packaged, so its FollowJointTrajectory action (and partsim's own services) are generated
# here at configure time with Debian's generators: C++ headers into ros1/include and Python
# modules into ros1/python of the build folder.
option(PARTSIM_ROS1 "Build the native ROS 1 interface when ROS 1 is installed" ON)
if(NOT PARTSIM_ROS1)
  return()
endif()
find_package(PkgConfig)
if(PkgConfig_FOUND)
  pkg_check_modules(ROS1 IMPORTED_TARGET roscpp actionlib sensor_msgs trajectory_msgs
                    geometry_msgs tf2_msgs rosgraph_msgs std_msgs actionlib_msgs)
endif()
set(ROS1_GENERATORS /usr/lib/actionlib_msgs/genaction.py /usr/lib/gencpp/gen_cpp.py
                    /usr/lib/genpy/genmsg_py.py /usr/lib/genpy/gensrv_py.py)
set(ROS1_MSG_DIRS std_msgs trajectory_msgs geometry_msgs actionlib_msgs std_srvs)
set(PARTSIM_ROS1_AVAILABLE ${ROS1_FOUND})
foreach(f ${ROS1_GENERATORS})
  if(NOT EXISTS ${f})
    set(PARTSIM_ROS1_AVAILABLE OFF)
  endif()
endforeach()
foreach(d ${ROS1_MSG_DIRS})
  if(NOT IS_DIRECTORY /usr/share/${d}/msg AND NOT IS_DIRECTORY /usr/share/${d}/srv)
    set(PARTSIM_ROS1_AVAILABLE OFF)
  endif()
endforeach()
find_program(ROS1_PYTHON /usr/bin/python3)

if(NOT PARTSIM_ROS1_AVAILABLE)
  message(STATUS "partsim: ROS 1 not found (libroscpp-dev, libactionlib-dev, message packages "
                 "and generators): building without the native ROS 1 interface")
  return()
endif()
message(STATUS "partsim: building the native ROS 1 interface")

set(ROS1_OUT ${CMAKE_BINARY_DIR}/ros1)
set(ROS1_SRC ${CMAKE_SOURCE_DIR}/ros1)
file(GLOB_RECURSE ROS1_DEFINITIONS CONFIGURE_DEPENDS ${ROS1_SRC}/*.msg ${ROS1_SRC}/*.srv
     ${ROS1_SRC}/*.action)

# Generate only when a definition or a generator changed: a stamp holds the hash of their names
# and contents. Regenerating rewrites the headers, which recompiles ros1_bridge.cc, so a
# configure with nothing changed must leave them alone.
set(ROS1_HASH_INPUT "")
foreach(f ${ROS1_DEFINITIONS} ${ROS1_GENERATORS})
  file(SHA256 ${f} h)
  string(APPEND ROS1_HASH_INPUT "${f} ${h}\n")
endforeach()
foreach(d ${ROS1_MSG_DIRS})
  file(GLOB deps /usr/share/${d}/msg/*.msg /usr/share/${d}/srv/*.srv)
  foreach(f ${deps})
    file(TIMESTAMP ${f} t UTC)
    string(APPEND ROS1_HASH_INPUT "${f} ${t}\n")
  endforeach()
endforeach()
string(SHA256 ROS1_HASH "${ROS1_HASH_INPUT}")
# an edited definition configures again (the glob alone notices only added or removed files)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ROS1_DEFINITIONS})
set(ROS1_STAMP ${ROS1_OUT}/generated.sha256)
set(ROS1_OLD_HASH "")
if(EXISTS ${ROS1_STAMP})
  file(READ ${ROS1_STAMP} ROS1_OLD_HASH)
endif()
if(ROS1_OLD_HASH STREQUAL ROS1_HASH)
  set(ROS1_GENERATE OFF)
else()
  set(ROS1_GENERATE ON)
  file(REMOVE_RECURSE ${ROS1_OUT})
endif()

function(ros1_run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ROS 1 message generation failed: ${ARGN}\n${err}")
  endif()
endfunction()

# search path of the generators: the Debian packages' definitions and ours
set(ROS1_INCLUDES)
foreach(d ${ROS1_MSG_DIRS})
  list(APPEND ROS1_INCLUDES -I${d}:/usr/share/${d}/msg)
endforeach()
foreach(pkg control_msgs partsim_msgs)
  list(APPEND ROS1_INCLUDES -I${pkg}:${ROS1_SRC}/${pkg}/msg -I${pkg}:${ROS1_OUT}/msg/${pkg})
endforeach()

foreach(pkg control_msgs partsim_msgs)
  if(NOT ROS1_GENERATE)
    break()
  endif()
  file(GLOB actions ${ROS1_SRC}/${pkg}/action/*.action)
  foreach(a ${actions})
    ros1_run(${ROS1_PYTHON} /usr/lib/actionlib_msgs/genaction.py -o ${ROS1_OUT}/msg/${pkg} ${a})
  endforeach()
  file(GLOB msgs ${ROS1_SRC}/${pkg}/msg/*.msg ${ROS1_OUT}/msg/${pkg}/*.msg)
  file(GLOB srvs ${ROS1_SRC}/${pkg}/srv/*.srv)
  foreach(f ${msgs} ${srvs})
    ros1_run(${ROS1_PYTHON} /usr/lib/gencpp/gen_cpp.py ${f} -p ${pkg}
             -o ${ROS1_OUT}/include/${pkg} -e /usr/share/gencpp ${ROS1_INCLUDES})
  endforeach()
  file(MAKE_DIRECTORY ${ROS1_OUT}/python/${pkg})
  file(WRITE ${ROS1_OUT}/python/${pkg}/__init__.py "")
  if(msgs)
    ros1_run(${ROS1_PYTHON} /usr/lib/genpy/genmsg_py.py ${msgs} -p ${pkg}
             -o ${ROS1_OUT}/python/${pkg}/msg ${ROS1_INCLUDES})
    ros1_run(${ROS1_PYTHON} /usr/lib/genpy/genmsg_py.py --initpy -p ${pkg}
             -o ${ROS1_OUT}/python/${pkg}/msg)
  endif()
  if(srvs)
    ros1_run(${ROS1_PYTHON} /usr/lib/genpy/gensrv_py.py ${srvs} -p ${pkg}
             -o ${ROS1_OUT}/python/${pkg}/srv ${ROS1_INCLUDES})
    ros1_run(${ROS1_PYTHON} /usr/lib/genpy/gensrv_py.py --initpy -p ${pkg}
             -o ${ROS1_OUT}/python/${pkg}/srv)
  endif()
endforeach()

if(ROS1_GENERATE)
  # written last: an interrupted generation leaves no stamp and runs again
  file(WRITE ${ROS1_STAMP} "${ROS1_HASH}")
  message(STATUS "partsim: generated the ROS 1 messages into ${ROS1_OUT}")
endif()

add_library(partsim_ros1 STATIC ${CMAKE_SOURCE_DIR}/src/server/ros1/ros1_bridge.cc)
target_include_directories(partsim_ros1 SYSTEM PRIVATE ${ROS1_OUT}/include)
target_link_libraries(partsim_ros1 PUBLIC partsim_server PRIVATE PkgConfig::ROS1)
target_compile_options(partsim_ros1 PRIVATE -Wall -Wextra -Wno-unused-parameter)
target_compile_definitions(partsim_ros1 PUBLIC PARTSIM_WITH_ROS1=1)
