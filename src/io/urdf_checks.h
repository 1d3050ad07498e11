// Checks of a URDF document's numbers before urdfdom reads it: urdfdom
// drops or misreports what it cannot parse (a NaN radius came back as "no
// <collision>"), and the shape builders must never see a size they cannot
// build. Every refusal names the element, the attribute, the value and the
// allowed range.
#ifndef RIGID_BODY_SIM_IO_URDF_CHECKS_H_
#define RIGID_BODY_SIM_IO_URDF_CHECKS_H_

#include <tinyxml.h>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Checks the link count against options.max_links, every collision
// geometry's sizes against kMinShapeSize, kMaxShapeSize and
// kMaxShapeAspectRatio, and every <origin>, <mass> and <inertia> of links
// and joints for finite numbers within kMaxShapeSize.
physics::Status CheckUrdfDocument(const TiXmlElement& robot, const UrdfLoadOptions& options);

// The extents of a shape's bounding box (m), within [kMinShapeSize,
// kMaxShapeSize] and with largest / smallest <= kMaxShapeAspectRatio;
// `what` names the shape in the message.
physics::Status CheckShapeExtents(const physics::Vec3& extents, const std::string& what);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_CHECKS_H_
