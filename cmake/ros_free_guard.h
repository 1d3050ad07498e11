// Force-included into the ROS-free libraries (rigid_body_sim_physics and
// rigid_body_sim_io). Debian installs ROS headers in /usr/include, where
// include paths alone cannot hide them, so the ROS namespaces are poisoned:
// including any ROS header here fails to compile.
#pragma GCC poison ros tf2 tf2_ros geometry_msgs visualization_msgs std_msgs std_srvs roscpp
