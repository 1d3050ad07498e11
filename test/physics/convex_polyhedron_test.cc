#include "rigid_body_sim/physics/convex_polyhedron.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh_fixtures.h"
#include "rigid_body_sim/physics/shape.h"

namespace rigid_body_sim::physics {
namespace {

using testing::Contains;
using testing::Icosphere;
using testing::PrismMassProperties;
using testing::RelativeDifference;

// Invariants every polyhedron must satisfy: twins run opposite ways, each
// face loop closes and keeps its face, vertex_half_edge leaves its vertex,
// Euler's formula for a sphere, each face plane holds its vertices and has
// every vertex on or behind it, unit outward normals, every edge direction
// represented exactly once up to sign.
void ExpectWellFormed(const ConvexPolyhedron& polyhedron) {
  const double tolerance = 1e-12;
  const int half_edge_count = static_cast<int>(polyhedron.half_edges.size());
  ASSERT_EQ(half_edge_count % 2, 0);
  for (int h = 0; h < half_edge_count; ++h) {
    const ConvexPolyhedron::HalfEdge& half_edge = polyhedron.half_edges[h];
    const ConvexPolyhedron::HalfEdge& twin = polyhedron.half_edges[ConvexPolyhedron::Twin(h)];
    ASSERT_GE(half_edge.next, 0);
    EXPECT_EQ(twin.origin, polyhedron.half_edges[half_edge.next].origin) << "half-edge " << h;
    EXPECT_EQ(polyhedron.half_edges[half_edge.next].face, half_edge.face);
    EXPECT_NE(twin.face, half_edge.face);
  }
  for (int v = 0; v < static_cast<int>(polyhedron.vertices.size()); ++v) {
    EXPECT_EQ(polyhedron.half_edges[polyhedron.vertex_half_edge[v]].origin, v);
  }
  const int face_count = static_cast<int>(polyhedron.faces.size());
  EXPECT_EQ(static_cast<int>(polyhedron.vertices.size()) - polyhedron.EdgeCount() + face_count, 2);
  int loop_total = 0;
  for (int f = 0; f < face_count; ++f) {
    const ConvexPolyhedron::Face& face = polyhedron.faces[f];
    EXPECT_NEAR(face.normal.norm(), 1.0, tolerance);
    const std::vector<int> loop = polyhedron.FaceVertices(f);
    loop_total += static_cast<int>(loop.size());
    for (int v : loop) EXPECT_NEAR(face.normal.dot(polyhedron.vertices[v]), face.offset, tolerance);
    double furthest_in_front = -std::numeric_limits<double>::infinity();
    for (const Vec3& vertex : polyhedron.vertices) {
      furthest_in_front = std::max(furthest_in_front, face.normal.dot(vertex) - face.offset);
    }
    EXPECT_LE(furthest_in_front, tolerance) << "face " << f;
    // Counter-clockwise from outside: the polygon's area vector is +normal.
    Vec3 area = Vec3::Zero();
    for (std::size_t i = 0; i < loop.size(); ++i) {
      area += polyhedron.vertices[loop[i]].cross(polyhedron.vertices[loop[(i + 1) % loop.size()]]);
    }
    EXPECT_GT(area.dot(face.normal), 0.0);
    EXPECT_LT(area.normalized().cross(face.normal).norm(), 1e-9);
  }
  EXPECT_EQ(loop_total, half_edge_count);
  for (int e = 0; e < polyhedron.EdgeCount(); ++e) {
    const Vec3 direction = (polyhedron.vertices[polyhedron.half_edges[2 * e + 1].origin] -
                            polyhedron.vertices[polyhedron.half_edges[2 * e].origin])
                               .normalized();
    const auto matches =
        std::count_if(polyhedron.edge_directions.begin(), polyhedron.edge_directions.end(),
                      [&](const Vec3& other) { return direction.cross(other).norm() < 1e-9; });
    EXPECT_EQ(matches, 1) << "edge " << e;
  }
}

std::vector<std::vector<int>> AllFaceLoops(const ConvexPolyhedron& polyhedron) {
  std::vector<std::vector<int>> loops;
  for (int f = 0; f < static_cast<int>(polyhedron.faces.size()); ++f) {
    loops.push_back(polyhedron.FaceVertices(f));
  }
  return loops;
}

TEST(ConvexPolyhedronTest, Box) {
  const Vec3 size(1.0, 2.0, 0.5);
  const ConvexPolyhedron box = MakeBoxPolyhedron(size);
  ExpectWellFormed(box);
  EXPECT_EQ(box.vertices.size(), 8u);
  EXPECT_EQ(box.faces.size(), 6u);
  EXPECT_EQ(box.EdgeCount(), 12);
  EXPECT_EQ(box.edge_directions.size(), 3u);
  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(box.FaceVertices(f).size(), 4u);
    // Axis-aligned faces at half the size along their normal.
    const Vec3& normal = box.faces[f].normal;
    int axis;
    EXPECT_NEAR(normal.cwiseAbs().maxCoeff(&axis), 1.0, 1e-15);
    EXPECT_NEAR(box.faces[f].offset, 0.5 * size[axis], 1e-15);
  }
  for (const Vec3& vertex : box.vertices) {
    EXPECT_TRUE(((vertex.cwiseAbs() - 0.5 * size).cwiseAbs().array() < 1e-15).all());
  }
  EXPECT_LT(box.centroid.norm(), 1e-15);
}

TEST(ConvexPolyhedronTest, TriangulatedCubeMergesIntoSixQuads) {
  const ConvexPolyhedron reference = MakeBoxPolyhedron(Vec3(2.0, 2.0, 2.0));
  // Shift the cube off the origin and add an unused vertex in front so the
  // indices must be remapped.
  std::vector<Vec3> vertices = {Vec3(10.0, 10.0, 10.0)};
  for (const Vec3& vertex : reference.vertices) vertices.push_back(vertex + Vec3(0.5, -3.0, 1.0));
  std::vector<std::vector<int>> triangles;
  for (const Eigen::Vector3i& t : reference.Triangulate().triangles) {
    triangles.push_back({t[0] + 1, t[1] + 1, t[2] + 1});
  }
  ASSERT_EQ(triangles.size(), 12u);
  const Result<ConvexPolyhedron> cube = MakeConvexPolyhedron(vertices, triangles);
  ASSERT_TRUE(cube.ok()) << cube.message();
  ExpectWellFormed(*cube);
  EXPECT_EQ(cube->vertices.size(), 8u);
  EXPECT_EQ(cube->faces.size(), 6u);
  EXPECT_EQ(cube->EdgeCount(), 12);
  EXPECT_EQ(cube->edge_directions.size(), 3u);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(cube->FaceVertices(f).size(), 4u);
  EXPECT_LT((cube->centroid - Vec3(0.5, -3.0, 1.0)).norm(), 1e-14);
}

// Each cube face fanned from a vertex at its centre: the centres end up
// inside merged faces and are dropped.
TEST(ConvexPolyhedronTest, FaceCentreVerticesAreDropped) {
  const ConvexPolyhedron reference = MakeBoxPolyhedron(Vec3(1.0, 3.0, 2.0));
  std::vector<Vec3> vertices = reference.vertices;
  std::vector<std::vector<int>> triangles;
  for (const std::vector<int>& loop : AllFaceLoops(reference)) {
    const int centre = static_cast<int>(vertices.size());
    Vec3 sum = Vec3::Zero();
    for (int v : loop) sum += reference.vertices[v];
    vertices.push_back(sum / static_cast<double>(loop.size()));
    for (std::size_t i = 0; i < loop.size(); ++i) {
      triangles.push_back({centre, loop[i], loop[(i + 1) % loop.size()]});
    }
  }
  ASSERT_EQ(triangles.size(), 24u);
  const Result<ConvexPolyhedron> cube = MakeConvexPolyhedron(vertices, triangles);
  ASSERT_TRUE(cube.ok()) << cube.message();
  ExpectWellFormed(*cube);
  EXPECT_EQ(cube->vertices, reference.vertices);
  EXPECT_EQ(cube->faces.size(), 6u);
  EXPECT_EQ(cube->EdgeCount(), 12);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(cube->FaceVertices(f).size(), 4u);
}

// A vertex in the middle of a cube edge, used by both faces at that edge,
// fanned into triangles: merging gives two pentagons with a straight angle,
// and removing the collinear vertex gives the plain cube back.
TEST(ConvexPolyhedronTest, CollinearVertexOnMergedEdgeIsRemoved) {
  const ConvexPolyhedron reference = MakeBoxPolyhedron(Vec3(1.0, 1.0, 1.0));
  std::vector<Vec3> vertices = reference.vertices;
  const int a = reference.half_edges[0].origin;
  const int b = reference.half_edges[1].origin;
  const int middle = static_cast<int>(vertices.size());
  vertices.push_back(0.5 * (vertices[a] + vertices[b]));
  std::vector<std::vector<int>> faces;
  int fanned = 0;
  for (std::vector<int> loop : AllFaceLoops(reference)) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int from = loop[i];
      const int to = loop[(i + 1) % loop.size()];
      if ((from == a && to == b) || (from == b && to == a)) {
        loop.insert(loop.begin() + i + 1, middle);
        // Fan from the inserted vertex, which never gives a flat triangle.
        std::rotate(loop.begin(), loop.begin() + i + 1, loop.end());
        for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
          faces.push_back({loop[0], loop[k], loop[k + 1]});
        }
        ++fanned;
        loop.clear();
        break;
      }
    }
    if (!loop.empty()) faces.push_back(loop);
  }
  ASSERT_EQ(fanned, 2);
  const Result<ConvexPolyhedron> cube = MakeConvexPolyhedron(vertices, faces);
  ASSERT_TRUE(cube.ok()) << cube.message();
  ExpectWellFormed(*cube);
  EXPECT_EQ(cube->vertices.size(), 8u);
  EXPECT_EQ(cube->faces.size(), 6u);
  EXPECT_EQ(cube->EdgeCount(), 12);
  for (int f = 0; f < 6; ++f) EXPECT_EQ(cube->FaceVertices(f).size(), 4u);
}

TEST(ConvexPolyhedronTest, FaceLoopsRoundTrip) {
  const ConvexPolyhedron cylinder = MakeCylinderPolyhedron(0.5, 1.0, 12);
  const Result<ConvexPolyhedron> rebuilt =
      MakeConvexPolyhedron(cylinder.vertices, AllFaceLoops(cylinder));
  ASSERT_TRUE(rebuilt.ok()) << rebuilt.message();
  EXPECT_EQ(rebuilt->vertices, cylinder.vertices);
  EXPECT_EQ(AllFaceLoops(*rebuilt), AllFaceLoops(cylinder));
}

TEST(ConvexPolyhedronTest, CylinderCounts) {
  for (int segments : {3, 16, 17}) {
    const ConvexPolyhedron cylinder = MakeCylinderPolyhedron(0.3, 0.8, segments);
    ExpectWellFormed(cylinder);
    EXPECT_EQ(static_cast<int>(cylinder.vertices.size()), 2 * segments);
    EXPECT_EQ(static_cast<int>(cylinder.faces.size()), segments + 2);
    EXPECT_EQ(cylinder.EdgeCount(), 3 * segments);
    int side_faces = 0;
    int caps = 0;
    for (int f = 0; f < static_cast<int>(cylinder.faces.size()); ++f) {
      const int size = static_cast<int>(cylinder.FaceVertices(f).size());
      if (std::abs(cylinder.faces[f].normal.z()) > 1.0 - 1e-12) {
        EXPECT_EQ(size, segments);
        EXPECT_NEAR(cylinder.faces[f].offset, 0.4, 1e-15);
        ++caps;
      } else {
        EXPECT_EQ(size, 4);
        EXPECT_NEAR(cylinder.faces[f].normal.z(), 0.0, 1e-15);
        ++side_faces;
      }
    }
    EXPECT_EQ(caps, 2);
    EXPECT_EQ(side_faces, segments);
    // Ring edges i and i + n/2 are parallel for even n; all the vertical
    // edges share one direction.
    const int ring_directions = segments % 2 == 0 ? segments / 2 : segments;
    EXPECT_EQ(static_cast<int>(cylinder.edge_directions.size()), ring_directions + 1);
    EXPECT_LT(cylinder.centroid.norm(), 1e-15);
  }
}

TEST(ConvexPolyhedronTest, IcosphereKeepsEveryTriangle) {
  const TriangleMesh mesh = Icosphere(1.5, 3);
  std::vector<std::vector<int>> faces;
  for (const Eigen::Vector3i& t : mesh.triangles) faces.push_back({t[0], t[1], t[2]});
  const Result<ConvexPolyhedron> sphere = MakeConvexPolyhedron(mesh.vertices, faces);
  ASSERT_TRUE(sphere.ok()) << sphere.message();
  ExpectWellFormed(*sphere);
  EXPECT_EQ(sphere->faces.size(), 1280u);
  EXPECT_EQ(sphere->vertices.size(), 642u);
  EXPECT_EQ(sphere->EdgeCount(), 1920);
}

// Hill climbing must agree with the brute-force maximum of d . v.
void ExpectSupportMatchesBruteForce(const ConvexPolyhedron& polyhedron, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 direction(normal(random), normal(random), normal(random));
    double best = -std::numeric_limits<double>::infinity();
    double second = best;
    int best_vertex = -1;
    for (int v = 0; v < static_cast<int>(polyhedron.vertices.size()); ++v) {
      const double distance = polyhedron.vertices[v].dot(direction);
      if (distance > best) {
        second = best;
        best = distance;
        best_vertex = v;
      } else if (distance > second) {
        second = distance;
      }
    }
    // From vertex 0, and from the axis_support vertex nearest the direction.
    for (const int support :
         {polyhedron.SupportVertex(direction), polyhedron.SupportVertexNearAxis(direction)}) {
      ASSERT_GE(support, 0);
      EXPECT_NEAR(polyhedron.vertices[support].dot(direction), best, 1e-12 * direction.norm());
      if (best - second > 1e-9 * direction.norm()) {
        EXPECT_EQ(support, best_vertex) << "direction " << direction.transpose();
      }
    }
  }
  for (int k = 0; k < 6; ++k) {
    Vec3 axis = Vec3::Zero();
    axis[k / 2] = k % 2 == 0 ? 1.0 : -1.0;
    const Vec3& support = polyhedron.vertices[polyhedron.axis_support[k]];
    EXPECT_DOUBLE_EQ(support.dot(axis),
                     polyhedron.vertices[polyhedron.SupportVertex(axis)].dot(axis));
  }
}

TEST(ConvexPolyhedronTest, SupportVertexMatchesBruteForce) {
  ExpectSupportMatchesBruteForce(MakeCylinderPolyhedron(0.4, 1.7, 64), 11);
  ExpectSupportMatchesBruteForce(MakeBoxPolyhedron(Vec3(0.2, 3.0, 1.0)), 12);
  const TriangleMesh mesh = Icosphere(1.0, 3);
  std::vector<std::vector<int>> faces;
  for (const Eigen::Vector3i& t : mesh.triangles) faces.push_back({t[0], t[1], t[2]});
  const Result<ConvexPolyhedron> sphere = MakeConvexPolyhedron(mesh.vertices, faces);
  ASSERT_TRUE(sphere.ok()) << sphere.message();
  ExpectSupportMatchesBruteForce(*sphere, 13);
}

TEST(ConvexPolyhedronTest, MassPropertiesOfBoxAndPrism) {
  const Vec3 size(0.7, 0.2, 1.4);
  const MassProperties box_polyhedron = PolyhedronMassProperties(800.0, MakeBoxPolyhedron(size));
  const MassProperties box = BoxMassProperties(800.0, size);
  EXPECT_NEAR(box_polyhedron.mass, box.mass, 1e-12 * box.mass);
  EXPECT_LT(box_polyhedron.center_of_mass.norm(), 1e-14);
  EXPECT_LT(RelativeDifference(box_polyhedron.inertia_about_com, box.inertia_about_com), 1e-12);

  const MassProperties prism_polyhedron =
      PolyhedronMassProperties(800.0, MakeCylinderPolyhedron(0.25, 0.6, 64));
  const MassProperties prism = PrismMassProperties(800.0, 0.25, 0.6, 64);
  EXPECT_NEAR(prism_polyhedron.mass, prism.mass, 1e-12 * prism.mass);
  EXPECT_LT(RelativeDifference(prism_polyhedron.inertia_about_com, prism.inertia_about_com), 1e-12);
  const MassProperties cylinder = CylinderMassProperties(800.0, 0.25, 0.6);
  EXPECT_NEAR(prism_polyhedron.mass, cylinder.mass, 0.01 * cylinder.mass);
}

TEST(ConvexPolyhedronTest, RefusesBadInput) {
  const ConvexPolyhedron box = MakeBoxPolyhedron(Vec3(1.0, 1.0, 1.0));
  const std::vector<std::vector<int>> loops = AllFaceLoops(box);

  std::vector<std::vector<int>> open = loops;
  open.pop_back();
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(box.vertices, open).message(), "open"));

  std::vector<Vec3> nan_vertices = box.vertices;
  nan_vertices[2].z() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(
      Contains(MakeConvexPolyhedron(nan_vertices, loops).message(), "vertex 2 is not finite"));

  std::vector<std::vector<int>> bad_index = loops;
  bad_index[1][2] = 8;
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(box.vertices, bad_index).message(),
                       "vertex index 8 outside [0, 8)"));
  bad_index[1][2] = -1;
  EXPECT_TRUE(
      Contains(MakeConvexPolyhedron(box.vertices, bad_index).message(), "vertex index -1 outside"));

  std::vector<std::vector<int>> doubled = loops;
  doubled.push_back(loops[0]);
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(box.vertices, doubled).message(), "used by two faces"));

  std::vector<std::vector<int>> flipped = loops;
  std::reverse(flipped[3].begin(), flipped[3].end());
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(box.vertices, flipped).message(), "used by two faces"));

  std::vector<std::vector<int>> repeated = loops;
  repeated[0][3] = repeated[0][1];
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(box.vertices, repeated).message(), "repeats"));

  // Moving one corner along z bends its three faces.
  std::vector<Vec3> bent = box.vertices;
  bent[7].z() += 0.1;
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(bent, loops).message(), "not planar"));

  // Three collinear points make a face of zero area.
  std::vector<Vec3> flat_face_vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0),
                                          Vec3(0, 1, 0)};
  const std::vector<std::vector<int>> tetrahedron = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  EXPECT_TRUE(
      Contains(MakeConvexPolyhedron(flat_face_vertices, tetrahedron).message(), "degenerate"));
  // The same tetrahedron with real volume is accepted.
  flat_face_vertices[2] = Vec3(0, 0, -1);
  const Result<ConvexPolyhedron> tetra = MakeConvexPolyhedron(flat_face_vertices, tetrahedron);
  ASSERT_TRUE(tetra.ok()) << tetra.message();
  ExpectWellFormed(*tetra);
  EXPECT_LT((tetra->centroid - Vec3(0.25, 0.25, -0.25)).norm(), 1e-15);

  // A cube whose top face is dented by a vertex pushed inward.
  const TriangleMesh mesh = testing::BoxMesh(Vec3(1.0, 1.0, 1.0));
  std::vector<Vec3> dented_vertices = mesh.vertices;
  dented_vertices.emplace_back(0.0, 0.0, 0.2);
  std::vector<std::vector<int>> dented;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3 normal = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                            .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (normal.z() > 0.0) continue;
    dented.push_back({t[0], t[1], t[2]});
  }
  // Top corners (z = +0.5) counter-clockwise seen from above, fanned to the dent.
  const std::vector<int> top = {4, 5, 7, 6};
  for (int i = 0; i < 4; ++i) dented.push_back({8, top[i], top[(i + 1) % 4]});
  EXPECT_TRUE(Contains(MakeConvexPolyhedron(dented_vertices, dented).message(), "not convex"));
}

TEST(ShapeDefTest, AcceptsValidShapes) {
  ShapeDef sphere;
  sphere.geometry = Sphere{0.1};
  sphere.body_from_shape.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitY()));
  sphere.material = {0.0, 1.0};
  EXPECT_TRUE(ValidateShapeDef(sphere).ok()) << ValidateShapeDef(sphere).message();
  ShapeDef box;
  box.geometry = std::make_shared<const ConvexPolyhedron>(MakeBoxPolyhedron(Vec3::Ones()));
  EXPECT_TRUE(ValidateShapeDef(box).ok()) << ValidateShapeDef(box).message();
  ShapeDef ground;
  ground.geometry = HalfSpace{};
  EXPECT_TRUE(ValidateShapeDef(ground).ok());
}

TEST(ShapeDefTest, RefusesInvalidShapes) {
  ShapeDef good;
  good.geometry = Sphere{0.1};
  auto message = [](const ShapeDef& shape) { return ValidateShapeDef(shape).message(); };

  ShapeDef shape = good;
  shape.body_from_shape.translation.x() = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(Contains(message(shape), "translation is not finite"));
  shape = good;
  shape.body_from_shape.rotation = Quat(0.0, 0.0, 0.0, 0.0);
  EXPECT_TRUE(Contains(message(shape), "zero quaternion"));
  shape = good;
  shape.body_from_shape.rotation = Quat(1.0, 0.0, 0.01, 0.0);
  EXPECT_TRUE(Contains(message(shape), "not a unit quaternion"));
  shape = good;
  shape.body_from_shape.rotation.w() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(Contains(message(shape), "rotation is not finite"));

  shape = good;
  shape.geometry = Sphere{0.0};
  EXPECT_TRUE(Contains(message(shape), "sphere radius"));
  shape.geometry = Sphere{std::numeric_limits<double>::quiet_NaN()};
  EXPECT_TRUE(Contains(message(shape), "sphere radius"));
  shape.geometry = std::shared_ptr<const ConvexPolyhedron>();
  EXPECT_TRUE(Contains(message(shape), "no polyhedron"));
  shape.geometry = std::make_shared<const ConvexPolyhedron>();
  EXPECT_TRUE(Contains(message(shape), "0 vertices"));

  shape = good;
  shape.material.friction = -0.1;
  EXPECT_TRUE(Contains(message(shape), "friction"));
  shape.material.friction = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(Contains(message(shape), "friction"));
  shape = good;
  shape.material.restitution = 1.5;
  EXPECT_TRUE(Contains(message(shape), "restitution"));
  shape.material.restitution = -0.01;
  EXPECT_TRUE(Contains(message(shape), "restitution"));
}

}  // namespace
}  // namespace rigid_body_sim::physics
