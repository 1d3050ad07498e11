#include "rigid_body_sim/physics/shape.h"

#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>

namespace rigid_body_sim::physics {
namespace {

// Callers normalise quaternions they read; what is left is rounding.
constexpr double kQuaternionNormTolerance = 1e-6;

Status ValidateGeometry(const ShapeGeometry& geometry) {
  return std::visit(
      [](const auto& shape) -> Status {
        using T = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          if (!std::isfinite(shape.radius) || shape.radius <= 0.0) {
            std::ostringstream out;
            out << "sphere radius must be positive and finite, got " << shape.radius << " m";
            return Status::Error(out.str());
          }
          return Status::Ok();
        } else if constexpr (std::is_same_v<T, std::shared_ptr<const ConvexPolyhedron>>) {
          if (shape == nullptr) return Status::Error("polyhedron shape has no polyhedron");
          if (shape->vertices.size() < 4) {
            return Status::Error("polyhedron has " + std::to_string(shape->vertices.size()) +
                                 " vertices, needs at least 4");
          }
          return Status::Ok();
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          if (!std::isfinite(shape.radius) || shape.radius <= 0.0 ||
              !std::isfinite(shape.half_length) || shape.half_length <= 0.0) {
            std::ostringstream out;
            out << "cylinder radius and half length must be positive and finite, got "
                << shape.radius << " m and " << shape.half_length << " m";
            return Status::Error(out.str());
          }
          return Status::Ok();
        } else if constexpr (std::is_same_v<T, StaticMesh>) {
          if (shape.mesh == nullptr) return Status::Error("static mesh shape has no mesh");
          if (shape.slot != 0) {
            return Status::Error("static mesh slot is set by the world, must be 0, got " +
                                 std::to_string(shape.slot));
          }
          return Status::Ok();
        } else {
          static_assert(std::is_same_v<T, HalfSpace>, "unhandled shape geometry");
          return Status::Ok();
        }
      },
      geometry);
}

}  // namespace

Status ValidateShapeDef(const ShapeDef& shape) {
  const Pose& pose = shape.body_from_shape;
  if (!IsFinite(pose.translation)) {
    return Status::Error("shape pose translation is not finite");
  }
  if (!IsFinite(pose.rotation)) {
    return Status::Error("shape pose rotation is not finite");
  }
  const double norm = pose.rotation.norm();
  if (norm == 0.0) {
    return Status::Error("shape pose rotation is the zero quaternion");
  }
  if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
    std::ostringstream out;
    out.precision(12);
    out << "shape pose rotation is not a unit quaternion (norm " << norm << ")";
    return Status::Error(out.str());
  }
  const Status geometry = ValidateGeometry(shape.geometry);
  if (!geometry.ok()) return geometry;
  const Material& material = shape.material;
  if (!std::isfinite(material.friction) || material.friction < 0.0) {
    std::ostringstream out;
    out << "friction coefficient must be finite and >= 0, got " << material.friction;
    return Status::Error(out.str());
  }
  if (!std::isfinite(material.restitution) || material.restitution < 0.0 ||
      material.restitution > 1.0) {
    std::ostringstream out;
    out << "coefficient of restitution must be in [0, 1], got " << material.restitution;
    return Status::Error(out.str());
  }
  return Status::Ok();
}

}  // namespace rigid_body_sim::physics
