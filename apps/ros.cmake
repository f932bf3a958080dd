# `sketchnav ros sim|nav` (doc/ros.md): built when the ROS 1 packages are (ros/CMakeLists.txt).
if(TARGET sketchnav::ros)
  target_sources(sketchnav PRIVATE cmd_ros.cpp)
  target_link_libraries(sketchnav PRIVATE sketchnav::ros)
else()
  target_sources(sketchnav PRIVATE cmd_ros_unavailable.cpp)
endif()
