#include "node/ros_uri.h"

#include <filesystem>
#include <mutex>

#include <ros/package.h>

namespace rigid_body_sim::node {
namespace {

constexpr char kPackageScheme[] = "package://";
constexpr char kFileScheme[] = "file://";

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

}  // namespace

physics::Result<std::string> ResolveRosUri(const std::string& uri) {
  if (StartsWith(uri, kFileScheme)) return uri.substr(std::string(kFileScheme).size());
  if (!StartsWith(uri, kPackageScheme)) return uri;
  const std::string rest = uri.substr(std::string(kPackageScheme).size());
  const std::size_t slash = rest.find('/');
  const std::string package = rest.substr(0, slash);
  if (package.empty())
    return physics::Result<std::string>::Error("URI '" + uri + "' names no package");
  // rospack keeps global state; calls are serialised.
  static std::mutex rospack_mutex;
  std::string package_path;
  {
    std::lock_guard<std::mutex> lock(rospack_mutex);
    package_path = ros::package::getPath(package);
  }
  if (package_path.empty()) {
    return physics::Result<std::string>::Error("package '" + package + "' of URI '" + uri +
                                               "' is not found");
  }
  if (slash == std::string::npos) return package_path;
  // The path inside the package, with '.' and '..' resolved by name: one
  // that climbs above the package's root is refused, and the path handed
  // on holds no '..' for the system to resolve through a symlink. Links the
  // package itself holds are followed, as the package's own content.
  const std::filesystem::path inside =
      std::filesystem::path(rest.substr(slash + 1)).lexically_normal();
  if (!inside.empty() && (*inside.begin() == ".." || inside.is_absolute())) {
    return physics::Result<std::string>::Error("URI '" + uri + "' leaves package '" + package +
                                               "': package:// paths stay inside their package");
  }
  return (std::filesystem::path(package_path) / inside).string();
}

}  // namespace rigid_body_sim::node
