#include "physics/geometry/shape_bounds.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <variant>

namespace rigid_body_sim::physics {
namespace {

// Up to this many vertices, transforming them all is cheaper than six
// support queries.
constexpr std::size_t kDirectAabbVertexCount = 16;

Aabb PolyhedronAabb(const ConvexPolyhedron& polyhedron, const Pose& world_from_shape,
                    std::array<int, 6>* seeds) {
  if (polyhedron.vertices.size() <= kDirectAabbVertexCount) {
    Aabb box{Vec3::Constant(std::numeric_limits<double>::infinity()),
             Vec3::Constant(-std::numeric_limits<double>::infinity())};
    const Mat3 rotation = world_from_shape.rotation.toRotationMatrix();
    for (const Vec3& vertex : polyhedron.vertices) {
      const Vec3 vertex_world = Multiply(rotation, vertex) + world_from_shape.translation;
      box.min = box.min.cwiseMin(vertex_world);
      box.max = box.max.cwiseMax(vertex_world);
    }
    return box;
  }
  // The extreme vertex along +-axis of the world is the support vertex along
  // that axis expressed in the shape frame.
  const Mat3 shape_from_world = world_from_shape.rotation.conjugate().toRotationMatrix();
  Aabb box;
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 axis_shape = shape_from_world.col(axis);
    int high_vertex = 0;
    int low_vertex = 0;
    if (seeds != nullptr) {
      high_vertex = polyhedron.SupportVertexFrom(axis_shape, (*seeds)[2 * axis]);
      low_vertex = polyhedron.SupportVertexFrom(-axis_shape, (*seeds)[2 * axis + 1]);
      (*seeds)[2 * axis] = high_vertex;
      (*seeds)[2 * axis + 1] = low_vertex;
    } else {
      high_vertex = polyhedron.SupportVertexNearAxis(axis_shape);
      low_vertex = polyhedron.SupportVertexNearAxis(-axis_shape);
    }
    const Vec3& high = polyhedron.vertices[high_vertex];
    const Vec3& low = polyhedron.vertices[low_vertex];
    box.max[axis] = (world_from_shape * high)[axis];
    box.min[axis] = (world_from_shape * low)[axis];
  }
  return box;
}

}  // namespace

Aabb ShapeAabb(const ShapeGeometry& geometry, const Pose& world_from_shape,
               std::array<int, 6>* support_seeds) {
  if (const auto* sphere = std::get_if<Sphere>(&geometry)) {
    const Vec3 radius = Vec3::Constant(sphere->radius);
    return Aabb{world_from_shape.translation - radius, world_from_shape.translation + radius};
  }
  if (const auto* cylinder = std::get_if<Cylinder>(&geometry)) {
    // Along world axis e_i the cylinder reaches h |a_i| + r sqrt(1 - a_i^2).
    const Vec3 axis = world_from_shape.rotation * Vec3::UnitZ();
    Vec3 extent;
    for (int i = 0; i < 3; ++i) {
      extent[i] = cylinder->half_length * std::abs(axis[i]) +
                  cylinder->radius * std::sqrt(std::max(0.0, 1.0 - axis[i] * axis[i]));
    }
    return Aabb{world_from_shape.translation - extent, world_from_shape.translation + extent};
  }
  if (const auto* mesh = std::get_if<StaticMesh>(&geometry)) {
    // The mesh's own box turned: centre c and half extents e give the world
    // half extents |R| e.
    const Vec3 center = 0.5 * (mesh->mesh->upper() + mesh->mesh->lower());
    const Vec3 half = 0.5 * (mesh->mesh->upper() - mesh->mesh->lower());
    const Mat3 rotation = world_from_shape.rotation.toRotationMatrix();
    const Vec3 extent = rotation.cwiseAbs() * half;
    const Vec3 center_world = world_from_shape * center;
    return Aabb{center_world - extent, center_world + extent};
  }
  const auto* polyhedron = std::get_if<std::shared_ptr<const ConvexPolyhedron>>(&geometry);
  assert(polyhedron != nullptr && *polyhedron != nullptr);
  return PolyhedronAabb(**polyhedron, world_from_shape, support_seeds);
}

double ShapeThickness(const ShapeGeometry& geometry) {
  if (const auto* sphere = std::get_if<Sphere>(&geometry)) return 2.0 * sphere->radius;
  if (const auto* cylinder = std::get_if<Cylinder>(&geometry)) {
    return 2.0 * std::min(cylinder->radius, cylinder->half_length);
  }
  const auto* polyhedron = std::get_if<std::shared_ptr<const ConvexPolyhedron>>(&geometry);
  if (polyhedron == nullptr) return std::numeric_limits<double>::infinity();
  double thickness = std::numeric_limits<double>::infinity();
  for (const ConvexPolyhedron::Face& face : (*polyhedron)->faces) {
    const Vec3& opposite = (*polyhedron)->vertices[(*polyhedron)->SupportVertex(-face.normal)];
    thickness = std::min(thickness, face.offset - face.normal.dot(opposite));
  }
  return thickness;
}

double ShapeBoundingRadius(const ShapeGeometry& geometry, const Vec3& center_shape) {
  if (const auto* sphere = std::get_if<Sphere>(&geometry)) {
    return center_shape.norm() + sphere->radius;
  }
  if (const auto* cylinder = std::get_if<Cylinder>(&geometry)) {
    return center_shape.norm() + std::hypot(cylinder->radius, cylinder->half_length);
  }
  if (const auto* mesh = std::get_if<StaticMesh>(&geometry)) {
    return mesh->mesh->BoundingRadius(center_shape);
  }
  const auto* polyhedron = std::get_if<std::shared_ptr<const ConvexPolyhedron>>(&geometry);
  if (polyhedron == nullptr) return std::numeric_limits<double>::infinity();
  double radius = 0.0;
  for (const Vec3& vertex : (*polyhedron)->vertices) {
    radius = std::max(radius, (vertex - center_shape).norm());
  }
  return radius;
}

}  // namespace rigid_body_sim::physics
