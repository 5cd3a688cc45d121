# ROS 1 (Debian bookworm's ros-core 1.16 packages) without catkin: the ROS libraries through their
# pkg-config files. rosbag_storage and image_transport require pluginlib, which Debian ships as an
# ament (ROS 2) package without a pkg-config file; their headers and libraries are named here
# instead. Defines the target Ros1::Ros1 for app/ros/ only.

pkg_check_modules(ROS1_PC REQUIRED IMPORTED_TARGET
                  roscpp roslib tf2_ros cv_bridge diagnostic_updater tf2_geometry_msgs roslz4)

set(_ros1_libs rosbag rosbag_storage image_transport message_filters class_loader rcutils rcpputils
                ament_index_cpp)
set(_ros1_found)
foreach(lib IN LISTS _ros1_libs)
  find_library(ROS1_LIB_${lib} ${lib} REQUIRED)
  list(APPEND _ros1_found ${ROS1_LIB_${lib}})
endforeach()
# pluginlib and class_loader (ament layout: include/<package>/<package>/...), which include
# rcpputils, rcutils and ament_index_cpp.
set(_ros1_includes)
foreach(pkg pluginlib class_loader rcpputils rcutils ament_index_cpp)
  find_path(ROS1_INCLUDE_${pkg} NAMES ${pkg} PATHS /usr/include/${pkg} NO_DEFAULT_PATH REQUIRED)
  list(APPEND _ros1_includes ${ROS1_INCLUDE_${pkg}})
endforeach()
find_path(ROS1_INCLUDE_rosbag NAMES rosbag/bag.h REQUIRED)
find_path(ROS1_INCLUDE_image_transport NAMES image_transport/image_transport.h REQUIRED)

add_library(ros1_deps INTERFACE)
target_link_libraries(ros1_deps INTERFACE PkgConfig::ROS1_PC ${_ros1_found})
target_include_directories(ros1_deps SYSTEM INTERFACE ${_ros1_includes})
add_library(Ros1::Ros1 ALIAS ros1_deps)
