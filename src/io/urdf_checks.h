// Checks of a URDF document's numbers before urdfdom reads it: urdfdom
// drops or misreports what it cannot parse (a NaN radius came back as "no
// <collision>"), and the shape builders must never see a size they cannot
// build. Every refusal names the element, the attribute, the value and the
// allowed range.
#ifndef RIGID_BODY_SIM_IO_URDF_CHECKS_H_
#define RIGID_BODY_SIM_IO_URDF_CHECKS_H_

#include <tinyxml.h>
#include <urdf_model/model.h>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Checks the link count against options.max_links, every collision
// geometry's sizes against kMinShapeSize, kMaxShapeSize and
// MaxAspectRatio, every <origin>, <mass> and <inertia> of links and joints
// for finite numbers within kMaxShapeSize, and every number of a joint's
// <axis>, <limit>, <dynamics>, <mimic>, <safety_controller> and
// <calibration> against its range. A number whose magnitude underflows a
// normal double (1e-320) is refused as well: it is not the number written.
physics::Status CheckUrdfDocument(const TiXmlElement& robot, const UrdfLoadOptions& options);

// Every mimic joint of a movable type with its leader (urdfdom's reading):
// multiplier * [leader lower, upper] + offset within kMaxJointPosition when
// the leader is limited on both sides within it, |multiplier| * the
// leader's velocity limit within kMaxJointSpeed, and the leader's effort
// limit times its effort scale (1 + the sum of its mimics' squared
// multipliers) finite. Leaders are CheckJoints' to name (urdf_loader.cc).
physics::Status CheckMimicJoints(const urdf::ModelInterface& model);

// The extents of a shape's bounding box (m), within [kMinShapeSize,
// kMaxShapeSize] and with largest / smallest <= max_aspect_ratio; `what`
// names the shape in the message.
physics::Status CheckShapeExtents(const physics::Vec3& extents, const std::string& what,
                                  double max_aspect_ratio);

// kMaxShapeAspectRatio for a moving body, whose inertia and contacts a
// sliver would ill-condition; a static shape (a ground slab) is bounded by
// the size range alone.
double MaxAspectRatio(bool static_model);

// Every link but 'world' states <inertial><mass value="0">: Bullet's way
// of writing a static model (a ground plane, a table).
bool EveryLinkIsMassless(const TiXmlElement& robot);

// The model will be static: spawned so, fixed to 'world', or massless.
bool IsStaticDocument(const TiXmlElement& robot, const UrdfLoadOptions& options);

// One entry per distinct <transmission> (ros_control's; joint commands drive
// the joints directly), in document order: "<transmission 'NAME'>". The
// loader appends the <gazebo> plugins and sensors that ReadGazeboPlugins
// does not hold (gazebo_plugins.h), worded "<gazebo> plugin 'NAME'
// (FILENAME)" and "<gazebo reference='LINK'> sensor 'NAME' (TYPE)".
std::vector<std::string> IgnoredElements(const TiXmlElement& robot);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_CHECKS_H_
