// The radiosity mesher: element count and edge length against what was asked, area and normals
// against the input surfaces, triangle quality, conformity (no T-junctions within a surface),
// vertex splitting at creases, and the repair of a broken polygon soup. Measured figures are
// printed and recorded as test properties (--gtest_output=xml).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/test_scenes.h"

namespace gilt::radiosity {
using namespace mesh;
namespace {

using rc::DVec3;
using rc::scene::Material;
using rc::Rgb;
using rc::scene::Scene;
using rc::scene::TriangleMesh;

constexpr double kPi = 3.14159265358979323846;

void note(const std::string& key, const std::string& value) {
  std::printf("[ measured ] %s: %s\n", key.c_str(), value.c_str());
  testing::Test::RecordProperty(key, value);
}

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, format, a, b, c, d);
  return text;
}

Scene committed_builtin(const std::string& name) {
  Scene scene = rc::io::builtin_scene(name);
  scene.commit();
  return scene;
}

/// Exact position key: vertices split at a crease keep bit-identical copies of one position.
using PointKey = std::array<float, 3>;
PointKey key_of(const Vec3& p) { return {p.x, p.y, p.z}; }

DVec3 d(const Vec3& v) { return DVec3(v); }

double min_angle_degrees(const DVec3& a, const DVec3& b, const DVec3& c) {
  const auto angle = [](const DVec3& p, const DVec3& q, const DVec3& r) {
    return std::acos(std::clamp(glm::dot(glm::normalize(q - p), glm::normalize(r - p)), -1.0, 1.0));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)}) * 180.0 / kPi;
}

/// Ratio of circumradius to twice the inradius: 1 for an equilateral triangle, larger otherwise.
double radius_ratio(const DVec3& a, const DVec3& b, const DVec3& c) {
  const double la = glm::length(b - c), lb = glm::length(c - a), lc = glm::length(a - b);
  const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
  const double circumradius = la * lb * lc / (4.0 * area);
  const double inradius = 2.0 * area / (la + lb + lc);
  return circumradius / (2.0 * inradius);
}

double percentile(std::vector<double> values, double fraction) {
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(fraction * double(values.size() - 1))];
}

double input_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const DVec3 a = d(mesh.positions[mesh.indices[3 * t]]), b = d(mesh.positions[mesh.indices[3 * t + 1]]),
                c = d(mesh.positions[mesh.indices[3 * t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

/// Area of the triangles of the mesh that lie in its highest horizontal plane (a block's top).
double top_face_area(const TriangleMesh& mesh) {
  float top = -std::numeric_limits<float>::infinity();
  for (const Vec3& p : mesh.positions) top = std::max(top, p.y);
  double area = 0.0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 &a = mesh.positions[mesh.indices[3 * t]], &b = mesh.positions[mesh.indices[3 * t + 1]],
               &c = mesh.positions[mesh.indices[3 * t + 2]];
    if (a.y == top && b.y == top && c.y == top) area += 0.5 * glm::length(glm::cross(d(b - a), d(c - a)));
  }
  return area;
}

/// Segments of the input mesh's boundary: edges (by position) used by exactly one triangle.
std::vector<std::array<DVec3, 2>> input_boundary(const TriangleMesh& mesh) {
  std::map<std::pair<PointKey, PointKey>, int> uses;
  for (size_t t = 0; t < mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      PointKey a = key_of(mesh.positions[mesh.indices[3 * t + k]]);
      PointKey b = key_of(mesh.positions[mesh.indices[3 * t + (k + 1) % 3]]);
      if (b < a) std::swap(a, b);
      ++uses[{a, b}];
    }
  std::vector<std::array<DVec3, 2>> boundary;
  for (const auto& [edge, count] : uses)
    if (count == 1)
      boundary.push_back({DVec3(edge.first[0], edge.first[1], edge.first[2]),
                          DVec3(edge.second[0], edge.second[1], edge.second[2])});
  return boundary;
}

/// Distance from p to segment ab, and the parameter of the closest point.
std::pair<double, double> segment_distance(const DVec3& p, const DVec3& a, const DVec3& b) {
  const DVec3 ab = b - a;
  const double s = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return {glm::length(p - (a + s * ab)), s};
}

/// Conformity of one surface of the mesh. An edge (by position, so copies of a vertex split at
/// a crease count as one point) must be used by two elements in opposite directions, or by one
/// element and lie on the input surface's boundary; no vertex may lie inside another edge.
struct Conformity {
  size_t interior_edges = 0, boundary_edges = 0;
  size_t bad_edges = 0;    ///< used more than twice, twice in one direction, or once off the boundary
  size_t t_junctions = 0;  ///< vertices strictly inside an edge of the same surface
};

Conformity check_conformity(const RadiosityMesh& mesh, uint32_t surface,
                            const std::vector<std::array<DVec3, 2>>& boundary, double edge_length) {
  // Tolerance for "lies on": rounding of float positions of O(10³) scene units is ~1e-4; the
  // elements are 10⁵ times larger than that, so 1e-5·L separates "on" from "off" by a wide margin.
  const double tolerance = 1e-5 * edge_length;
  std::map<std::pair<PointKey, PointKey>, std::pair<int, int>> directed;  // (forward, backward) uses
  std::set<PointKey> points;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    if (mesh.element_surface[e] != surface) continue;
    for (int k = 0; k < 3; ++k) {
      const PointKey a = key_of(mesh.positions[mesh.elements[e][k]]);
      const PointKey b = key_of(mesh.positions[mesh.elements[e][(k + 1) % 3]]);
      points.insert(a);
      if (a < b)
        ++directed[{a, b}].first;
      else
        ++directed[{b, a}].second;
    }
  }
  const auto point = [](const PointKey& k) { return DVec3(k[0], k[1], k[2]); };
  Conformity result;
  for (const auto& [edge, uses] : directed) {
    const DVec3 a = point(edge.first), b = point(edge.second);
    if (uses.first == 1 && uses.second == 1) {
      ++result.interior_edges;
    } else if (uses.first + uses.second == 1) {
      ++result.boundary_edges;
      const bool on_boundary = std::any_of(boundary.begin(), boundary.end(), [&](const auto& segment) {
        return segment_distance(a, segment[0], segment[1]).first < tolerance &&
               segment_distance(b, segment[0], segment[1]).first < tolerance;
      });
      if (!on_boundary) ++result.bad_edges;
    } else {
      ++result.bad_edges;
    }
    for (const PointKey& k : points) {
      if (k == edge.first || k == edge.second) continue;
      const auto [distance, s] = segment_distance(point(k), a, b);
      if (distance < tolerance && s > 0.0 && s < 1.0) ++result.t_junctions;
    }
  }
  return result;
}

/// Distance from p to triangle abc with unit normal n.
double triangle_distance(const DVec3& p, const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& n) {
  const double height = glm::dot(p - a, n);
  const DVec3 q = p - height * n;  // p projected onto the plane
  if (glm::dot(glm::cross(b - a, q - a), n) >= 0.0 && glm::dot(glm::cross(c - b, q - b), n) >= 0.0 &&
      glm::dot(glm::cross(a - c, q - c), n) >= 0.0)
    return std::abs(height);
  return std::min(
      {segment_distance(p, a, b).first, segment_distance(p, b, c).first, segment_distance(p, c, a).first});
}

/// Unit normal of the input triangle of `mesh` closest to `p`, and the distance to it.
std::pair<DVec3, double> source_face(const TriangleMesh& mesh, const DVec3& p) {
  std::pair<DVec3, double> best{DVec3(0.0), INFINITY};
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const DVec3 a = d(mesh.positions[mesh.indices[3 * t]]), b = d(mesh.positions[mesh.indices[3 * t + 1]]),
                c = d(mesh.positions[mesh.indices[3 * t + 2]]);
    const DVec3 n = glm::normalize(glm::cross(b - a, c - a));
    const double distance = triangle_distance(p, a, b, c, n);
    if (distance < best.second) best = {n, distance};
  }
  return best;
}

/// Mean length of the elements' edges, each element edge counted once per element.
double mean_edge_length(const RadiosityMesh& mesh) {
  double sum = 0.0;
  for (const auto& e : mesh.elements)
    for (int k = 0; k < 3; ++k)
      sum += glm::distance(d(mesh.positions[e[k]]), d(mesh.positions[e[(k + 1) % 3]]));
  return sum / double(3 * mesh.element_count());
}

// ------------------------------------------------------------------------------------------------

TEST(Mesh, CornellBoxAtTheDefault) {
  const Scene scene = committed_builtin("cornell");
  MeshReport report;
  const auto start = std::chrono::steady_clock::now();
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{}, &report);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  note("cornell_seconds", fmt("%.3f", seconds));
  note("cornell_elements", fmt("%.0f elements, %.0f vertices, L = %.3f", double(mesh.element_count()),
                               double(mesh.vertex_count()), report.max_edge));

  // Array sizes agree.
  ASSERT_EQ(mesh.normals.size(), mesh.vertex_count());
  ASSERT_EQ(mesh.vertex_material.size(), mesh.vertex_count());
  ASSERT_EQ(mesh.element_material.size(), mesh.element_count());
  ASSERT_EQ(mesh.element_surface.size(), mesh.element_count());
  ASSERT_EQ(mesh.element_normal.size(), mesh.element_count());
  ASSERT_EQ(mesh.element_area.size(), mesh.element_count());

  // Count: L comes from the count through the area of an equilateral triangle, but remeshed
  // triangles are not all equilateral, edges spread over [4/5, 4/3] of the remesher's target and
  // protected edges are cut into whole pieces, so the count is not exact. The mesher calibrates
  // its target so the count lands within a few per cent (measured: 0.95–1.01 of the request on
  // the Cornell box from 1000 to 20000 elements); ±25 % is the bound it promises users, wide
  // enough for scenes whose many short protected edges force extra elements.
  const double requested = kDefaultElements;
  EXPECT_NEAR(double(mesh.element_count()), requested, 0.25 * requested);

  // Area per surface: remeshing moves vertices only within the input's planes, so the area is kept
  // up to rounding (float positions, ~1e-7 relative per element, accumulating over ~10³ elements
  // to ~1e-5 at worst). The one exception, elements straddling the red wall's 0.47° fold (see
  // below), differ from the input by O(θ²) ≈ 7e-5 of their own area, a few per cent of the wall's
  // elements: far below the bound. Hence 1e-4 relative.
  // The floor under the blocks is buried and removed: the blocks are vertical prisms standing on
  // it, so what is removed is the area of their top faces.
  double footprints = 0.0;
  for (const TriangleMesh& m : scene.meshes)
    if (m.name.find("block") != std::string::npos) footprints += top_face_area(m);
  EXPECT_GT(report.buried_faces, 0u);
  EXPECT_GT(report.contact_edges, 0u);
  double total_in = 0.0, total_out = 0.0;
  for (size_t s = 0; s < scene.meshes.size(); ++s) {
    double out = 0.0;
    for (size_t e = 0; e < mesh.element_count(); ++e)
      if (mesh.element_surface[e] == s) out += mesh.element_area[e];
    const double in = input_area(scene.meshes[s]) - (scene.meshes[s].name == "floor" ? footprints : 0.0);
    total_in += in;
    total_out += out;
    EXPECT_NEAR(out, in, 1e-4 * in) << scene.meshes[s].name;
  }
  EXPECT_NEAR(total_out, total_in, 1e-4 * total_in);
  note("cornell_area", fmt("input %.6g, mesh %.6g, relative difference %.2e", total_in, total_out,
                           std::abs(total_out - total_in) / total_in));

  // Each element faces the way its source face does (the input triangle nearest its centroid),
  // and its vertices' normals agree. The red wall is a slightly warped quad (its corners are not
  // coplanar in the measured data): its two triangles meet at 0.47°, far below the crease angle,
  // so elements straddle the fold. 0.999 = cos 2.6° covers that fold; a flipped or misplaced
  // element is off by far more. An element lies within the fold's sagitta of its source
  // (~L·tan(0.47°)/4 ≈ 0.002 L), well inside 1 % of L.
  size_t far_from_source = 0, misaligned = 0, bad_vertex_normals = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const DVec3 centroid =
        (d(mesh.positions[el[0]]) + d(mesh.positions[el[1]]) + d(mesh.positions[el[2]])) / 3.0;
    const TriangleMesh& input = scene.meshes[mesh.element_surface[e]];
    EXPECT_EQ(mesh.element_material[e], input.material);
    const auto [normal, distance] = source_face(input, centroid);
    if (distance > 0.01 * report.max_edge) ++far_from_source;
    if (glm::dot(d(mesh.element_normal[e]), normal) <= 0.999) ++misaligned;
    for (uint32_t v : el) {
      if (glm::dot(d(mesh.normals[v]), d(mesh.element_normal[e])) <= 0.999) ++bad_vertex_normals;
      EXPECT_EQ(mesh.vertex_material[v], input.material);
    }
    // Counter-clockwise seen from the front: the stored normal is the winding's normal.
    const DVec3 winding = glm::cross(d(mesh.positions[el[1]] - mesh.positions[el[0]]),
                                     d(mesh.positions[el[2]] - mesh.positions[el[0]]));
    EXPECT_GT(glm::dot(winding, d(mesh.element_normal[e])), 0.0);
  }
  EXPECT_EQ(far_from_source, 0u);
  EXPECT_EQ(misaligned, 0u);
  EXPECT_EQ(bad_vertex_normals, 0u);
  // The walls face into the box.
  const Vec3 inside(278.0f, 274.4f, 279.6f);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const std::string& name = scene.meshes[mesh.element_surface[e]].name;
    if (name.find("block") != std::string::npos) continue;
    const Vec3 p = mesh.positions[mesh.elements[e][0]];
    ASSERT_GT(glm::dot(mesh.element_normal[e], inside - p), 0.0f) << name;
  }

  // Triangle quality. Isotropic remeshing gives mostly near-equilateral triangles; the worst ones
  // sit at corners of protected borders, where the remesher may not move vertices. Bounds: 95 % of
  // the elements above 25° (an equilateral triangle has 60°, a right isosceles one 45°; measured
  // 99.7 %) and no sliver below 10° (measured smallest 17.5°: the bound catches a broken remesh,
  // not a move of a few degrees in one corner). The figures are printed so a change shows.
  std::vector<double> min_angles, ratios;
  for (const auto& el : mesh.elements) {
    const DVec3 a = d(mesh.positions[el[0]]), b = d(mesh.positions[el[1]]), c = d(mesh.positions[el[2]]);
    min_angles.push_back(min_angle_degrees(a, b, c));
    ratios.push_back(radius_ratio(a, b, c));
  }
  const double above25 =
      double(std::count_if(min_angles.begin(), min_angles.end(), [](double a) { return a > 25.0; })) /
      double(min_angles.size());
  note("cornell_min_angle",
       fmt("smallest %.2f deg, 5th percentile %.2f deg, median %.2f deg, %.4f above 25 deg",
           percentile(min_angles, 0.0), percentile(min_angles, 0.05), percentile(min_angles, 0.5), above25));
  note("cornell_radius_ratio", fmt("median %.4f, 95th percentile %.4f, largest %.4f", percentile(ratios, 0.5),
                                   percentile(ratios, 0.95), percentile(ratios, 1.0)));
  EXPECT_GT(above25, 0.95);
  EXPECT_GT(percentile(min_angles, 0.0), 10.0);

  // Conformity within each surface. The blocks' outlines on the floor are part of its boundary now.
  std::vector<std::array<DVec3, 2>> outlines;
  for (const TriangleMesh& m : scene.meshes)
    if (m.name.find("block") != std::string::npos)
      for (const auto& segment : input_boundary(m))
        if (segment[0].y == 0.0 && segment[1].y == 0.0) outlines.push_back(segment);
  EXPECT_EQ(outlines.size(), 8u);
  for (size_t s = 0; s < scene.meshes.size(); ++s) {
    std::vector<std::array<DVec3, 2>> boundary = input_boundary(scene.meshes[s]);
    if (scene.meshes[s].name == "floor") boundary.insert(boundary.end(), outlines.begin(), outlines.end());
    const Conformity c = check_conformity(mesh, uint32_t(s), boundary, report.max_edge);
    EXPECT_GT(c.interior_edges, 0u) << scene.meshes[s].name;
    EXPECT_EQ(c.bad_edges, 0u) << scene.meshes[s].name;
    EXPECT_EQ(c.t_junctions, 0u) << scene.meshes[s].name;
  }

  // The light fills a hole in the ceiling: both outlines are cut at bit-identical points, so the
  // two surfaces meet without cracks (each light border vertex is also a ceiling vertex).
  std::set<PointKey> ceiling_points;
  size_t light_border_points = 0, unmatched = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e)
    if (scene.meshes[mesh.element_surface[e]].name == "ceiling")
      for (uint32_t v : mesh.elements[e]) ceiling_points.insert(key_of(mesh.positions[v]));
  uint32_t light = 0;
  while (light < scene.meshes.size() && scene.meshes[light].name != "light") ++light;
  ASSERT_LT(light, scene.meshes.size());
  const auto light_outline = input_boundary(scene.meshes[light]);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    if (mesh.element_surface[e] != light) continue;
    for (uint32_t v : mesh.elements[e]) {
      const DVec3 p = d(mesh.positions[v]);
      const bool on_outline =
          std::any_of(light_outline.begin(), light_outline.end(), [&](const auto& segment) {
            return segment_distance(p, segment[0], segment[1]).first < 1e-5 * report.max_edge;
          });
      if (!on_outline) continue;
      ++light_border_points;
      if (!ceiling_points.count(key_of(mesh.positions[v]))) ++unmatched;
    }
  }
  EXPECT_GT(light_border_points, 0u);
  EXPECT_EQ(unmatched, 0u);

  for (const std::string& w : report.warnings) note("cornell_warning", w);
  // Repairs on the Cornell box: only the merging of the quads' separate corners (the ceiling's
  // four trapezoids and the blocks' five faces come with their own vertices).
  EXPECT_EQ(report.removed_degenerate, 0u);
  EXPECT_EQ(report.reoriented, 0u);
  EXPECT_EQ(report.self_intersecting, 0u);
}

TEST(Mesh, MirrorsAndGlassAreLeftToRayTracing) {
  const Scene scene = committed_builtin("cornell-caustics");
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.elements = 2000});
  std::set<uint32_t> surfaces(mesh.element_surface.begin(), mesh.element_surface.end());
  for (size_t s = 0; s < scene.spheres.size(); ++s)
    EXPECT_FALSE(surfaces.count(uint32_t(scene.meshes.size() + s))) << "sphere " << s;
  // Every mesh is diffuse, the emitter included.
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    EXPECT_TRUE(surfaces.count(uint32_t(m))) << scene.meshes[m].name;

  // Glossy surfaces are meshed (their diffuse part), mirrors are not.
  Scene mixed;
  mixed.materials = {Material::make_glossy("glossy", Rgb(0.5f), Rgb(0.2f), 20.0f),
                     Material::make_mirror("mirror")};
  mixed.spheres = {{Vec3(0.0f), 1.0f, 0}, {Vec3(3.0f, 0.0f, 0.0f), 1.0f, 1}};
  mixed.commit();
  const RadiosityMesh glossy = build_mesh(mixed, MeshSettings{.max_edge = 0.3f});
  ASSERT_GT(glossy.element_count(), 0u);
  for (uint32_t s : glossy.element_surface) EXPECT_EQ(s, 0u);
}

/// A unit cube of one material, outward-facing (or inward with `inward`), as 8 shared vertices.
TriangleMesh cube(bool inward) {
  TriangleMesh mesh;
  mesh.name = "cube";
  for (int i = 0; i < 8; ++i)
    mesh.positions.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
  // Each face as a quad, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    std::array<uint32_t, 6> tris = {uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2]),
                                    uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])};
    if (inward) {
      std::swap(tris[1], tris[2]);
      std::swap(tris[4], tris[5]);
    }
    mesh.indices.insert(mesh.indices.end(), tris.begin(), tris.end());
  }
  return mesh;
}

Scene single_mesh_scene(TriangleMesh mesh) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  scene.meshes.push_back(std::move(mesh));
  return scene;
}

TEST(Mesh, SharpEdgesSplitVertices) {
  for (bool inward : {false, true}) {
    Scene scene = single_mesh_scene(cube(inward));
    scene.commit();
    MeshReport report;
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.25f}, &report);
    ASSERT_GT(mesh.element_count(), 12u);
    EXPECT_EQ(report.reoriented, 0u);

    // Every element keeps the input's side: outward normals point away from the centre.
    const DVec3 center(0.5);
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const double outward =
          glm::dot(d(mesh.element_normal[e]), d(mesh.positions[mesh.elements[e][0]]) - center);
      EXPECT_GT(inward ? -outward : outward, 0.0);
    }
    // No vertex spans two faces: all elements around a vertex share its normal, the face's.
    for (size_t e = 0; e < mesh.element_count(); ++e)
      for (uint32_t v : mesh.elements[e])
        ASSERT_GT(glm::dot(mesh.normals[v], mesh.element_normal[e]), 0.9999f);
    // A cube corner is one vertex per face (3), a point on a cube edge one per face (2).
    std::map<PointKey, int> copies;
    for (const Vec3& p : mesh.positions) ++copies[key_of(p)];
    for (const auto& [p, n] : copies) {
      const int on_faces = int(p[0] == 0.0f || p[0] == 1.0f) + int(p[1] == 0.0f || p[1] == 1.0f) +
                           int(p[2] == 0.0f || p[2] == 1.0f);
      EXPECT_EQ(n, on_faces);
    }
  }
}

/// Closed surface of genus 0: V − E + F = 2 with E = 3F/2, so V = F/2 + 2 when every vertex is
/// shared by all its elements. Vertices lie at distances [inner, outer] from the centre.
void expect_shared_closed_surface(const RadiosityMesh& mesh, const DVec3& center, double inner,
                                  double outer) {
  EXPECT_EQ(mesh.vertex_count(), mesh.element_count() / 2 + 2);
  std::set<PointKey> distinct;
  for (const Vec3& p : mesh.positions) distinct.insert(key_of(p));
  EXPECT_EQ(distinct.size(), mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const DVec3 radial = glm::normalize(d(mesh.positions[v]) - center);
    // 0.99 = cos 8°: the normal of a polyhedral sphere whose edges subtend ~L/r = 0.1–0.2 rad
    // differs from the radial direction by a fraction of that angle.
    EXPECT_GT(glm::dot(d(mesh.normals[v]), radial), 0.99);
    const double r = glm::length(d(mesh.positions[v]) - center);
    EXPECT_GE(r, inner);
    EXPECT_LE(r, outer);
  }
  for (size_t e = 0; e < mesh.element_count(); ++e)
    EXPECT_GT(glm::dot(d(mesh.element_normal[e]), d(mesh.positions[mesh.elements[e][0]]) - center), 0.0);
}

TEST(Mesh, SmoothSurfacesKeepSharedVertices) {
  {  // An analytic sphere is tessellated.
    Scene scene;
    scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
    scene.spheres.push_back({Vec3(1.0f, 2.0f, 3.0f), 2.0f, 0});
    scene.commit();
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.2f});
    for (uint32_t s : mesh.element_surface) ASSERT_EQ(s, 0u);  // meshes.size() + sphere 0
    // On the sphere up to float rounding of coordinates ~3 (2⁻²² ≈ 2.4e-7 each): 1e-6 relative.
    expect_shared_closed_surface(mesh, DVec3(1.0, 2.0, 3.0), 2.0 * (1.0 - 1e-6), 2.0 * (1.0 + 1e-6));
    for (size_t v = 0; v < mesh.vertex_count(); ++v)  // radial normals, exactly
      EXPECT_GT(glm::dot(d(mesh.normals[v]), glm::normalize(d(mesh.positions[v]) - DVec3(1.0, 2.0, 3.0))),
                0.99999);
    // Edge length: ±20 %, as for meshes below.
    EXPECT_NEAR(mean_edge_length(mesh), 0.2, 0.2 * 0.2);
    note("sphere_mean_edge", fmt("%.4f for L = 0.2", mean_edge_length(mesh)));
  }
  {  // A finely tessellated sphere mesh is remeshed coarser; its dihedral angles stay ~10°.
    Scene scene = single_mesh_scene(gilt::test::icosphere(4));
    scene.commit();
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.15f});
    // The remesher keeps vertices on the input polyhedron, which lies between the unit sphere and
    // the nearest plane of its faces (plus float rounding, 1e-6).
    const TriangleMesh& input = scene.meshes[0];
    double nearest_plane = 1.0;
    for (size_t t = 0; t < input.triangle_count(); ++t) {
      const DVec3 a = d(input.positions[input.indices[3 * t]]),
                  b = d(input.positions[input.indices[3 * t + 1]]),
                  c = d(input.positions[input.indices[3 * t + 2]]);
      nearest_plane =
          std::min(nearest_plane, std::abs(glm::dot(a, glm::normalize(glm::cross(b - a, c - a)))));
    }
    expect_shared_closed_surface(mesh, DVec3(0.0), nearest_plane - 1e-6, 1.0 + 1e-6);
  }
}

/// A closed box with outward normals: its base is the rectangle of half sides (hx, hy) around
/// (cx, cy), turned by `turn` radians about z, spanning z0 to z1.
TriangleMesh closed_box(const std::string& name, double cx, double cy, double hx, double hy, double turn, float z0,
                        float z1) {
  TriangleMesh box;
  box.name = name;
  const double c = std::cos(turn), s = std::sin(turn);
  for (float z : {z0, z1})
    for (const auto& [x, y] : {std::pair{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}})
      box.positions.emplace_back(float(cx + c * x - s * y), float(cy + s * x + c * y), z);
  // Corners 0–3 below, 4–7 above, counter-clockwise seen from +z.
  box.indices = {0, 2, 1, 0, 3, 2,  4, 5, 6, 4, 6, 7,  0, 1, 5, 0, 5, 4,
                 1, 2, 6, 1, 6, 5,  2, 3, 7, 2, 7, 6,  3, 0, 4, 3, 4, 7};
  return box;
}

/// Whether (x, y) lies inside the turned rectangle of closed_box, shrunk by `margin`.
bool inside_footprint(double x, double y, double cx, double cy, double hx, double hy, double turn, double margin) {
  const double c = std::cos(turn), s = std::sin(turn);
  const double u = c * (x - cx) + s * (y - cy), v = -s * (x - cx) + c * (y - cy);
  return std::abs(u) < hx - margin && std::abs(v) < hy - margin;
}

// Where a solid stands on the floor or pierces it, the line of contact is imprinted on the floor
// and on the solid, and what lies inside the solid is removed: no element straddles the line, and
// no vertex on it is shared by the elements on its two sides (each side has its own copy), so
// Gouraud interpolation cannot smear the dark on one side over the lit other.
TEST(Mesh, ContactLinesAreImprintedAndBuriedElementsRemoved) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  TriangleMesh floor;
  floor.name = "floor";
  floor.positions = {Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0)};
  floor.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(floor);
  // Standing on the floor (its bottom face lies on it), sunk into it, and floating above it.
  struct Placed { double cx, cy, hx, hy, turn; float z0, z1; };
  const Placed standing{-0.9, -0.8, 0.45, 0.3, 0.5, 0.0f, 0.8f}, sunk{0.9, 0.7, 0.35, 0.35, -0.3, -0.25f, 0.6f},
      floating{0.9, -1.1, 0.3, 0.3, 0.2, 0.05f, 0.5f};
  for (const auto& [name, b] : {std::pair{"standing", standing}, {"sunk", sunk}, {"floating", floating}})
    scene.meshes.push_back(closed_box(name, b.cx, b.cy, b.hx, b.hy, b.turn, b.z0, b.z1));
  scene.commit();
  MeshReport report;
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.2f}, &report);
  note("contact", fmt("%.0f contact edges imprinted, %.0f buried elements removed", double(report.contact_edges),
                      double(report.buried_faces)));
  EXPECT_GT(report.contact_edges, 0u);
  EXPECT_GT(report.buried_faces, 0u);

  // The floor loses exactly the two footprints (the floating box leaves it whole); float
  // coordinates of size ~1 round at ~1e-7, so 1e-5 relative is far above rounding and far
  // below an element's share (~1e-3).
  const double expected = 16.0 - 4.0 * standing.hx * standing.hy - 4.0 * sunk.hx * sunk.hy;
  double floor_area = 0.0;
  size_t straddling = 0;
  std::vector<char> used_above(mesh.vertex_count(), 0), used_below(mesh.vertex_count(), 0);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const DVec3 centroid = (d(mesh.positions[el[0]]) + d(mesh.positions[el[1]]) + d(mesh.positions[el[2]])) / 3.0;
    if (mesh.element_surface[e] == 0) {
      floor_area += mesh.element_area[e];
      // No floor element inside a footprint, not even partly: its centroid would be more than a
      // few per cent of an edge inside (0.005 against elements of 0.2).
      EXPECT_FALSE(inside_footprint(centroid.x, centroid.y, standing.cx, standing.cy, standing.hx, standing.hy,
                                    standing.turn, -0.005));
      EXPECT_FALSE(inside_footprint(centroid.x, centroid.y, sunk.cx, sunk.cy, sunk.hx, sunk.hy, sunk.turn, -0.005));
    }
    // The sunk box is cut where it crosses the floor: none of its elements has corners both
    // above and below z = 0.
    if (mesh.element_surface[e] == 2) {
      bool above = false, below = false;
      for (uint32_t v : el) above |= mesh.positions[v].z > 1e-6f, below |= mesh.positions[v].z < -1e-6f;
      straddling += above && below;
      for (uint32_t v : el) (centroid.z > 0.0 ? used_above : used_below)[v] = 1;
    }
  }
  EXPECT_NEAR(floor_area, expected, 1e-5 * expected);
  EXPECT_EQ(straddling, 0u);
  size_t shared = 0, on_line = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    shared += used_above[v] && used_below[v];
    on_line += (used_above[v] || used_below[v]) && std::abs(mesh.positions[v].z) < 1e-6f;
  }
  EXPECT_GT(on_line, 0u) << "the sunk box has vertices on the floor's line";
  EXPECT_EQ(shared, 0u) << "vertices on the line shared by the sunk box's elements above and below it";
}

// Pieces are remeshed patch by patch (the faces between sharp or contact edges) and welded back
// at the patches' borders: a floating box's six sides come back as one closed surface, every
// element edge shared by exactly two elements, with the box's area.
TEST(Mesh, BoxRemeshedSideBySideStaysClosed) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  scene.meshes.push_back(closed_box("box", 0.1, -0.2, 0.45, 0.3, 0.4, 0.05f, 0.8f));
  scene.commit();
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.1f});
  std::map<std::pair<PointKey, PointKey>, int> edges;
  double area = 0.0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    area += mesh.element_area[e];
    for (int i = 0; i < 3; ++i) {
      PointKey a = key_of(mesh.positions[el[i]]), b = key_of(mesh.positions[el[(i + 1) % 3]]);
      if (b < a) std::swap(a, b);
      ++edges[{a, b}];
    }
  }
  size_t not_two = 0;
  for (const auto& [edge, count] : edges) not_two += count != 2;
  note("closed box", fmt("%.0f elements, %.0f edges, %.0f not shared by two", double(mesh.element_count()),
                         double(edges.size()), double(not_two)));
  EXPECT_GT(mesh.element_count(), 100u) << "the sides were remeshed to the 0.1 edge";
  EXPECT_EQ(not_two, 0u);
  // Sides 0.9 x 0.6 x 0.75; float corners of size ~1 round at ~1e-7 relative.
  const double expected = 2.0 * (0.9 * 0.6 + 0.9 * 0.75 + 0.6 * 0.75);
  EXPECT_NEAR(area, expected, 1e-5 * expected);
}

// Under --time, meshing stops at its share of the budget: a deadline already past leaves every
// piece as it came (no contact searched, so the touching pieces are counted as not imprinted;
// none remeshed; no self-intersection counted; no face tested for burial), and says so.
TEST(Mesh, APassedDeadlineLeavesPiecesAsTheyCame) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  TriangleMesh floor;
  floor.name = "floor";
  floor.positions = {Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0)};
  floor.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(floor);
  scene.meshes.push_back(closed_box("standing", -0.9, -0.8, 0.45, 0.3, 0.5, 0.0f, 0.8f));
  scene.meshes.push_back(closed_box("floating", 0.9, -1.1, 0.3, 0.3, 0.2, 0.05f, 0.5f));
  scene.commit();
  size_t input_triangles = 0;
  for (const TriangleMesh& m : scene.meshes) input_triangles += m.indices.size() / 3;

  MeshReport in_time, late;
  build_mesh(scene, MeshSettings{.max_edge = 0.2f}, &in_time);
  EXPECT_GT(in_time.contact_edges, 0u);
  EXPECT_EQ(in_time.pieces_not_imprinted, 0u);
  EXPECT_EQ(in_time.pieces_not_remeshed, 0u);

  const RadiosityMesh mesh =
      build_mesh(scene, MeshSettings{.max_edge = 0.2f, .deadline = std::chrono::steady_clock::now()}, &late);
  // The floor and the standing box touch; the floating box touches nothing (its box meets no
  // other), so it has nothing to imprint. No piece is remeshed and none tested for burial: the
  // elements are the input's triangles.
  EXPECT_EQ(late.pieces_not_imprinted, 2u);
  EXPECT_EQ(late.contact_edges, 0u);
  EXPECT_EQ(late.pieces_not_remeshed, 3u);
  EXPECT_EQ(late.buried_faces + late.buried_elements, 0u);
  EXPECT_EQ(mesh.element_count(), input_triangles);
  const auto warned = [&](const std::string& what) {
    return std::any_of(late.warnings.begin(), late.warnings.end(),
                       [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  EXPECT_TRUE(warned("no time to imprint"));
  EXPECT_TRUE(warned("no time to remesh"));
  EXPECT_TRUE(warned("not searched for faces that intersect"));
  EXPECT_TRUE(warned("not tested for lying buried"));
}

// input_point_buried tests one point of a face that is only partly buried: the floor's two
// triangles run under the standing and the sunk box, so neither is buried as a whole, but the
// points under the boxes are, and those beside them and under the floating box are not.
TEST(Mesh, PointsUnderABoxAreBuriedOnAFaceThatIsNot) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  TriangleMesh floor;
  floor.positions = {Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0)};
  floor.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(floor);
  scene.meshes.push_back(closed_box("standing", -0.9, -0.8, 0.45, 0.3, 0.0, 0.0f, 0.8f));
  scene.meshes.push_back(closed_box("sunk", 0.9, 0.7, 0.35, 0.35, 0.0, -0.25f, 0.6f));
  scene.meshes.push_back(closed_box("floating", 0.9, -1.1, 0.3, 0.3, 0.0, 0.05f, 0.5f));
  scene.commit();
  const Vec3 up(0, 0, 1);
  EXPECT_FALSE(input_triangle_buried(scene, floor.positions[0], floor.positions[1], floor.positions[2]));
  EXPECT_FALSE(input_triangle_buried(scene, floor.positions[0], floor.positions[2], floor.positions[3]));
  EXPECT_TRUE(input_point_buried(scene, Vec3(-0.9f, -0.8f, 0.0f), up)) << "under the standing box";
  EXPECT_TRUE(input_point_buried(scene, Vec3(0.9f, 0.7f, 0.0f), up)) << "inside the sunk box";
  EXPECT_FALSE(input_point_buried(scene, Vec3(-1.6f, 1.5f, 0.0f), up)) << "open floor";
  EXPECT_FALSE(input_point_buried(scene, Vec3(0.9f, -1.1f, 0.0f), up)) << "under the floating box: in view";
  EXPECT_FALSE(input_point_buried(scene, Vec3(-0.9f, -0.8f, 0.8f), up)) << "the standing box's top";
}

// Behind an open sheet a point is buried only where no light reaches it. A floor under a slab
// modelled as one quad facing up (its back over the floor, nothing closed about it) is lit by
// the sky round the slab's edges and is kept, though every burial ray from its middle meets the
// slab's back; the floor under a box with no bottom face, which no light can enter, is removed
// as under a closed box. The camera looks down on the slab, seeing neither.
TEST(Mesh, PointsBehindAnOpenSheetAreBuriedOnlyWhereNoLightReaches) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  scene.meshes.push_back(gilt::test::quad(Vec3(-8, -8, 0), Vec3(8, -8, 0), Vec3(8, 8, 0), Vec3(-8, 8, 0)));
  // The slab, facing up, half a unit over the floor's left part.
  scene.meshes.push_back(
      gilt::test::quad(Vec3(-7, -3, 0.5f), Vec3(-1, -3, 0.5f), Vec3(-1, 3, 0.5f), Vec3(-7, 3, 0.5f)));
  TriangleMesh bottomless = closed_box("bottomless", 4.0, 0.0, 0.5, 0.5, 0.0, 0.0f, 1.0f);
  bottomless.indices.erase(bottomless.indices.begin(), bottomless.indices.begin() + 6);
  scene.meshes.push_back(bottomless);
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  scene.camera = rc::scene::Camera{.look_from = Vec3(0, 0, 30), .look_at = Vec3(0, 0, 0)};
  scene.commit();
  ASSERT_FALSE(scene.on_closed_surface(1, 0));
  ASSERT_FALSE(scene.on_closed_surface(2, 0));
  const Vec3 up(0, 0, 1);
  EXPECT_FALSE(input_point_buried(scene, Vec3(-4.0f, 0.0f, 0.0f), up))
      << "under the slab: lit round its edges";
  EXPECT_TRUE(input_point_buried(scene, Vec3(4.0f, 0.0f, 0.0f), up)) << "under the box without a bottom";
}

// A model of many small separate tiles cannot be meshed coarser than its tiles: each keeps its
// border. Asked for fewer elements than that, the mesher says so rather than silently giving
// many more (on Šibenik, --elements 20000 gave 170,608); without --elements it says nothing.
TEST(Mesh, SaysWhenTheInputAllowsNoFewerElementsThanAsked) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  TriangleMesh tiles;
  tiles.name = "tiles";
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) {
      const float x = 0.1f * float(i), y = 0.1f * float(j), s = 0.08f;
      const auto v = static_cast<uint32_t>(tiles.positions.size());
      tiles.positions.insert(tiles.positions.end(), {Vec3(x, y, 0), Vec3(x + s, y, 0), Vec3(x + s, y + s, 0), Vec3(x, y + s, 0)});
      tiles.indices.insert(tiles.indices.end(), {v, v + 1, v + 2, v, v + 2, v + 3});
    }
  scene.meshes.push_back(tiles);
  scene.commit();
  const auto says_so = [](const MeshReport& r) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [](const std::string& w) { return w.find("asked for about 100 elements") != std::string::npos; });
  };
  MeshReport report;
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.elements = 100}, &report);
  EXPECT_EQ(report.elements, mesh.element_count());
  EXPECT_GE(mesh.element_count(), 1800u) << "two triangles per tile at least";
  EXPECT_TRUE(says_so(report));
  MeshReport unasked;
  build_mesh(scene, MeshSettings{}, &unasked);
  EXPECT_TRUE(std::none_of(unasked.warnings.begin(), unasked.warnings.end(),
                           [](const std::string& w) { return w.find("asked for about") != std::string::npos; }));
}

// A room modelled inside out (a closed box facing outwards, as a scaled cube primitive comes)
// encloses what stands in it just as a block encloses the floor under it. What the camera inside
// sees is kept; and when "buried" would take a large share of the scene, nothing is removed.
TEST(Mesh, InsideOutRoomsKeepTheirContents) {
  for (const bool camera_inside : {true, false}) {
    Scene scene;
    scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
    scene.meshes.push_back(closed_box("room", 0.0, 0.0, 2.0, 2.0, 0.0, 0.0f, 3.0f));  // faces outwards
    // Small inside the room with the camera in it; large (a third of the area) with it outside.
    scene.meshes.push_back(camera_inside ? closed_box("block", 0.5, 0.5, 0.3, 0.3, 0.2, 0.0f, 0.6f)
                                         : closed_box("block", 0.0, 0.0, 1.5, 1.5, 0.0, 0.0f, 2.0f));
    scene.camera =
        rc::scene::Camera{.look_from = camera_inside ? Vec3(0.0f, -1.5f, 2.5f) : Vec3(0.0f, -10.0f, 1.5f),
                          .look_at = Vec3(0.5f, 0.5f, 0.3f),
                          .up = Vec3(0.0f, 0.0f, 1.0f)};
    scene.commit();
    MeshReport report;
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.25f}, &report);
    double top = 0.0;
    for (size_t e = 0; e < mesh.element_count(); ++e)
      if (mesh.element_surface[e] == 1 && mesh.element_normal[e].z > 0.999f) top += mesh.element_area[e];
    const double block_top = camera_inside ? 0.36 : 9.0;
    EXPECT_NEAR(top, block_top, 1e-5 * block_top) << (camera_inside ? "camera inside" : "camera outside");
    const bool warned = std::any_of(report.warnings.begin(), report.warnings.end(),
                                    [](const std::string& w) { return w.find("buried") != std::string::npos; });
    EXPECT_EQ(warned, !camera_inside);
    if (!camera_inside) {
      EXPECT_EQ(report.buried_faces, 0u);
    }
  }
}

TEST(Mesh, RepairsABrokenSoup) {
  // A 2 × 2 square in z = 0 facing +z, as a soup: every triangle has its own three vertices. One
  // triangle is wound the other way, one triangle repeats a point (zero area), one has three
  // collinear points on the square's edge, and a separate mesh has two triangles crossing each
  // other. The scene is not committed: commit() would drop the degenerate triangles itself.
  TriangleMesh soup;
  soup.name = "soup";
  const auto triangle = [&](Vec3 a, Vec3 b, Vec3 c) {
    const auto base = uint32_t(soup.positions.size());
    soup.positions.insert(soup.positions.end(), {a, b, c});
    soup.indices.insert(soup.indices.end(), {base, base + 1, base + 2});
  };
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const Vec3 p00(float(i), float(j), 0.0f), p10(float(i + 1), float(j), 0.0f),
          p11(float(i + 1), float(j + 1), 0.0f), p01(float(i), float(j + 1), 0.0f);
      triangle(p00, p10, p11);
      if (i == 1 && j == 1)
        triangle(p00, p01, p11);  // flipped
      else
        triangle(p00, p11, p01);
    }
  triangle(Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(0, 0, 0));  // repeated point
  triangle(Vec3(2, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 0));  // collinear, wound like its neighbours
  TriangleMesh crossing;
  crossing.name = "crossing";
  crossing.positions = {Vec3(5, 0, 0),  Vec3(7, 0, 0), Vec3(6, 2, 0),
                        Vec3(6, 1, -1), Vec3(6, 1, 1), Vec3(6, 3, 0)};
  crossing.indices = {0, 1, 2, 3, 4, 5};

  // Two triangles on one edge, the second folded back over the first: one connected piece that
  // overlaps itself.
  TriangleMesh folded;
  folded.name = "folded";
  folded.positions = {Vec3(10, 0, 0), Vec3(12, 0, 0), Vec3(11, 2, 0), Vec3(10.5f, 0.5f, 0)};
  folded.indices = {0, 1, 2, 2, 1, 3};

  // Three triangles on one edge: not a manifold, so orientation copies the edge's vertices and
  // meshes the three as separate sheets.
  TriangleMesh fin;
  fin.name = "fin";
  fin.positions = {Vec3(0, 0, 5), Vec3(1, 0, 5), Vec3(0.5f, 1, 5), Vec3(0.5f, -1, 5), Vec3(0.5f, 0, 6)};
  fin.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};

  Scene scene = single_mesh_scene(soup);
  scene.meshes.push_back(crossing);
  scene.meshes.push_back(fin);
  scene.meshes.push_back(folded);
  MeshReport report;
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = 0.25f}, &report);

  // 8 + 2 triangles of 3 points each, 9 distinct points in the square; crossing has none equal.
  EXPECT_EQ(report.merged_vertices, 30u - 9u);
  EXPECT_EQ(report.removed_degenerate, 2u);
  EXPECT_EQ(report.reoriented, 1u);
  // Only 'folded' intersects itself, once. The two triangles of 'crossing' are separate pieces:
  // where they cross is a contact, imprinted on both. So are the three sheets of 'fin', which
  // meet along their borders.
  EXPECT_EQ(report.self_intersecting, 1u);
  EXPECT_GT(report.contact_edges, 0u);
  for (const std::string& w : report.warnings) note("repair_warning", w);
  const auto warned = [&](const std::string& what) {
    return std::any_of(report.warnings.begin(), report.warnings.end(), [&](const std::string& w) {
      return w.find("'soup'") != std::string::npos && w.find(what) != std::string::npos;
    });
  };
  EXPECT_TRUE(warned("merged"));
  EXPECT_TRUE(warned("degenerate"));
  EXPECT_TRUE(warned("reoriented"));
  EXPECT_TRUE(std::any_of(report.warnings.begin(), report.warnings.end(), [](const std::string& w) {
    return w.find("'folded'") != std::string::npos && w.find("intersect") != std::string::npos;
  }));
  // Each crossing triangle is cut along the other, and they cross along x = 6, z = 0 for
  // 1 < y < 2: no element of either may cross that segment. An element crosses it when it
  // straddles the other triangle's plane (z = 0 for the second, x = 6 for the first) and the
  // line where it meets that plane overlaps 1 < y < 2.
  size_t straddling = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    if (mesh.element_surface[e] != 1) continue;
    const auto& el = mesh.elements[e];
    const bool first = mesh.element_normal[e].z > 0.5f || mesh.element_normal[e].z < -0.5f;  // lies in z = 0
    auto side = [&](const Vec3& q) { return first ? q.x - 6.0f : q.z; };
    float lo = std::numeric_limits<float>::max(), hi = -lo;
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = mesh.positions[el[k]], &b = mesh.positions[el[(k + 1) % 3]];
      const float sa = side(a), sb = side(b);
      if ((sa < -1e-6f && sb > 1e-6f) || (sa > 1e-6f && sb < -1e-6f)) {
        const float y = a.y + (b.y - a.y) * sa / (sa - sb);
        lo = std::min(lo, y), hi = std::max(hi, y);
      }
    }
    straddling += hi > 1.0f + 1e-4f && lo < 2.0f - 1e-4f;
  }
  EXPECT_EQ(straddling, 0u);

  EXPECT_TRUE(std::any_of(report.warnings.begin(), report.warnings.end(), [](const std::string& w) {
    return w.find("'fin'") != std::string::npos && w.find("manifold") != std::string::npos;
  }));
  double fin_area = 0.0;
  for (size_t e = 0; e < mesh.element_count(); ++e)
    if (mesh.element_surface[e] == 2) fin_area += mesh.element_area[e];
  EXPECT_NEAR(fin_area, 1.5, 1e-6 * 1.5);  // all three triangles kept, planar pieces: float rounding

  // The square comes out whole (area 4, float-exact coordinates: 1e-6), facing +z, conforming.
  double area = 0.0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    if (mesh.element_surface[e] != 0) continue;
    area += mesh.element_area[e];
    EXPECT_GT(mesh.element_normal[e].z, 0.9999f);
  }
  EXPECT_NEAR(area, 4.0, 1e-6 * 4.0);
  TriangleMesh square;
  square.positions = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 2, 0), Vec3(0, 2, 0)};
  square.indices = {0, 1, 2, 0, 2, 3};
  const Conformity c = check_conformity(mesh, 0, input_boundary(square), 0.25);
  EXPECT_EQ(c.bad_edges, 0u);
  EXPECT_EQ(c.t_junctions, 0u);
}

TEST(Mesh, MaxEdgeIsRespected) {
  const Scene scene = committed_builtin("cornell");
  for (float max_edge : {25.0f, 50.0f, 100.0f}) {
    MeshReport report;
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = max_edge}, &report);
    EXPECT_EQ(report.max_edge, max_edge);
    const double mean = mean_edge_length(mesh);
    note("mean_edge_" + std::to_string(int(max_edge)),
         fmt("%.3f (%.3f L), %.0f elements", mean, mean / max_edge, double(mesh.element_count())));
    // The mesher aims the remesher so the mean edge is L (measured 1.02–1.05 L for L = 25, 50, 100); ±20 %
    // leaves room for meshes where short protected edges, cut into whole pieces, make up a larger share (they
    // grow in number relative to interior edges as L grows).
    EXPECT_NEAR(mean, max_edge, 0.2 * max_edge);
  }
}

TEST(Mesh, ElementCountIsRespected) {
  const Scene scene = committed_builtin("cornell");
  for (int elements : {1000, 3000, 12000}) {
    MeshReport report;
    const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.elements = elements}, &report);
    EXPECT_FLOAT_EQ(report.max_edge, target_edge_length(scene, MeshSettings{.elements = elements}));
    note("elements_" + std::to_string(elements), fmt("%.0f (%.3f of requested)", double(mesh.element_count()),
                                                     double(mesh.element_count()) / elements));
    // Same bound and reason as at the default count.
    EXPECT_NEAR(double(mesh.element_count()), elements, 0.25 * elements);
  }
}

TEST(Mesh, SameResultForAnyThreadCount) {
  const Scene scene = committed_builtin("cornell");
  const RadiosityMesh parallel = build_mesh(scene, MeshSettings{.elements = 2000});
  RadiosityMesh serial;
  {
    rc::util::ThreadLimit one(1);
    serial = build_mesh(scene, MeshSettings{.elements = 2000});
  }
  EXPECT_EQ(parallel.positions, serial.positions);
  EXPECT_EQ(parallel.normals, serial.normals);
  EXPECT_EQ(parallel.elements, serial.elements);
  EXPECT_EQ(parallel.element_surface, serial.element_surface);
}

TEST(Mesh, TargetEdgeLength) {
  const Scene scene = committed_builtin("cornell");
  double area = 0.0;
  for (const TriangleMesh& m : scene.meshes) area += input_area(m);
  // N equilateral triangles of edge L cover A: L = sqrt(4A / (√3 N)). Float result: 1e-6.
  const double expected = std::sqrt(4.0 * area / (std::sqrt(3.0) * kDefaultElements));
  EXPECT_NEAR(target_edge_length(scene, MeshSettings{}), expected, 1e-6 * expected);
  EXPECT_EQ(target_edge_length(scene, MeshSettings{.max_edge = 7.0f, .elements = 100}), 7.0f);
  EXPECT_THROW(target_edge_length(scene, MeshSettings{.max_edge = -1.0f}), rc::InputError);
}

}  // namespace
}  // namespace gilt::radiosity
