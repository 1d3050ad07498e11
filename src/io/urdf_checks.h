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
// MaxAspectRatio, and every <origin>, <mass> and <inertia> of links
// and joints for finite numbers within kMaxShapeSize.
physics::Status CheckUrdfDocument(const TiXmlElement& robot, const UrdfLoadOptions& options);

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

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_CHECKS_H_
