#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "rigid_body_sim");
  ros::NodeHandle private_node("~");
  ROS_INFO("rigid_body_sim started");
  ros::spin();
  return 0;
}
