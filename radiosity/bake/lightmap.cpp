// Lightmap layout (charts, projection, packing) and baking; see lightmap.h.

#include "radiosity/bake/lightmap.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <unordered_map>

#include <tiny_gltf.h>

#include "raytrace_core/io/gltf_file.h"

#include "radiosity/bake/onto_input.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/progress.h"

namespace gilt::radiosity::bake {

using solver::Solution;

using rc::InputError;
using rc::Vec2;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Faces of one mesh that lie in one plane of projection.
struct Chart {
  uint32_t mesh = 0;
  std::vector<uint32_t> faces;
  std::vector<Vec2> corner;  ///< three per face, in the chart's plane (scene units), later its rectangle's frame
  Vec2 extent{0.0f};         ///< the rectangle, from the origin, width ≥ height
  // Where packing put it, in texels: the rectangle's corner.
  double x = 0.0, y = 0.0;
};

/// Positions made equal by bits share an id, so faces whose vertices were split (for normals or
/// UVs) are still neighbours.
std::vector<uint32_t> weld(const std::vector<Vec3>& positions) {
  struct Key {
    uint32_t b[3];
    bool operator==(const Key& o) const { return std::memcmp(b, o.b, sizeof b) == 0; }
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      return (size_t(k.b[0]) * 0x9e3779b97f4a7c15ull) ^ (size_t(k.b[1]) * 0xc2b2ae3d27d4eb4full) ^
             (size_t(k.b[2]) * 0x165667b19e3779f9ull);
    }
  };
  std::unordered_map<Key, uint32_t, Hash> ids;
  ids.reserve(positions.size());
  std::vector<uint32_t> id(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    Key k;
    std::memcpy(k.b, &positions[v], sizeof k.b);
    id[v] = ids.emplace(k, uint32_t(ids.size())).first->second;
  }
  return id;
}

/// Do two triangles' interiors overlap by more than eps (separating axes of their six edges)?
bool triangles_overlap(const Vec2* a, const Vec2* b, float eps) {
  const auto separated_along = [&](const Vec2* t, int e) {
    const Vec2 d = t[(e + 1) % 3] - t[e];
    const Vec2 axis(-d.y, d.x);
    float a_lo = rc::kInfinity, a_hi = -rc::kInfinity, b_lo = rc::kInfinity, b_hi = -rc::kInfinity;
    for (int k = 0; k < 3; ++k) {
      const float pa = glm::dot(a[k], axis), pb = glm::dot(b[k], axis);
      a_lo = std::min(a_lo, pa), a_hi = std::max(a_hi, pa);
      b_lo = std::min(b_lo, pb), b_hi = std::max(b_hi, pb);
    }
    const float tol = eps * glm::length(axis);
    return a_hi <= b_lo + tol || b_hi <= a_lo + tol;
  };
  for (int e = 0; e < 3; ++e)
    if (separated_along(a, e) || separated_along(b, e)) return false;
  return true;
}

/// Grows the charts of one mesh.
void grow_charts(const rc::scene::TriangleMesh& mesh, uint32_t mesh_index, std::vector<Chart>& charts) {
  const size_t faces = mesh.triangle_count();
  if (faces == 0) return;
  const std::vector<uint32_t> id = weld(mesh.positions);
  // Faces around each welded edge.
  std::unordered_map<uint64_t, std::vector<uint32_t>> edge_faces;
  edge_faces.reserve(faces * 2);
  const auto edge_key = [&](uint32_t f, int e) {
    const uint32_t a = id[mesh.indices[3 * f + uint32_t(e)]], b = id[mesh.indices[3 * f + uint32_t((e + 1) % 3)]];
    return (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
  };
  std::vector<Vec3> normal(faces);
  std::vector<float> area(faces), longest(faces);
  for (uint32_t f = 0; f < faces; ++f) {
    const Vec3 &p0 = mesh.positions[mesh.indices[3 * f]], &p1 = mesh.positions[mesh.indices[3 * f + 1]],
               &p2 = mesh.positions[mesh.indices[3 * f + 2]];
    const Vec3 c = glm::cross(p1 - p0, p2 - p0);
    area[f] = 0.5f * glm::length(c);
    normal[f] = area[f] > 0.0f ? c / (2.0f * area[f]) : Vec3(0.0f);
    longest[f] = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
    for (int e = 0; e < 3; ++e) edge_faces[edge_key(f, e)].push_back(f);
  }
  std::vector<float> sorted_longest = longest;
  std::nth_element(sorted_longest.begin(), sorted_longest.begin() + long(faces / 2), sorted_longest.end());
  const float cell = std::max(2.0f * sorted_longest[faces / 2], 1e-12f);

  std::vector<uint32_t> order(faces);
  for (uint32_t f = 0; f < faces; ++f) order[f] = f;
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area[a] > area[b]; });
  std::vector<char> taken(faces, 0);
  const float min_cos = std::cos(kChartAngle * rc::kPi / 180.0f);

  for (const uint32_t seed : order) {
    if (taken[seed]) continue;
    Chart chart;
    chart.mesh = mesh_index;
    // The plane of projection: the seed's (any plane for a degenerate seed, whose area is zero).
    const Vec3 axis = area[seed] > 0.0f ? normal[seed] : Vec3(0.0f, 0.0f, 1.0f);
    const Vec3 helper = std::abs(axis.x) > 0.9f ? Vec3(0.0f, 1.0f, 0.0f) : Vec3(1.0f, 0.0f, 0.0f);
    const Vec3 tangent = glm::normalize(glm::cross(helper, axis)), bitangent = glm::cross(axis, tangent);
    const auto project = [&](uint32_t f, Vec2* out) {
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = mesh.positions[mesh.indices[3 * f + uint32_t(k)]];
        out[k] = Vec2(glm::dot(p, tangent), glm::dot(p, bitangent));
      }
    };
    // The chart's faces by grid cell, for the overlap test.
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    const auto cells = [&](const Vec2* t, auto&& visit) {
      const Vec2 lo = glm::min(t[0], glm::min(t[1], t[2])), hi = glm::max(t[0], glm::max(t[1], t[2]));
      const int64_t x0 = int64_t(std::floor(lo.x / cell)), x1 = int64_t(std::floor(hi.x / cell));
      const int64_t y0 = int64_t(std::floor(lo.y / cell)), y1 = int64_t(std::floor(hi.y / cell));
      for (int64_t x = x0; x <= x1; ++x)
        for (int64_t y = y0; y <= y1; ++y) visit((uint64_t(uint32_t(x)) << 32) | uint32_t(y));
    };
    const auto fits = [&](uint32_t f, const Vec2* t) {
      if (!(area[f] > 0.0f)) return true;  // covers nothing
      const float eps = 1e-4f * longest[f];
      bool clear = true;
      cells(t, [&](uint64_t key) {
        if (!clear) return;
        const auto it = grid.find(key);
        if (it == grid.end()) return;
        for (uint32_t local : it->second)
          if (triangles_overlap(t, &chart.corner[3 * size_t(local)], eps)) {
            clear = false;
            return;
          }
      });
      return clear;
    };
    const auto add = [&](uint32_t f, const Vec2* t) {
      taken[f] = 1;
      const uint32_t local = uint32_t(chart.faces.size());
      chart.faces.push_back(f);
      chart.corner.insert(chart.corner.end(), {t[0], t[1], t[2]});
      if (area[f] > 0.0f) cells(t, [&](uint64_t key) { grid[key].push_back(local); });
    };
    Vec2 t[3];
    project(seed, t);
    add(seed, t);
    std::deque<uint32_t> frontier{seed};
    while (!frontier.empty()) {
      const uint32_t f = frontier.front();
      frontier.pop_front();
      for (int e = 0; e < 3; ++e)
        for (const uint32_t g : edge_faces[edge_key(f, e)]) {
          if (taken[g]) continue;
          // Degenerate faces ride along with any neighbour; others must face the plane.
          if (area[g] > 0.0f && glm::dot(normal[g], axis) < min_cos) continue;
          project(g, t);
          if (!fits(g, t)) continue;
          add(g, t);
          frontier.push_back(g);
        }
    }
    charts.push_back(std::move(chart));
  }
}

/// Turns a chart to its smallest bounding rectangle (over its convex hull's edge directions),
/// wider than tall, with its corner at the origin.
void fit_rectangle(Chart& chart) {
  std::vector<Vec2> pts = chart.corner;
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  std::vector<Vec2> hull;
  if (pts.size() < 3) {
    hull = pts;
  } else {  // Andrew's monotone chain
    const auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
      return double(a.x - o.x) * double(b.y - o.y) - double(a.y - o.y) * double(b.x - o.x);
    };
    std::vector<Vec2> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
      h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
      while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
      h[k++] = pts[i];
    }
    h.resize(k - 1);
    hull = std::move(h);
  }
  Vec2 best_dir(1.0f, 0.0f);
  double best_area = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < std::max<size_t>(hull.size(), 1); ++i) {
    Vec2 d = hull.size() >= 2 ? hull[(i + 1) % hull.size()] - hull[i] : Vec2(1.0f, 0.0f);
    const float len = glm::length(d);
    if (!(len > 0.0f)) continue;
    d /= len;
    float x0 = rc::kInfinity, x1 = -rc::kInfinity, y0 = rc::kInfinity, y1 = -rc::kInfinity;
    for (const Vec2& p : hull) {
      const float x = glm::dot(p, d), y = d.x * p.y - d.y * p.x;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    const double a = double(x1 - x0) * double(y1 - y0);
    if (a < best_area) best_area = a, best_dir = d;
  }
  // Rotate into the frame (d, d⊥); swap axes if taller than wide. Both keep the chart's winding
  // or mirror it, which does not matter for a lightmap: each texel maps to one surface point.
  Vec2 lo(rc::kInfinity), hi(-rc::kInfinity);
  for (Vec2& p : chart.corner) {
    p = Vec2(glm::dot(p, best_dir), best_dir.x * p.y - best_dir.y * p.x);
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  }
  for (Vec2& p : chart.corner) p -= lo;
  chart.extent = hi - lo;
  if (chart.extent.y > chart.extent.x) {
    for (Vec2& p : chart.corner) p = Vec2(p.y, p.x);
    chart.extent = Vec2(chart.extent.y, chart.extent.x);
  }
}

/// A chart's cell in the atlas at `density` texels per unit: its rectangle, one texel more so
/// that a chart of no width still holds one, and the pad on each side.
int cell_size(float extent, double density) { return int(std::ceil(double(extent) * density)) + 1 + 2 * kLightmapPad; }

/// Shelf packing of charts (sorted by height, tallest first) into size × size; false when they do
/// not fit. Stores each chart's texel corner.
bool pack(std::vector<Chart>& charts, int size, double density) {
  int x = 0, y = 0, shelf = 0;
  for (Chart& c : charts) {
    const int w = cell_size(c.extent.x, density), h = cell_size(c.extent.y, density);
    if (w > size) return false;
    if (x + w > size) {
      y += shelf;
      x = 0;
      shelf = 0;
    }
    if (y + h > size) return false;
    c.x = x + kLightmapPad;
    c.y = y + kLightmapPad;
    x += w;
    shelf = std::max(shelf, h);
  }
  return true;
}

/// Closest point of triangle t to p, as barycentrics of t[1] and t[2] (Ericson, Real-Time
/// Collision Detection, §5.1.5, in 2D).
Vec2 closest_barycentric(const Vec2* t, const Vec2& p) {
  const Vec2 ab = t[1] - t[0], ac = t[2] - t[0], ap = p - t[0];
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return Vec2(0.0f, 0.0f);
  const Vec2 bp = p - t[1];
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return Vec2(1.0f, 0.0f);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return Vec2(d1 / (d1 - d3), 0.0f);
  const Vec2 cp = p - t[2];
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return Vec2(0.0f, 1.0f);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return Vec2(0.0f, d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec2(1.0f - w, w);
  }
  const float denom = 1.0f / (va + vb + vc);
  return Vec2(vb * denom, vc * denom);
}

/// The input's own UV set chosen for the lightmap, or why none was.
struct InputUvs {
  int set = -1;  ///< glTF TEXCOORD_<set>; OBJ and PLY: 0, their one set
  std::string why;
  std::vector<std::vector<Vec2>> corner_uv;  ///< per scene mesh, three per face
};

/// Vertex UVs of a glTF primitive's TEXCOORD_<set> (float, or normalized unsigned byte or
/// short); empty when it has none or they do not match the mesh's vertices.
std::vector<Vec2> gltf_uvs(const tinygltf::Model& model, const rc::scene::TriangleMesh& mesh, int set) {
  const rc::scene::MeshOrigin& o = mesh.origin;
  if (o.mesh < 0 || size_t(o.mesh) >= model.meshes.size() ||
      size_t(o.primitive) >= model.meshes[size_t(o.mesh)].primitives.size())
    return {};
  const auto& attributes = model.meshes[size_t(o.mesh)].primitives[size_t(o.primitive)].attributes;
  const auto it = attributes.find("TEXCOORD_" + std::to_string(set));
  if (it == attributes.end() || it->second < 0 || size_t(it->second) >= model.accessors.size()) return {};
  const tinygltf::Accessor& a = model.accessors[size_t(it->second)];
  if (a.type != TINYGLTF_TYPE_VEC2 || a.count != mesh.positions.size() || a.sparse.isSparse || a.bufferView < 0 ||
      size_t(a.bufferView) >= model.bufferViews.size())
    return {};
  const tinygltf::BufferView& view = model.bufferViews[size_t(a.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) return {};
  const std::vector<unsigned char>& buffer = model.buffers[size_t(view.buffer)].data;
  const int component = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  if (component <= 0) return {};
  const size_t stride = view.byteStride != 0 ? view.byteStride : size_t(2 * component);
  std::vector<Vec2> uv(a.count);
  for (size_t i = 0; i < a.count; ++i) {
    const size_t at = view.byteOffset + a.byteOffset + i * stride;
    if (at + size_t(2 * component) > buffer.size()) return {};
    for (int k = 0; k < 2; ++k) {
      const unsigned char* p = buffer.data() + at + size_t(k * component);
      float x = 0.0f;
      if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        std::memcpy(&x, p, 4);
      } else if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a.normalized) {
        x = float(*p) / 255.0f;
      } else if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a.normalized) {
        uint16_t v;
        std::memcpy(&v, p, 2);
        x = float(v) / 65535.0f;
      } else {
        return {};
      }
      uv[i][k] = x;
    }
  }
  return uv;
}

/// Whether one UV set of every baked mesh can hold the lightmap: inside [0, 1]², no face with
/// area flattened to none, and no two faces on the same texels (texel centres inside two faces,
/// at the atlas's size, beyond 0.1 % of those covered: touching charts share a few by rounding).
/// Returns an empty string when it can, else why not.
std::string check_uv_set(const rc::scene::Scene& scene, const std::vector<uint32_t>& baked,
                         const std::vector<std::vector<Vec2>>& corner_uv, int size) {
  std::vector<uint32_t> claimed(size_t(size) * size_t(size), 0);
  size_t covered = 0, shared = 0;
  for (uint32_t m : baked) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
      const Vec2* c = &corner_uv[m][3 * f];
      Vec2 t[3];
      for (int k = 0; k < 3; ++k) {
        if (!(c[k].x >= 0.0f && c[k].x <= 1.0f && c[k].y >= 0.0f && c[k].y <= 1.0f))
          return "UVs outside [0, 1] (a tiling texture's)";
        t[k] = c[k] * float(size);
      }
      const Vec3 &p0 = mesh.positions[mesh.indices[3 * f]], &p1 = mesh.positions[mesh.indices[3 * f + 1]],
                 &p2 = mesh.positions[mesh.indices[3 * f + 2]];
      const double twice = double(t[1].x - t[0].x) * (t[2].y - t[0].y) - double(t[1].y - t[0].y) * (t[2].x - t[0].x);
      if (twice == 0.0) {
        if (glm::length(glm::cross(p1 - p0, p2 - p0)) > 0.0f) return "a face whose UVs have no area";
        continue;
      }
      const Vec2 lo = glm::min(t[0], glm::min(t[1], t[2])), hi = glm::max(t[0], glm::max(t[1], t[2]));
      for (int y = std::max(0, int(std::floor(lo.y))); y <= std::min(size - 1, int(std::floor(hi.y))); ++y)
        for (int x = std::max(0, int(std::floor(lo.x))); x <= std::min(size - 1, int(std::floor(hi.x))); ++x) {
          const Vec2 q(float(x) + 0.5f, float(y) + 0.5f);
          const double b1 = (double(q.x - t[0].x) * (t[2].y - t[0].y) - double(q.y - t[0].y) * (t[2].x - t[0].x)) / twice;
          const double b2 = (double(t[1].x - t[0].x) * (q.y - t[0].y) - double(t[1].y - t[0].y) * (q.x - t[0].x)) / twice;
          if (!(b1 > 0.0 && b2 > 0.0 && b1 + b2 < 1.0)) continue;
          uint32_t& owner = claimed[size_t(y) * size_t(size) + size_t(x)];
          ++covered;
          if (owner != 0) ++shared;
          owner = 1;
        }
    }
  }
  if (covered == 0) return "no texel inside any face";
  if (double(shared) > 1e-3 * double(covered)) return "faces overlap in UV space";
  return {};
}

InputUvs input_uv_set(const rc::scene::Scene& scene, const std::vector<uint32_t>& baked, int size) {
  InputUvs out;
  const std::string& file = scene.model_files.at(size_t(scene.meshes[baked[0]].origin.file));
  const std::string ext = rc::io::lower_extension(file);
  std::vector<std::string> reasons;
  const auto try_set = [&](int set, const std::function<std::vector<Vec2>(const rc::scene::TriangleMesh&)>& vertex_uvs) {
    std::vector<std::vector<Vec2>> corner(scene.meshes.size());
    for (uint32_t m : baked) {
      const rc::scene::TriangleMesh& mesh = scene.meshes[m];
      const std::vector<Vec2> uv = vertex_uvs(mesh);
      if (uv.size() != mesh.positions.size()) {
        reasons.push_back("set " + std::to_string(set) + ": not on every mesh");
        return false;
      }
      for (uint32_t v : mesh.indices) corner[m].push_back(uv[v]);
    }
    const std::string why = check_uv_set(scene, baked, corner, size);
    if (!why.empty()) {
      reasons.push_back("set " + std::to_string(set) + ": " + why);
      return false;
    }
    out.set = set;
    out.corner_uv = std::move(corner);
    return true;
  };
  if (ext == ".gltf" || ext == ".glb") {
    const tinygltf::Model model = rc::io::read_gltf_file(file);
    // A mesh placed by several nodes shares its UVs between its instances, which are lit
    // differently: the input's sets cannot hold them all.
    std::map<int32_t, std::set<int32_t>> nodes_of_mesh;
    for (uint32_t m : baked) nodes_of_mesh[scene.meshes[m].origin.mesh].insert(scene.meshes[m].origin.node);
    bool instanced = false;
    for (const auto& [mesh, nodes] : nodes_of_mesh) instanced = instanced || nodes.size() > 1;
    if (instanced) {
      reasons.push_back("a mesh is placed by several nodes, and each instance needs its own texels");
    } else {
      for (int set : {1, 0})
        if (try_set(set, [&](const rc::scene::TriangleMesh& mesh) { return gltf_uvs(model, mesh, set); }))
          break;
    }
  } else {  // OBJ and PLY: one set, v counted up from the bottom
    try_set(0, [](const rc::scene::TriangleMesh& mesh) {
      std::vector<Vec2> uv;
      for (const Vec2& t : mesh.uvs) uv.emplace_back(t.x, 1.0f - t.y);
      return uv;
    });
  }
  if (out.set >= 0) {
    out.why = ext == ".gltf" || ext == ".glb" ? "the input's TEXCOORD_" + std::to_string(out.set)
                                              : std::string("the input's UVs");
  } else {
    out.why = "laid out by gilt (the input's UVs cannot hold it:";
    for (const std::string& r : reasons) out.why += " " + r + ";";
    if (reasons.empty()) out.why += " it has none;";
    out.why.back() = ')';
  }
  return out;
}

/// gilt's own charts over the baked meshes, packed into a size × size atlas at the highest
/// density that fits (returned in `density`, texels per scene unit). Throws InputError when the
/// charts do not fit even at one texel each.
std::vector<Chart> lay_out_charts(const rc::scene::Scene& scene, const std::vector<uint32_t>& baked_meshes,
                                  int size, double& density) {
  std::vector<Chart> charts;
  for (uint32_t m : baked_meshes) grow_charts(scene.meshes[m], m, charts);
  rc::util::parallel_for(charts.size(), [&](size_t c) { fit_rectangle(charts[c]); });
  std::stable_sort(charts.begin(), charts.end(), [](const Chart& a, const Chart& b) { return a.extent.y > b.extent.y; });
  double chart_area = 0.0;
  for (const Chart& c : charts) chart_area += double(c.extent.x) * double(c.extent.y);
  // The densest layout that packs: bisection between one that fits and one that does not.
  // The sparsest layout gives every chart one texel (and its border); at density 0 the charts
  // would fit as points, with no texel inside any face: an atlas of nothing.
  const auto top_density = [&](int atlas) { return double(atlas) / std::sqrt(std::max(chart_area, 1e-30)); };
  double lo = 1e-9 * top_density(size), hi = top_density(size);
  if (!pack(charts, size, lo)) {
    int enough = size;
    while (enough < 16384 && !pack(charts, enough, 1e-9 * top_density(enough))) enough *= 2;
    throw InputError("--lightmap " + std::to_string(size) + ": " + std::to_string(charts.size()) +
                     " charts do not fit in the atlas even at one texel each: give a larger size" +
                     (enough > size && enough <= 16384 ? " (" + std::to_string(enough) + " holds them)" : std::string()));
  }
  for (int i = 0; i < 40 && hi > lo * (1.0 + 1e-4); ++i) {
    const double mid = 0.5 * (lo + hi);
    (pack(charts, size, mid) ? lo : hi) = mid;
  }
  pack(charts, size, lo);
  density = lo;
  return charts;
}

/// The meshes of the scene's model file that a lightmap bakes: all but mirrors and glass.
std::vector<uint32_t> lightmap_meshes(const rc::scene::Scene& scene) {
  const int32_t file = onto_input_file(scene);
  std::vector<uint32_t> baked;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.meshes[m].origin.file == file && !scene.materials[scene.meshes[m].material].is_traced_through())
      baked.push_back(m);
  if (baked.empty()) throw InputError("--lightmap: " + scene.name + " has no faces to bake (all are mirrors or glass)");
  return baked;
}

}  // namespace

Rgb Lightmap::at(size_t mesh, size_t face, float u, float v) const {
  const Vec2* c = &corner_uv[mesh][3 * face];
  const Vec2 uv = c[0] * (1.0f - u - v) + c[1] * u + c[2] * v;
  const float x = uv.x * float(size) - 0.5f, y = uv.y * float(size) - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - float(x0), fy = y - float(y0);
  const auto texel = [&](int tx, int ty) {
    tx = std::clamp(tx, 0, size - 1), ty = std::clamp(ty, 0, size - 1);
    return image.pixels[size_t(ty) * size_t(size) + size_t(tx)];
  };
  return (texel(x0, y0) * (1.0f - fx) + texel(x0 + 1, y0) * fx) * (1.0f - fy) +
         (texel(x0, y0 + 1) * (1.0f - fx) + texel(x0 + 1, y0 + 1) * fx) * fy;
}

void check_lightmap_layout(const rc::scene::Scene& scene, int size) {
  if (size < 16 || size > 16384)
    throw InputError("--lightmap " + std::to_string(size) + ": the atlas's size must be 16 to 16384 texels");
  const std::vector<uint32_t> baked = lightmap_meshes(scene);
  if (input_uv_set(scene, baked, size).set >= 0) return;
  double density = 0.0;
  lay_out_charts(scene, baked, size, density);
}

namespace {

/// Groups of faces that own disjoint texels, rasterised in parallel: charts; or, with the input's
/// UVs, whose charts gilt did not place, all faces in one group (`one_group`).
struct LightmapLayout {
  std::vector<std::pair<uint32_t, std::vector<uint32_t>>> groups;  ///< (mesh, its faces)
  std::vector<std::vector<char>> buried;                           ///< per mesh and face
  bool one_group = false;
};

/// Which face a texel shows (UINT32_MAX: none), and how far its centre is from it in texels.
struct TexelOwner {
  uint32_t mesh = UINT32_MAX, face = 0;
  float distance = rc::kInfinity;
};

/// Reads the scene; writes out.corner_uv and the layout's statistics: the input's own UV set where
/// it can hold a lightmap, else charts of gilt's own. Returns the groups and the buried faces.
LightmapLayout lay_out_lightmap(const rc::scene::Scene& scene, int size, Lightmap& out) {
  LightmapLayout layout;
  const std::vector<uint32_t> baked_meshes = lightmap_meshes(scene);
  layout.buried.resize(scene.meshes.size());
  for (uint32_t m : baked_meshes) {
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    out.stats.faces += mesh.triangle_count();
    layout.buried[m] = input_faces_buried(scene, mesh.positions, mesh.indices);
    for (char b : layout.buried[m]) out.stats.buried_faces += size_t(b);
  }
  const InputUvs input = input_uv_set(scene, baked_meshes, size);
  out.stats.uv_set = input.set;
  out.stats.uv_source = input.why;
  layout.one_group = input.set >= 0;
  if (input.set >= 0) {
    for (uint32_t m : baked_meshes) {
      out.corner_uv[m] = input.corner_uv[m];
      std::vector<uint32_t> faces(scene.meshes[m].triangle_count());
      for (uint32_t f = 0; f < faces.size(); ++f) faces[f] = f;
      layout.groups.emplace_back(m, std::move(faces));
    }
    return layout;
  }
  double lo = 0.0;
  const std::vector<Chart> charts = lay_out_charts(scene, baked_meshes, size, lo);
  out.stats.charts = charts.size();
  out.stats.texels_per_metre = lo;
  for (const Chart& c : charts) {
    std::vector<Vec2>& uv = out.corner_uv[c.mesh];
    uv.resize(3 * scene.meshes[c.mesh].triangle_count(), Vec2(0.0f));
    for (size_t i = 0; i < c.faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const Vec2 texel = Vec2(float(c.x + double(c.corner[3 * i + size_t(k)].x) * lo + 0.5),
                                float(c.y + double(c.corner[3 * i + size_t(k)].y) * lo + 0.5));
        uv[3 * size_t(c.faces[i]) + size_t(k)] = texel / float(size);
      }
    layout.groups.emplace_back(c.mesh, c.faces);
  }
  return layout;
}

/// Reads the layout and out.corner_uv; returns which face each texel shows: the nearest to its
/// centre, within 1.5 texels. gilt's charts own disjoint cells of the atlas, so they are
/// rasterised in parallel; the input's UVs in one go.
std::vector<TexelOwner> rasterise_owners(const LightmapLayout& layout, const Lightmap& out) {
  constexpr float kReach = 1.5f;
  const int size = out.size;
  std::vector<TexelOwner> owner(size_t(size) * size_t(size));
  const auto rasterise = [&](size_t gi) {
    const uint32_t mesh_index = layout.groups[gi].first;
    const std::vector<Vec2>& uv = out.corner_uv[mesh_index];
    for (const uint32_t f : layout.groups[gi].second) {
      if (layout.buried[mesh_index][f]) continue;
      const Vec2 t[3] = {uv[3 * f] * float(size), uv[3 * f + 1] * float(size), uv[3 * f + 2] * float(size)};
      if (!(std::abs((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x)) > 0.0f)) continue;
      const Vec2 lo_t = glm::min(t[0], glm::min(t[1], t[2])) - kReach, hi_t = glm::max(t[0], glm::max(t[1], t[2])) + kReach;
      const int x0 = std::max(0, int(std::floor(lo_t.x))), x1 = std::min(size - 1, int(std::floor(hi_t.x)));
      const int y0 = std::max(0, int(std::floor(lo_t.y))), y1 = std::min(size - 1, int(std::floor(hi_t.y)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const Vec2 centre(float(x) + 0.5f, float(y) + 0.5f);
          const Vec2 b = closest_barycentric(t, centre);
          const float d = glm::length(t[0] * (1.0f - b.x - b.y) + t[1] * b.x + t[2] * b.y - centre);
          TexelOwner& o = owner[size_t(y) * size_t(size) + size_t(x)];
          if (d <= kReach && d < o.distance) o = {mesh_index, f, d};
        }
    }
  };
  if (layout.one_group) {
    for (size_t g = 0; g < layout.groups.size(); ++g) rasterise(g);
  } else {
    rc::util::parallel_for(layout.groups.size(), rasterise);
  }
  return owner;
}

/// Reads the owners and out.corner_uv; writes out.image: each owned texel the mean of the solution
/// at four points of its footprint, clamped onto its face. Returns which texels were filled.
/// `report`: show the rows filled on stderr.
std::vector<char> fill_texels(const rc::scene::Scene& scene, const SolutionAtInput& at_input,
                              const std::vector<TexelOwner>& owner, Lightmap& out, bool report) {
  const int size = out.size;
  std::vector<char> filled(owner.size(), 0);
  rc::util::Progress progress("bake: lightmap", size_t(size), "rows", report);
  rc::util::parallel_for(size_t(size), [&](size_t y) {
    progress.advance(1);
    for (size_t x = 0; x < size_t(size); ++x) {
      const TexelOwner& o = owner[y * size_t(size) + x];
      if (o.mesh == UINT32_MAX) continue;
      const rc::scene::TriangleMesh& mesh = scene.meshes[o.mesh];
      const std::vector<Vec2>& uv = out.corner_uv[o.mesh];
      const Vec2 t[3] = {uv[3 * o.face] * float(size), uv[3 * o.face + 1] * float(size), uv[3 * o.face + 2] * float(size)};
      const Vec3 &p0 = mesh.positions[mesh.indices[3 * o.face]], &p1 = mesh.positions[mesh.indices[3 * o.face + 1]],
                 &p2 = mesh.positions[mesh.indices[3 * o.face + 2]];
      const Vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      const rc::scene::Material& material = scene.materials[mesh.material];
      Rgb sum(0.0f);
      int count = 0;
      for (int s = 0; s < 4; ++s) {
        const Vec2 point(float(x) + 0.25f + 0.5f * float(s & 1), float(y) + 0.25f + 0.5f * float(s >> 1));
        const Vec2 b = closest_barycentric(t, point);
        const std::optional<Rgb> v = at_input(material, p0 * (1.0f - b.x - b.y) + p1 * b.x + p2 * b.y, n);
        if (v) sum += *v, ++count;
      }
      if (count == 0) continue;
      out.image.pixels[y * size_t(size) + x] = sum / float(count);
      filled[y * size_t(size) + x] = 1;
    }
  });
  return filled;
}

/// Reads and writes out.image and `filled`: kLightmapPad rounds of filling empty texels with their
/// filled neighbours' mean, the border that keeps filtering from reading black.
void pad_border(std::vector<char>& filled, Lightmap& out) {
  const int size = out.size;
  for (int round = 0; round < kLightmapPad; ++round) {
    std::vector<char> next = filled;
    std::vector<Rgb> pixels = out.image.pixels;
    rc::util::parallel_for(size_t(size), [&](size_t y) {
      for (size_t x = 0; x < size_t(size); ++x) {
        if (filled[y * size_t(size) + x]) continue;
        Rgb sum(0.0f);
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const long nx = long(x) + dx, ny = long(y) + dy;
            if (nx < 0 || ny < 0 || nx >= size || ny >= size || !filled[size_t(ny) * size_t(size) + size_t(nx)]) continue;
            sum += out.image.pixels[size_t(ny) * size_t(size) + size_t(nx)];
            ++count;
          }
        if (count == 0) continue;
        pixels[y * size_t(size) + x] = sum / float(count);
        next[y * size_t(size) + x] = 1;
      }
    });
    filled = std::move(next);
    out.image.pixels = std::move(pixels);
  }
}

}  // namespace

Lightmap bake_lightmap(const rc::scene::Scene& scene, const Solution& solution, Quantity quantity, int size,
                       BakeGather gather) {
  if (size < 16 || size > 16384)
    throw InputError("--lightmap " + std::to_string(size) + ": the atlas's size must be 16 to 16384 texels");
  auto start = std::chrono::steady_clock::now();
  Lightmap out;
  out.size = size;
  out.file = onto_input_file(scene);
  out.corner_uv.resize(scene.meshes.size());
  const LightmapLayout layout = lay_out_lightmap(scene, size, out);
  out.stats.layout_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();

  const std::vector<TexelOwner> owner = rasterise_owners(layout, out);
  const SolutionAtInput at_input(scene, solution, quantity, gather);
  out.image.width = out.image.height = size;
  out.image.pixels.assign(owner.size(), Rgb(0.0f));
  std::vector<char> filled = fill_texels(scene, at_input, owner, out, gather.progress);
  for (char f : filled) out.stats.texels += size_t(f);
  pad_border(filled, out);
  out.stats.gather = at_input.gather_count();
  out.stats.sides = at_input.sides_count();
  out.stats.bake_seconds = seconds_since(start);
  return out;
}

std::string lightmap_image_path(const std::string& model_output) {
  const std::filesystem::path p(model_output);
  return (p.parent_path() / (p.stem().string() + "_lightmap.exr")).string();
}

}  // namespace gilt::radiosity::bake
