# Registers a rover component and its standalone executable; exported to the
# packages that find_package(rover_core).
macro(rover_register_node target)
  cmake_parse_arguments(_rover "" "PLUGIN;EXECUTABLE" "" ${ARGN})
  rclcpp_components_register_node(${target} PLUGIN "${_rover_PLUGIN}" EXECUTABLE ${_rover_EXECUTABLE})
endmacro()
