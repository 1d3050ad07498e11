// What LoadUrdfString and LoadUrdfFile do before they build a model: check
// the load options, pick the URI resolver, and expand a xacro description.
#ifndef RIGID_BODY_SIM_IO_URDF_LOAD_OPTIONS_H_
#define RIGID_BODY_SIM_IO_URDF_LOAD_OPTIONS_H_

#include <string>

#include "rigid_body_sim/io/urdf_loader.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::io {

// The options' own ranges: density positive, max_joints, max_links >= 1,
// hull.max_vertices >= 4.
physics::Status ValidateLoadOptions(const UrdfLoadOptions& options);

// options.resolver, else ResolveFileUri.
UriResolver ResolverOrDefault(const UrdfLoadOptions& options);

// The URDF of a description: `text` itself, or what options.xacro_expander
// makes of it (of the file at `path` when it is not empty) when it is xacro
// (LooksLikeXacro); refused, saying so, when it is xacro and there is no
// expander.
physics::Result<std::string> ExpandedDescription(const std::string& path, const std::string& text,
                                                 const UrdfLoadOptions& options);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_LOAD_OPTIONS_H_
