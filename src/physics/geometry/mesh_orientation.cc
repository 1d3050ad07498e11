// Orientation of a static mesh's connected components.
#include "physics/geometry/mesh_orientation.h"

#include <algorithm>
#include <cstddef>
#include <utility>

namespace rigid_body_sim::physics {
namespace {

// The triangles' edges as (vertex pair, 3 t + k) sorted by the pair, the
// smaller vertex first: the triangles around one edge form a run.
std::vector<std::pair<std::uint64_t, int>> SortedEdges(
    const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const auto v0 = static_cast<std::uint32_t>(triangles[t][k]);
      const auto v1 = static_cast<std::uint32_t>(triangles[t][(k + 1) % 3]);
      const std::uint64_t key =
          (std::uint64_t{std::min(v0, v1)} << 32) | std::uint64_t{std::max(v0, v1)};
      edges.emplace_back(key, static_cast<int>(3 * t + k));
    }
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

// Across each edge of exactly two triangles (a manifold edge): the other
// triangle, and whether both run the edge the same way (then one of them is
// wound against the other). Edges of one triangle or of three and more
// carry nothing: orientation does not propagate across them.
struct Adjacency {
  std::vector<int> across;                   // by 3 t + k; -1 for none
  std::vector<std::uint8_t> same_direction;  // by 3 t + k
};

Adjacency FindAdjacency(const std::vector<std::array<int, 3>>& triangles,
                        const std::vector<std::pair<std::uint64_t, int>>& edges) {
  Adjacency adjacency;
  adjacency.across.assign(edges.size(), -1);
  adjacency.same_direction.assign(edges.size(), 0);
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin + 1;
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    if (end - begin == 2) {
      const int x = edges[begin].second;
      const int y = edges[begin + 1].second;
      const bool same = triangles[x / 3][x % 3] == triangles[y / 3][y % 3];
      adjacency.across[x] = y / 3;
      adjacency.across[y] = x / 3;
      adjacency.same_direction[x] = adjacency.same_direction[y] = same ? 1 : 0;
    }
    begin = end;
  }
  return adjacency;
}

// Marks open the components with an edge that is not shared by exactly two
// of the component's own triangles: a boundary edge, or an edge of three or
// more triangles of which the component holds other than two.
void MarkOpenComponents(const std::vector<std::pair<std::uint64_t, int>>& edges,
                        const std::vector<int>& component, std::vector<std::uint8_t>* open) {
  std::vector<int> around;
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin + 1;
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    if (end - begin != 2) {
      around.clear();
      for (std::size_t e = begin; e < end; ++e) around.push_back(component[edges[e].second / 3]);
      std::sort(around.begin(), around.end());
      for (std::size_t i = 0; i < around.size();) {
        std::size_t j = i + 1;
        while (j < around.size() && around[j] == around[i]) ++j;
        if (j - i != 2) (*open)[around[i]] = 1;
        i = j;
      }
    }
    begin = end;
  }
}

}  // namespace

// Orientation propagation over the edge graph (Schneider and Eberly 2003,
// "Geometric Tools for Computer Graphics", section 9.3.3: a manifold mesh is
// consistently ordered when two faces sharing an edge run it in opposite
// directions). A breadth-first walk from the lowest unvisited triangle, the
// seed, crosses each manifold edge and gives the neighbour the seed's
// orientation: reversed from its neighbour's when both run the edge the same
// way. A non-orientable component (a Moebius strip) keeps what the walk
// gave. Then each component as a whole: a closed one keeps the orientation
// of positive signed volume, sum over its triangles of
// (a - r) . ((b - r) x (c - r)) / 6 (the divergence theorem, as in Mirtich
// 1996; r, a vertex of the seed, keeps the terms small), so its normals
// point out; an open one keeps the orientation of the larger part of its
// area as given, the seed's on a tie.
MeshOrientation OrientComponents(const std::vector<Vec3>& vertices,
                                 const std::vector<std::array<int, 3>>& triangles) {
  const int count = static_cast<int>(triangles.size());
  MeshOrientation orientation;
  orientation.flip.assign(count, 0);
  const std::vector<std::pair<std::uint64_t, int>> edges = SortedEdges(triangles);
  const Adjacency adjacency = FindAdjacency(triangles, edges);
  std::vector<int> component(count, -1);
  std::vector<int> order;  // the triangles component by component, as walked
  order.reserve(count);
  std::vector<std::size_t> starts;
  for (int seed = 0; seed < count; ++seed) {
    if (component[seed] >= 0) continue;
    component[seed] = static_cast<int>(starts.size());
    starts.push_back(order.size());
    order.push_back(seed);
    for (std::size_t head = starts.back(); head < order.size(); ++head) {
      const int t = order[head];
      for (int k = 0; k < 3; ++k) {
        const int u = adjacency.across[3 * t + k];
        if (u < 0 || component[u] >= 0) continue;
        component[u] = component[t];
        orientation.flip[u] = orientation.flip[t] ^ adjacency.same_direction[3 * t + k];
        order.push_back(u);
      }
    }
  }
  orientation.components = static_cast<int>(starts.size());
  std::vector<std::uint8_t> component_open(starts.size(), 0);
  MarkOpenComponents(edges, component, &component_open);
  starts.push_back(order.size());
  for (int walked = 0; walked < orientation.components; ++walked) {
    const std::size_t first = starts[walked];
    const std::size_t last = starts[walked + 1];
    const Vec3& reference = vertices[triangles[order[first]][0]];
    double volume = 0.0;     // x6, as walked
    double kept_area = 0.0;  // x2, of the triangles the walk keeps
    double flip_area = 0.0;  // x2, of those it reverses
    for (std::size_t i = first; i < last; ++i) {
      const std::array<int, 3>& triangle = triangles[order[i]];
      const Vec3 a = vertices[triangle[0]] - reference;
      const Vec3 b = vertices[triangle[1]] - reference;
      const Vec3 c = vertices[triangle[2]] - reference;
      const bool flip = orientation.flip[order[i]] != 0;
      volume += (flip ? -1.0 : 1.0) * a.dot(b.cross(c));
      (flip ? flip_area : kept_area) += (b - a).cross(c - a).norm();
    }
    const bool reverse = component_open[walked] ? flip_area > kept_area : volume < 0.0;
    for (std::size_t i = first; i < last; ++i) {
      orientation.flip[order[i]] ^= reverse ? 1 : 0;
    }
  }
  orientation.open.resize(count);
  for (int t = 0; t < count; ++t) orientation.open[t] = component_open[component[t]];
  return orientation;
}

}  // namespace rigid_body_sim::physics
