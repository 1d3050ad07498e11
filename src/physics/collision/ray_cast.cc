#include "physics/collision/ray_cast.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <variant>

#include "physics/geometry/wide_box_tree.h"

namespace rigid_body_sim::physics {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

RayHit MakeHit(const Ray& ray, double t, const Vec3& normal) {
  RayHit hit;
  hit.hit = true;
  hit.distance = t;
  hit.point = ray.origin + t * ray.direction;
  hit.normal = normal;
  return hit;
}

// The ray in a shape's frame (a pose keeps lengths, so t is the same).
Ray ToShape(const ShapeFrame& frame, const Ray& ray) {
  Ray local;
  local.origin = frame.shape_from_world * (ray.origin - frame.translation);
  local.direction = frame.shape_from_world * ray.direction;
  local.max_distance = ray.max_distance;
  return local;
}

// Moller and Trumbore 1997, "Fast, Minimum Storage Ray/Triangle
// Intersection", section 2: o + t d = (1 - u - v) v0 + u v1 + v v2 solved
// by Cramer's rule with the triple products, e1 = v1 - v0 and e2 = v2 - v0.
// Edges count as inside, so a ray through an edge two triangles share hits
// one of them. Returns t, or +infinity. Every quantity is computed before
// one test of them all: a ray's few triangles fail the tests at random, and
// a branch per test cost more in mispredictions than the arithmetic it
// skipped. With det = 0 (parallel to the plane), 1/det is infinite and u, v
// and t are infinite or NaN, which the tests refuse.
double RayTriangle(const Ray& ray, const Vec3& v0, const Vec3& e1, const Vec3& e2) {
  const Vec3 p = ray.direction.cross(e2);
  const double det = e1.dot(p);
  const double inverse = 1.0 / det;
  const Vec3 s = ray.origin - v0;
  const double u = s.dot(p) * inverse;
  const Vec3 q = s.cross(e1);
  const double v = ray.direction.dot(q) * inverse;
  const double t = e2.dot(q) * inverse;
  // & rather than &&: no branch per test.
  const bool inside =
      (det != 0.0) & (u >= 0.0) & (u <= 1.0) & (v >= 0.0) & (u + v <= 1.0) & (t >= 0.0);
  return inside ? t : kInfinity;
}

// Triangle `index` of the mesh against the ray, if it faces it (a closed
// component's triangles only from their outer side): t or +infinity.
double RayMeshTriangle(const CollisionMesh& mesh, int index, const Ray& ray) {
  const CollisionMesh::RayTriangle& triangle = mesh.ray_triangles()[index];
  if (!triangle.two_sided && triangle.normal.dot(ray.direction) >= 0.0) return kInfinity;
  return RayTriangle(ray, triangle.corner, triangle.edge1, triangle.edge2);
}

// A hit at t on triangle i before the best so far (ties go to the lower
// index, so that the walk and the brute force agree on shared edges).
bool Nearer(double t, int i, double best, int best_triangle) {
  if (!std::isfinite(t) || t > best) return false;
  return t < best || best_triangle < 0 || i < best_triangle;
}

RayHit MeshHit(const CollisionMesh& mesh, const Ray& ray, double t, int triangle) {
  if (triangle < 0) return RayHit{};
  const Vec3& normal = mesh.ray_triangles()[triangle].normal;
  return MakeHit(ray, t, normal.dot(ray.direction) < 0.0 ? normal : Vec3(-normal));
}

}  // namespace

// |o + t d|^2 = r^2 with |d| = 1: t = -b -+ sqrt(r^2 - |o - b d|^2), b = o.d.
// The discriminant is taken as r^2 less the squared distance of the line
// from the centre and the entry as c / (-b + sqrt(.)), c = |o|^2 - r^2,
// which lose no digits to cancellation far from the sphere (Haines, Gunther
// and Akenine-Moller 2019, "Precision Improvements for Ray/Sphere
// Intersection", Ray Tracing Gems, chapter 7, section 7.3).
RayHit RayCastSphere(double radius, const Ray& ray) {
  const double b = ray.origin.dot(ray.direction);
  const double c = ray.origin.squaredNorm() - radius * radius;
  if (c < 0.0 || b >= 0.0) return RayHit{};  // starts inside, or moves away
  const double discriminant = radius * radius - (ray.origin - b * ray.direction).squaredNorm();
  if (discriminant < 0.0) return RayHit{};
  const double t = c / (-b + std::sqrt(discriminant));
  if (t > ray.max_distance) return RayHit{};
  const Vec3 point = ray.origin + t * ray.direction;
  return MakeHit(ray, t, point / radius);
}

// The solid cylinder x^2 + y^2 <= r^2, |z| <= h: the ray's interval inside
// the infinite cylinder (the same quadratic as the sphere's, in x and y)
// intersected with its interval between the caps; the entry is on the cap
// or the side, whichever interval begins later.
RayHit RayCastCylinder(const Cylinder& cylinder, const Ray& ray) {
  const Vec3& o = ray.origin;
  const Vec3& d = ray.direction;
  const double r = cylinder.radius;
  const double h = cylinder.half_length;
  double cap_entry = -kInfinity;
  double cap_exit = kInfinity;
  if (d.z() != 0.0) {
    const double t1 = (-h - o.z()) / d.z();
    const double t2 = (h - o.z()) / d.z();
    cap_entry = std::min(t1, t2);
    cap_exit = std::max(t1, t2);
  } else if (std::abs(o.z()) > h) {
    return RayHit{};
  }
  double side_entry = -kInfinity;
  double side_exit = kInfinity;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a > 0.0) {
    const double b = o.x() * d.x() + o.y() * d.y();
    const double px = o.x() - (b / a) * d.x();
    const double py = o.y() - (b / a) * d.y();
    const double discriminant = r * r - (px * px + py * py);
    if (discriminant < 0.0) return RayHit{};
    const double root = std::sqrt(a * discriminant);
    side_entry = b < 0.0 ? c / (-b + root) : (-b - root) / a;
    side_exit = b < 0.0 ? (-b + root) / a : c / (-b - root);
  } else if (c > 0.0) {
    return RayHit{};
  }
  const double entry = std::max(cap_entry, side_entry);
  const double exit = std::min(cap_exit, side_exit);
  const bool inside = c < 0.0 && std::abs(o.z()) < h;
  if (inside || entry > exit || entry < 0.0 || entry > ray.max_distance) return RayHit{};
  const Vec3 point = o + entry * d;
  const Vec3 normal = cap_entry >= side_entry ? Vec3(0.0, 0.0, d.z() > 0.0 ? -1.0 : 1.0)
                                              : Vec3(point.x() / r, point.y() / r, 0.0);
  return MakeHit(ray, entry, normal);
}

// Cyrus and Beck 1978, "Generalized two- and three-dimensional clipping",
// the clip of a line by a convex polyhedron: each face plane n.x = c bounds
// t from below where the ray enters (n.d < 0) and from above where it
// leaves (n.d > 0); the hit is the largest entry, if it comes before the
// smallest exit. A ray parallel to a face outside it misses.
RayHit RayCastPolyhedron(const ConvexPolyhedron& polyhedron, const Ray& ray) {
  double entry = -kInfinity;
  double exit = kInfinity;
  int entry_face = -1;
  bool outside = false;
  for (std::size_t f = 0; f < polyhedron.faces.size(); ++f) {
    const ConvexPolyhedron::Face& face = polyhedron.faces[f];
    const double rate = face.normal.dot(ray.direction);
    const double room = face.offset - face.normal.dot(ray.origin);  // >= 0 inside the plane
    outside = outside || room < 0.0;
    if (rate == 0.0) {
      if (room < 0.0) return RayHit{};
      continue;
    }
    const double t = room / rate;
    if (rate < 0.0) {
      if (t > entry) {
        entry = t;
        entry_face = static_cast<int>(f);
      }
    } else {
      exit = std::min(exit, t);
    }
    if (entry > exit) return RayHit{};
  }
  if (!outside || entry_face < 0 || entry < 0.0 || entry > ray.max_distance) return RayHit{};
  return MakeHit(ray, entry, polyhedron.faces[entry_face].normal);
}

// z <= 0: a ray from above that points down enters at t = -o_z / d_z.
RayHit RayCastHalfSpace(const Ray& ray) {
  if (!(ray.origin.z() >= 0.0 && ray.direction.z() < 0.0)) return RayHit{};
  const double t = -ray.origin.z() / ray.direction.z();
  if (t > ray.max_distance) return RayHit{};
  return MakeHit(ray, t, Vec3::UnitZ());
}

// The mesh's tree walked nearest child first, a leaf skipped when it
// begins beyond the nearest hit so far; the triangles in double precision.
RayHit RayCastMesh(const CollisionMesh& mesh, const Ray& ray) {
  double best = ray.max_distance;
  int best_triangle = -1;
  mesh.tree().CastRay(ray.origin, ray.direction, &best, [&](int first, int count) {
    for (int i = first; i < first + count; ++i) {
      const double t = RayMeshTriangle(mesh, i, ray);
      if (Nearer(t, i, best, best_triangle)) {
        best = t;
        best_triangle = i;
      }
    }
  });
  return MeshHit(mesh, ray, best, best_triangle);
}

RayHit RayCastMeshBruteForce(const CollisionMesh& mesh, const Ray& ray) {
  double best = ray.max_distance;
  int best_triangle = -1;
  for (int i = 0; i < static_cast<int>(mesh.triangles().size()); ++i) {
    const double t = RayMeshTriangle(mesh, i, ray);
    if (Nearer(t, i, best, best_triangle)) {
      best = t;
      best_triangle = i;
    }
  }
  return MeshHit(mesh, ray, best, best_triangle);
}

RayHit RayCastShape(const ShapeGeometry& geometry, const Pose& world_from_shape, const Ray& ray) {
  return RayCastShape(geometry, ShapeFrame(world_from_shape), ray);
}

RayHit RayCastShape(const ShapeGeometry& geometry, const ShapeFrame& frame, const Ray& ray) {
  const Ray local = ToShape(frame, ray);
  RayHit hit = std::visit(
      [&local](const auto& shape) -> RayHit {
        using T = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          return RayCastSphere(shape.radius, local);
        } else if constexpr (std::is_same_v<T, Cylinder>) {
          return RayCastCylinder(shape, local);
        } else if constexpr (std::is_same_v<T, HalfSpace>) {
          return RayCastHalfSpace(local);
        } else if constexpr (std::is_same_v<T, StaticMesh>) {
          return RayCastMesh(*shape.mesh, local);
        } else {
          return RayCastPolyhedron(*shape, local);
        }
      },
      geometry);
  if (!hit.hit) return hit;
  hit.point = ray.origin + hit.distance * ray.direction;
  hit.normal = frame.shape_from_world.transpose() * hit.normal;
  return hit;
}

}  // namespace rigid_body_sim::physics
