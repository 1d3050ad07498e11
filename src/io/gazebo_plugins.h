// Reading a URDF's <gazebo> sensors and ROS plugins into GazeboPlugins
// (rigid_body_sim/io/gazebo_plugins.h), their links and joints checked
// against the model's. Defaults are those of gazebo_ros_pkgs' plugins
// (noetic-devel) unless a comment says why not.
#ifndef RIGID_BODY_SIM_SRC_IO_GAZEBO_PLUGINS_H_
#define RIGID_BODY_SIM_SRC_IO_GAZEBO_PLUGINS_H_

#include <map>
#include <set>
#include <string>

#include <tinyxml.h>

#include "io/gazebo_sdf.h"
#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::io {

// A joint as the plugins see it.
struct GazeboJoint {
  std::string type;  // URDF type: fixed, revolute, continuous, prismatic, ...
  std::string parent_link;
  std::string child_link;
};

// What references in <gazebo> elements may name.
struct GazeboModelNames {
  std::string root_link;                      // the model's base: a diff drive's link
  std::set<std::string> links;                // every link but 'world'
  std::map<std::string, GazeboJoint> joints;  // every joint, the one to 'world' too
};

// The names of a loaded model, with its joint to 'world' (which LoadedModel
// does not keep) read from `robot`.
GazeboModelNames ModelNamesOf(const LoadedModel& model, const TiXmlElement& robot);

// Reads every <gazebo> element of `robot`: the sensors and plugins it
// knows into their lists, any other <plugin> or <sensor> into `ignored`.
// Fails, naming the element, the field, the value and its allowed range,
// on a bad number, an unknown link or joint, or a joint of the wrong type.
physics::Result<GazeboPlugins> ReadGazeboPlugins(const TiXmlElement& robot,
                                                 const GazeboModelNames& names);

// Sets model->plugins from `robot` and appends plugins.ignored to
// model->ignored, each entry once.
physics::Status AddGazeboPlugins(const TiXmlElement& robot, LoadedModel* model);

// One <sensor> of a <gazebo reference="LINK_OR_JOINT"> element: added to
// `plugins` when one of its <plugin>s is known, else listed as ignored
// (gazebo_sensors.cc).
physics::Status ReadGazeboSensor(const TiXmlElement& gazebo, const TiXmlElement& sensor,
                                 const GazeboModelNames& names, GazeboPlugins* plugins);

// libgazebo_ros_ft_sensor.so's settings in `plugin` for `joint`, which
// must be a joint of the model other than the one to 'world';
// `default_rate` (Hz) when it gives no <updateRate>.
physics::Result<ForceTorqueSensor> ReadForceTorque(const SdfScope& plugin, const std::string& joint,
                                                   const GazeboModelNames& names,
                                                   double default_rate);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_SRC_IO_GAZEBO_PLUGINS_H_
