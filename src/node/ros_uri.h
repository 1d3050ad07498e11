// Resolution of the URIs a URDF names its files by.
#ifndef RIGID_BODY_SIM_NODE_ROS_URI_H_
#define RIGID_BODY_SIM_NODE_ROS_URI_H_

#include <string>

#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::node {

// package://<package>/<path> through roslib, file://<path> and plain paths
// as they are. Fails, naming the URI, on an unknown package, or on a path
// whose '..' climbs above the package's directory.
physics::Result<std::string> ResolveRosUri(const std::string& uri);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_ROS_URI_H_
