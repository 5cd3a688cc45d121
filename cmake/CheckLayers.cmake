# cmake -DLINETRACK_SOURCE_DIR=DIR -P CheckLayers.cmake
# Checks that every #include "..." of the checked parts (LinetrackLayers.cmake) names a file of a
# part it may depend on: the robot's libraries include nothing from render/, synth/, sim/,
# fake_gige/, evaluation/, app/ (app/bench/ included) or tests/, and no layer includes upwards;
# and none includes ROS (app/ros/ only).
cmake_minimum_required(VERSION 3.18)
include(${CMAKE_CURRENT_LIST_DIR}/LinetrackLayers.cmake)

if(NOT LINETRACK_SOURCE_DIR)
  message(FATAL_ERROR "CheckLayers.cmake: pass -DLINETRACK_SOURCE_DIR=<source tree>")
endif()

set(violations "")
set(checked 0)
file(GLOB_RECURSE files RELATIVE ${LINETRACK_SOURCE_DIR}
     ${LINETRACK_SOURCE_DIR}/models/*.h ${LINETRACK_SOURCE_DIR}/models/*.cc
     ${LINETRACK_SOURCE_DIR}/calibration/*.h ${LINETRACK_SOURCE_DIR}/calibration/*.cc
     ${LINETRACK_SOURCE_DIR}/matching/*.h ${LINETRACK_SOURCE_DIR}/matching/*.cc
     ${LINETRACK_SOURCE_DIR}/tracking/*.h ${LINETRACK_SOURCE_DIR}/tracking/*.cc)
# ROS 1's packages (their include folders), known to app/ros/ alone.
set(ros_headers "ros|rosbag|image_transport|cv_bridge|tf2|tf2_ros|tf2_msgs|tf2_geometry_msgs|diagnostic_updater|sensor_msgs|nav_msgs|geometry_msgs|std_msgs|std_srvs|diagnostic_msgs")
foreach(file IN LISTS files)
  linetrack_part_of("${file}" part)
  file(STRINGS ${LINETRACK_SOURCE_DIR}/${file} ros_includes
       REGEX "^[ \t]*#[ \t]*include[ \t]*<(${ros_headers})/")
  foreach(line IN LISTS ros_includes)
    list(APPEND violations "${file}: ${line}: ROS belongs in app/ros/")
  endforeach()
  file(STRINGS ${LINETRACK_SOURCE_DIR}/${file} includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*$" "\\1" header "${line}")
    linetrack_part_of("${header}" used)
    math(EXPR checked "${checked} + 1")
    if(used STREQUAL "")
      list(APPEND violations "${file}: #include \"${header}\" is not a project path")
    elseif(NOT used IN_LIST LINETRACK_DEPS_${part})
      string(REPLACE ";" ", " allowed "${LINETRACK_DEPS_${part}}")
      list(APPEND violations "${file} (${part}) includes ${header} (${used}), allowed: ${allowed}")
    endif()
  endforeach()
endforeach()

list(LENGTH violations count)
if(count GREATER 0)
  string(REPLACE ";" "\n" text "${violations}")
  message(FATAL_ERROR "${count} include(s) against the layers:\n${text}")
endif()
message(STATUS "layers: ${checked} project includes in the libraries point down")
