#include "io/urdf_load_options.h"

#include <string>

#include "io/urdf_elements.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/io/xacro_process.h"

namespace rigid_body_sim::io {

using physics::FormatNumber;
using physics::Result;
using physics::Status;

Status ValidateLoadOptions(const UrdfLoadOptions& options) {
  if (!PositiveFinite(options.default_density)) {
    return Status::Error("URDF load option default_density must be positive and finite, got " +
                         FormatNumber(options.default_density));
  }
  if (options.max_joints < 1) {
    return Status::Error("URDF load option max_joints must be at least 1, got " +
                         std::to_string(options.max_joints));
  }
  if (options.max_links < 1) {
    return Status::Error("URDF load option max_links must be at least 1, got " +
                         std::to_string(options.max_links));
  }
  if (options.hull.max_vertices < 4) {
    return Status::Error("URDF load option hull.max_vertices must be at least 4, got " +
                         std::to_string(options.hull.max_vertices));
  }
  return Status::Ok();
}

UriResolver ResolverOrDefault(const UrdfLoadOptions& options) {
  return options.resolver ? options.resolver : UriResolver(ResolveFileUri);
}

Result<std::string> ExpandedDescription(const std::string& path, const std::string& text,
                                        const UrdfLoadOptions& options) {
  if (!LooksLikeXacro(path, text)) return text;
  if (!options.xacro_expander) {
    return Result<std::string>::Error(
        "the description is xacro (a .xacro file or the xacro namespace); this load takes URDF "
        "only");
  }
  return options.xacro_expander(path, path.empty() ? text : std::string());
}

}  // namespace rigid_body_sim::io
