// A static mesh's extra contact slots: copies of its shape that hold the
// second and later groups of a body's contacts with it (CollideConvexMesh),
// and the map between a slot's shape index and the caller's.
#include "physics/collision/mesh_collision.h"

#include <cstddef>
#include <variant>
#include <vector>

namespace rigid_body_sim::physics {
namespace {

// The number of the caller's shapes: those before the first slot copy.
int CallerShapeCount(const std::vector<ShapeDef>& shapes) {
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const auto* mesh = std::get_if<StaticMesh>(&shapes[i].geometry);
    if (mesh != nullptr && mesh->slot > 0) return static_cast<int>(i);
  }
  return static_cast<int>(shapes.size());
}

}  // namespace

void AddMeshSlots(std::vector<ShapeDef>* shapes) {
  const std::size_t count = shapes->size();
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::holds_alternative<StaticMesh>((*shapes)[i].geometry)) continue;
    for (int slot = 1; slot < StaticMesh::kContactSlots; ++slot) {
      ShapeDef copy = (*shapes)[i];
      std::get<StaticMesh>(copy.geometry).slot = slot;
      shapes->push_back(std::move(copy));
    }
  }
}

int MeshSlotShape(const std::vector<ShapeDef>& shapes, int owner, int slot) {
  if (slot == 0) return owner;
  int ordinal = 0;  // meshes before `owner`
  for (int i = 0; i < owner; ++i) ordinal += std::holds_alternative<StaticMesh>(shapes[i].geometry);
  return CallerShapeCount(shapes) + ordinal * (StaticMesh::kContactSlots - 1) + slot - 1;
}

int CallerShape(const std::vector<ShapeDef>& shapes, int shape) {
  // A body of one shape has no slot copies (a mesh brings kContactSlots - 1):
  // its shape is the caller's, with no shape read.
  if (shapes.size() == 1) return shape;
  const int callers = CallerShapeCount(shapes);
  if (shape < callers) return shape;
  int ordinal = (shape - callers) / (StaticMesh::kContactSlots - 1);
  for (int i = 0; i < callers; ++i) {
    if (std::holds_alternative<StaticMesh>(shapes[i].geometry) && ordinal-- == 0) return i;
  }
  return shape;
}

}  // namespace rigid_body_sim::physics
