// Contact geometry produced by the narrow phase and consumed by the contact
// cache and the solver.
#ifndef RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_MANIFOLD_H_
#define RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_MANIFOLD_H_

#include <array>
#include <cstdint>
#include <limits>

#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Which pair of features produced a contact point, so a point can be matched
// with last step's point for warm starting. Baraff's two contact types are
// vertex/face and edge/edge; clipping adds the edge-crossing points of
// face/face and edge/face manifolds.
enum class FeatureType : std::uint8_t {
  kVertexFace = 0,  // vertex index_a of A against face index_b of B
  kFaceVertex = 1,  // face index_a of A against vertex index_b of B
  kEdgeEdge = 2,    // edge index_a of A against edge index_b of B
  kSphere = 3,      // a sphere's surface point; indices unused
};

// 32-bit indices: a static mesh's feature numbers its triangle (times 16,
// plus the feature of the triangle's prism), and meshes of more than 4,096
// triangles would otherwise give far-apart triangles the same id.
struct FeatureId {
  FeatureType type = FeatureType::kSphere;
  std::uint32_t index_a = 0;
  std::uint32_t index_b = 0;

  std::uint64_t Key() const {
    return (static_cast<std::uint64_t>(type) << 62) ^ (static_cast<std::uint64_t>(index_a) << 31) ^
           static_cast<std::uint64_t>(index_b);
  }
  friend bool operator==(FeatureId x, FeatureId y) {
    return x.type == y.type && x.index_a == y.index_a && x.index_b == y.index_b;
  }
};

struct ContactPoint {
  Vec3 position_world = Vec3::Zero();  // m, midway between the two surfaces
  double separation = 0.0;             // m, along the manifold normal; negative = penetration
  FeatureId feature;
};

// Up to four points sharing one normal, from B towards A.
struct ContactManifold {
  static constexpr int kMaxPoints = 4;
  Vec3 normal_world = Vec3::UnitZ();  // unit, from B to A
  std::array<ContactPoint, kMaxPoints> points;
  int point_count = 0;
};

// The feature that separated the shapes, or defined their contact, last
// step (Baraff's "defining face / defining edge"); cached per shape pair and
// tested first on the next step.
struct SeparatingWitness {
  enum class Type : std::uint8_t { kNone, kFaceA, kFaceB, kEdges };
  SeparatingWitness() = default;
  SeparatingWitness(Type feature, int a, int b) : type(feature), index_a(a), index_b(b) {}

  Type type = Type::kNone;
  int index_a = -1;  // face of A, or edge of A
  int index_b = -1;  // face of B, or edge of B
  // When the full separating-axis test between two polyhedra last ran: an
  // upper bound on their signed distance then (m, +infinity when none is
  // known), and B's pose in A's frame. While B has moved little in A's frame
  // since, the test's answer is bounded without running it
  // (CollidePolyhedra).
  double distance_bound = std::numeric_limits<double>::infinity();
  Pose a_from_b_at_test;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_CONTACT_CONTACT_MANIFOLD_H_
