#include "io/mesh_collision_modes.h"

#include <cctype>

namespace rigid_body_sim::io {
namespace {

using physics::Result;

std::string Quoted(const std::string& text) { return "'" + text + "'"; }

std::string Trimmed(const char* text) {
  std::string value = text == nullptr ? "" : text;
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!value.empty() && space(value.back())) value.pop_back();
  std::size_t first = 0;
  while (first < value.size() && space(value[first])) ++first;
  return value.substr(first);
}

// The <mesh_collision> children of `parent` into modes[key].
physics::Status ReadModes(const TiXmlElement& parent, const std::string& where,
                          const std::pair<std::string, std::string>& key,
                          MeshCollisionModes* modes) {
  for (const TiXmlElement* element = parent.FirstChildElement("mesh_collision"); element != nullptr;
       element = element->NextSiblingElement("mesh_collision")) {
    const std::string value = Trimmed(element->GetText());
    if (value == "triangles") {
      (*modes)[key] = MeshCollision::kTriangles;
    } else if (value == "hull") {
      (*modes)[key] = MeshCollision::kHull;
    } else if (value == "decomposition") {
      (*modes)[key] = MeshCollision::kDecomposition;
    } else {
      return physics::Status::Error(where + " <mesh_collision> value " + Quoted(value) +
                                    " is not one of 'triangles', 'hull', 'decomposition'");
    }
  }
  return physics::Status::Ok();
}

}  // namespace

Result<MeshCollisionModes> ReadMeshCollisionModes(const TiXmlElement& robot) {
  MeshCollisionModes modes;
  for (const TiXmlElement* gazebo = robot.FirstChildElement("gazebo"); gazebo != nullptr;
       gazebo = gazebo->NextSiblingElement("gazebo")) {
    const char* reference = gazebo->Attribute("reference");
    if (reference == nullptr) continue;
    const std::string where = std::string("<gazebo reference=") + Quoted(reference) + ">";
    if (physics::Status status = ReadModes(*gazebo, where, {reference, ""}, &modes); !status.ok()) {
      return status;
    }
    for (const TiXmlElement* collision = gazebo->FirstChildElement("collision");
         collision != nullptr; collision = collision->NextSiblingElement("collision")) {
      const char* name = collision->Attribute("name");
      if (name == nullptr || *name == '\0') {
        if (collision->FirstChildElement("mesh_collision") == nullptr) continue;
        return Result<MeshCollisionModes>::Error(where +
                                                 " <collision> needs a name to take a "
                                                 "<mesh_collision>");
      }
      const std::string inner = where + " <collision name=" + Quoted(name) + ">";
      if (physics::Status status = ReadModes(*collision, inner, {reference, name}, &modes);
          !status.ok()) {
        return status;
      }
    }
  }
  return modes;
}

MeshCollision ModeOf(const MeshCollisionModes& modes, const std::string& link,
                     const std::string& collision) {
  if (!collision.empty()) {
    const auto own = modes.find({link, collision});
    if (own != modes.end()) return own->second;
  }
  const auto linked = modes.find({link, ""});
  return linked == modes.end() ? MeshCollision::kDefault : linked->second;
}

}  // namespace rigid_body_sim::io
