// Imprinting contact lines with exact orientation predicates and one constrained Delaunay
// triangulation per cut face. The segment two triangles share is found as in Möller 1997, "A
// Fast Triangle-Triangle Intersection Test": each triangle meets the other's plane in an
// interval of the line where the planes cross, and the segment is the intervals' overlap. Which
// side of a plane a corner lies on is decided exactly (CGAL's filtered predicates), so a leg
// standing on a floor meets it along its sides' bottom edges, not a rounding error above it.

#include "radiosity/mesh/imprint.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/box_intersection_d.h>
#include <glm/geometric.hpp>

#include "raytrace_core/util/parallel.h"

namespace gilt::radiosity::mesh::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = Kernel::Point_2;
using Point3 = Kernel::Point_3;
using Triangle = std::array<DVec3, 3>;

constexpr uint32_t kNone = UINT32_MAX;

/// A vertex of a face's triangulation: its index among the face's points (kNone for a point the
/// triangulation made where two lines cross).
struct VertexInfo {
  uint32_t index = kNone;
};
/// A face of a face's triangulation: whether it lies outside the cut face.
struct FaceInfo {
  bool outside = false;
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using Fb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel, CGAL::Constrained_triangulation_face_base_2<Kernel>>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

Point3 cgal(const DVec3& p) { return {p.x, p.y, p.z}; }

bool lex_less(const DVec3& a, const DVec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); }

/// Where the segment a–b crosses the plane through `origin` with normal `normal`, for endpoints
/// on opposite sides. The endpoints are taken in lexicographic order, so an edge two faces share
/// is cut at one point, bit for bit, whichever face asks.
DVec3 crossing(DVec3 a, DVec3 b, const DVec3& origin, const DVec3& normal) {
  if (lex_less(b, a)) std::swap(a, b);
  const double da = glm::dot(normal, a - origin), db = glm::dot(normal, b - origin);
  const double s = da == db ? 0.5 : std::clamp(da / (da - db), 0.0, 1.0);
  return a + (b - a) * s;
}

/// Where a piece of contact line ends, as the cut face sees it.
enum Where : int { kEdge0 = 0, kEdge1, kEdge2, kCorner0, kCorner1, kCorner2, kInside };

struct LinePoint {
  DVec3 p;
  int where = kInside;
  double along = 0.0;  ///< position along the line the two planes share
};

/// The points where triangle `tri`, whose corners lie on the sides `side` of a plane, meets the
/// plane: corners on it and crossings of edges between opposite sides. At most two, unless the
/// triangle lies in the plane (all sides 0), which the caller excludes.
int meet_plane(const Triangle& tri, const std::array<int, 3>& side, const DVec3& origin, const DVec3& normal,
               LinePoint out[2]) {
  int n = 0;
  for (int k = 0; k < 3 && n < 2; ++k) {
    if (side[k] == 0) out[n++] = {tri[k], kCorner0 + k};
    const int j = (k + 1) % 3;
    if (n < 2 && side[k] * side[j] < 0) out[n++] = {crossing(tri[k], tri[j], origin, normal), kEdge0 + k};
  }
  return n;
}

std::array<int, 3> sides(const Triangle& plane, const Triangle& tri) {
  const Point3 a = cgal(plane[0]), b = cgal(plane[1]), c = cgal(plane[2]);
  std::array<int, 3> s;
  for (int k = 0; k < 3; ++k) s[k] = static_cast<int>(CGAL::orientation(a, b, c, cgal(tri[k])));
  return s;
}

/// How far from a face's edge or corner a constructed point may lie and still be taken as on it:
/// a billionth of the face's longest edge, and at least a few units in the last place of its
/// coordinates. Points this close are one point to a float, which is all an element keeps.
double snap_distance(const Triangle& face) {
  double longest = 0.0, largest = 0.0;
  for (int k = 0; k < 3; ++k) {
    longest = std::max(longest, glm::length(face[(k + 1) % 3] - face[k]));
    for (int i = 0; i < 3; ++i) largest = std::max(largest, std::abs(face[k][i]));
  }
  return std::max(1e-9 * longest, 16 * std::numeric_limits<double>::epsilon() * largest);
}

/// The piece of contact line where tool triangle `tool` crosses face `face`, as the face sees
/// its ends; false when they do not cross along a line (apart, touching at a point, or coplanar).
bool contact_segment(const Triangle& face, const Triangle& tool, LinePoint& lo, LinePoint& hi) {
  const std::array<int, 3> tool_sides = sides(face, tool);
  if (tool_sides[0] == tool_sides[1] && tool_sides[1] == tool_sides[2]) return false;  // one side, or coplanar
  const std::array<int, 3> face_sides = sides(tool, face);
  if (face_sides[0] == face_sides[1] && face_sides[1] == face_sides[2]) return false;
  const DVec3 face_normal = glm::cross(face[1] - face[0], face[2] - face[0]);
  const DVec3 tool_normal = glm::cross(tool[1] - tool[0], tool[2] - tool[0]);
  LinePoint on_face[2], on_tool[2];
  if (meet_plane(face, face_sides, tool[0], tool_normal, on_face) < 2) return false;
  if (meet_plane(tool, tool_sides, face[0], face_normal, on_tool) < 2) return false;
  const DVec3 line = glm::cross(face_normal, tool_normal);
  for (LinePoint* p : {&on_face[0], &on_face[1], &on_tool[0], &on_tool[1]}) p->along = glm::dot(line, p->p);
  if (on_face[1].along < on_face[0].along) std::swap(on_face[0], on_face[1]);
  if (on_tool[1].along < on_tool[0].along) std::swap(on_tool[0], on_tool[1]);
  // The overlap of the two intervals; on a tie the face's own point, which lies on its border.
  lo = on_face[0].along >= on_tool[0].along ? on_face[0] : LinePoint{on_tool[0].p, kInside, on_tool[0].along};
  hi = on_face[1].along <= on_tool[1].along ? on_face[1] : LinePoint{on_tool[1].p, kInside, on_tool[1].along};
  if (!(lo.along < hi.along) || lo.p == hi.p) return false;
  // A tool's point on one of the face's edges (a wall standing along the floor's edge, a leg's
  // corner on the floor's diagonal) is a point of that edge, for both of its faces: within
  // snap_distance of it, which covers the rounding of the point's construction.
  const double eps = snap_distance(face);
  for (LinePoint* p : {&lo, &hi}) {
    if (p->where != kInside) continue;
    for (int k = 0; k < 3 && p->where == kInside; ++k)
      if (glm::length(p->p - face[k]) <= eps) p->where = kCorner0 + k;
    for (int k = 0; k < 3 && p->where == kInside; ++k) {
      const DVec3 &a = face[k], ab = face[(k + 1) % 3] - face[k];
      const double s = glm::dot(p->p - a, ab) / glm::dot(ab, ab);
      if (s > 0.0 && s < 1.0 && glm::length(p->p - (a + s * ab)) <= eps) p->where = kEdge0 + k;
    }
    if (p->where >= kCorner0 && p->where <= kCorner2) p->p = face[p->where - kCorner0];
  }
  if (lo.p == hi.p) return false;
  return true;
}

/// The coordinate plane a face is projected to: kept axes u and v, in an order that keeps
/// counter-clockwise about the normal counter-clockwise, and the dropped axis w.
struct Projection {
  int u, v, w;
  DVec3 normal, origin;

  Projection(const Triangle& face) : origin(face[0]) {
    normal = glm::cross(face[1] - face[0], face[2] - face[0]);
    const DVec3 a = glm::abs(normal);
    if (a.z >= a.x && a.z >= a.y) std::tie(u, v, w) = normal.z > 0 ? std::tuple(0, 1, 2) : std::tuple(1, 0, 2);
    else if (a.x >= a.y) std::tie(u, v, w) = normal.x > 0 ? std::tuple(1, 2, 0) : std::tuple(2, 1, 0);
    else std::tie(u, v, w) = normal.y > 0 ? std::tuple(2, 0, 1) : std::tuple(0, 2, 1);
  }
  Point2 operator()(const DVec3& p) const { return {p[u], p[v]}; }
  /// The point of the face's plane that projects to `q`.
  DVec3 lift(const Point2& q) const {
    DVec3 p;
    p[u] = q.x();
    p[v] = q.y();
    p[w] = origin[w] - (normal[u] * (p[u] - origin[u]) + normal[v] * (p[v] - origin[v])) / normal[w];
    return p;
  }
};

/// A face point that the surface's points are merged on: an input vertex, or a new position.
struct FacePoint {
  DVec3 p;
  uint32_t input = kNone;
};

/// One cut face, retriangulated: triangles and imprinted edges over its points.
struct CutFace {
  std::vector<FacePoint> points;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<std::array<uint32_t, 2>> lines;
};

struct Segment {
  LinePoint a, b;
};

uint64_t edge_key(uint32_t a, uint32_t b) {
  return a < b ? (uint64_t{a} << 32 | b) : (uint64_t{b} << 32 | a);
}

/// Marks the faces of `cdt` that lie outside the cut face: those reached from the infinite face
/// without crossing a constrained edge (slivers between the straight hull and a border point that
/// rounding put a hair inside the face).
void mark_outside(Cdt& cdt) {
  std::vector<Cdt::Face_handle> stack{cdt.infinite_face()};
  cdt.infinite_face()->info().outside = true;
  while (!stack.empty()) {
    const Cdt::Face_handle f = stack.back();
    stack.pop_back();
    for (int i = 0; i < 3; ++i) {
      const Cdt::Face_handle n = f->neighbor(i);
      if (n->info().outside || cdt.is_constrained(Cdt::Edge(f, i))) continue;
      n->info().outside = true;
      stack.push_back(n);
    }
  }
}

/// Retriangulates face `f` (corners `corner`, input indices `index`) with the points `splits[k]`
/// on its edge k (ordered from corner k) and the contact segments `segments`.
CutFace cut_face(const Triangle& corner, const std::array<uint32_t, 3>& index,
                 const std::array<std::vector<DVec3>, 3>& splits, const std::vector<Segment>& segments,
                 size_t& lost) {
  const Projection project(corner);
  CutFace out;
  Cdt cdt;
  const auto add = [&](const DVec3& p, uint32_t input) {
    const Cdt::Vertex_handle v = cdt.insert(project(p));
    if (v->info().index == kNone) {
      v->info().index = static_cast<uint32_t>(out.points.size());
      out.points.push_back({p, input});
    }
    return v;
  };
  // The border, a closed chain of constrained edges; border[k] holds edge k's chain.
  std::array<std::vector<Cdt::Vertex_handle>, 3> border;
  for (int k = 0; k < 3; ++k) {
    border[k].push_back(add(corner[k], index[k]));
    for (const DVec3& p : splits[k]) border[k].push_back(add(p, kNone));
  }
  for (int k = 0; k < 3; ++k) {
    border[k].push_back(border[(k + 1) % 3].front());
    for (size_t i = 0; i + 1 < border[k].size(); ++i)
      if (border[k][i] != border[k][i + 1]) cdt.insert_constraint(border[k][i], border[k][i + 1]);
  }
  // Lines along an edge mark that edge's pieces; the others are constrained inside.
  std::vector<std::pair<Cdt::Vertex_handle, Cdt::Vertex_handle>> inner;
  std::vector<std::pair<Cdt::Vertex_handle, Cdt::Vertex_handle>> along;  // border pieces on a line
  const Point2 c0 = project(corner[0]), c1 = project(corner[1]), c2 = project(corner[2]);
  const auto inside = [&](const DVec3& p) {
    const Point2 q = project(p);
    return CGAL::orientation(c0, c1, q) != CGAL::RIGHT_TURN && CGAL::orientation(c1, c2, q) != CGAL::RIGHT_TURN &&
           CGAL::orientation(c2, c0, q) != CGAL::RIGHT_TURN;
  };
  const auto edge_of = [](int where, int k) {  // whether a point at `where` lies on edge k's closure
    return where == k || where == kCorner0 + k || where == kCorner0 + (k + 1) % 3;
  };
  for (const Segment& s : segments) {
    int shared = -1;
    for (int k = 0; k < 3; ++k)
      if (edge_of(s.a.where, k) && edge_of(s.b.where, k)) shared = k;
    if (shared >= 0) {
      // Mark the border pieces between the two ends.
      const std::vector<Cdt::Vertex_handle>& chain = border[shared];
      const DVec3 from = corner[shared], dir = corner[(shared + 1) % 3] - from;
      double lo = glm::dot(s.a.p - from, dir), hi = glm::dot(s.b.p - from, dir);
      if (hi < lo) std::swap(lo, hi);
      for (size_t i = 0; i + 1 < chain.size(); ++i) {
        const double x = glm::dot(out.points[chain[i]->info().index].p - from, dir);
        const double y = glm::dot(out.points[chain[i + 1]->info().index].p - from, dir);
        if (x >= lo && y <= hi && chain[i] != chain[i + 1]) along.emplace_back(chain[i], chain[i + 1]);
      }
      continue;
    }
    if ((s.a.where == kInside && !inside(s.a.p)) || (s.b.where == kInside && !inside(s.b.p))) {
      ++lost;
      continue;
    }
    // An end inside the face is put on its plane: a leg's edge crosses the floor at a rounding
    // error from it, and the floor's pieces stay flat.
    const auto end = [&](const LinePoint& p) {
      return add(p.where == kInside ? project.lift(project(p.p)) : p.p, kNone);
    };
    const Cdt::Vertex_handle a = end(s.a), b = end(s.b);
    if (a != b) inner.emplace_back(a, b);
  }
  for (const auto& [a, b] : inner) cdt.insert_constraint(a, b);
  mark_outside(cdt);

  // Points the triangulation made where two lines cross lie in the face's plane.
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
    if (v->info().index == kNone) {
      v->info().index = static_cast<uint32_t>(out.points.size());
      out.points.push_back({project.lift(v->point()), kNone});
    }
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info().outside) continue;
    out.triangles.push_back({f->vertex(0)->info().index, f->vertex(1)->info().index, f->vertex(2)->info().index});
    for (int i = 0; i < 3; ++i) {
      // A constrained edge inside the face is a line; each is seen from both of its faces, and
      // the merge keeps it once.
      const Cdt::Face_handle n = f->neighbor(i);
      if (!cdt.is_constrained(Cdt::Edge(f, i)) || n->info().outside) continue;
      out.lines.push_back({f->vertex(Cdt::ccw(i))->info().index, f->vertex(Cdt::cw(i))->info().index});
    }
  }
  for (const auto& [a, b] : along) out.lines.push_back({a->info().index, b->info().index});
  return out;
}

struct PointHash {
  size_t operator()(const DVec3& p) const {
    uint64_t h = 0xcbf29ce484222325ull;
    for (int i = 0; i < 3; ++i) h = (h ^ std::bit_cast<uint64_t>(p[i] + 0.0)) * 0x100000001b3ull;
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

Triangle face_of(const TriangleSoup& surface, size_t f) {
  const auto& t = surface.triangles[f];
  return Triangle{surface.points[t[0]], surface.points[t[1]], surface.points[t[2]]};
}

/// A point a contact segment puts on an input edge (key: edge_key of its ends), and the point it
/// is merged into.
struct EdgePoint {
  uint64_t key;
  DVec3 p, to;
  bool operator<(const EdgePoint& o) const { return key != o.key ? key < o.key : lex_less(p, o.p); }
};

/// Reads the surface and the tools; returns the face–tool pairs whose boxes meet (CGAL's
/// box_intersection_d), in (face, tool) order, without repeats.
std::vector<std::pair<uint32_t, uint32_t>> face_tool_pairs(const TriangleSoup& surface,
                                                           std::span<const std::array<DVec3, 3>> tools) {
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, uint32_t, CGAL::Box_intersection_d::ID_EXPLICIT>;
  const auto box_of = [](const Triangle& t) { return cgal(t[0]).bbox() + cgal(t[1]).bbox() + cgal(t[2]).bbox(); };
  const size_t n = surface.triangles.size();
  std::vector<Box> face_boxes, tool_boxes;
  face_boxes.reserve(n);
  tool_boxes.reserve(tools.size());
  for (size_t f = 0; f < n; ++f) face_boxes.emplace_back(box_of(face_of(surface, f)), static_cast<uint32_t>(f));
  for (size_t t = 0; t < tools.size(); ++t) tool_boxes.emplace_back(box_of(tools[t]), static_cast<uint32_t>(t));
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  CGAL::box_intersection_d(face_boxes.begin(), face_boxes.end(), tool_boxes.begin(), tool_boxes.end(),
                           [&](const Box& f, const Box& t) { pairs.emplace_back(f.info(), t.info()); });
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

/// Reads the pairs; returns each face's contact segments with its tools.
std::vector<std::vector<Segment>> contact_segments(const TriangleSoup& surface, std::span<const std::array<DVec3, 3>> tools,
                                                   const std::vector<std::pair<uint32_t, uint32_t>>& pairs) {
  const size_t n = surface.triangles.size();
  std::vector<size_t> first(n + 1, 0);
  for (const auto& [f, t] : pairs) ++first[f + 1];
  for (size_t f = 0; f < n; ++f) first[f + 1] += first[f];
  std::vector<std::vector<Segment>> segments(n);
  rc::util::parallel_for(n, [&](size_t f) {
    const Triangle corner = face_of(surface, f);
    for (size_t i = first[f]; i < first[f + 1]; ++i) {
      Segment s;
      if (contact_segment(corner, tools[pairs[i].second], s.a, s.b)) segments[f].push_back(s);
    }
  });
  return segments;
}

/// Reads the segments; returns the points they put on each edge, from every face that has it,
/// sorted by edge. Points that one geometric point gave as several constructions (a leg's corner on
/// the floor's diagonal, met by two of its sides) are merged into one, the first along the edge
/// from its lower-numbered end; points at an end are merged into that end.
std::vector<EdgePoint> merged_edge_points(const TriangleSoup& surface, const std::vector<std::vector<Segment>>& segments,
                                          ImprintCounts& c) {
  std::vector<EdgePoint> edge_points;
  for (size_t f = 0; f < segments.size(); ++f) {
    const auto& t = surface.triangles[f];
    c.segments += segments[f].size();
    for (const Segment& s : segments[f])
      for (const LinePoint* p : {&s.a, &s.b})
        if (p->where <= kEdge2) edge_points.push_back({edge_key(t[p->where], t[(p->where + 1) % 3]), p->p, p->p});
  }
  std::sort(edge_points.begin(), edge_points.end());
  edge_points.erase(std::unique(edge_points.begin(), edge_points.end(),
                                [](const EdgePoint& x, const EdgePoint& y) { return x.key == y.key && x.p == y.p; }),
                    edge_points.end());
  for (size_t i = 0; i < edge_points.size();) {
    size_t j = i;
    while (j < edge_points.size() && edge_points[j].key == edge_points[i].key) ++j;
    const DVec3 a = surface.points[edge_points[i].key >> 32], b = surface.points[edge_points[i].key & 0xffffffffu];
    const Triangle ends{a, b, a};
    const double eps = snap_distance(ends), length = glm::length(b - a);
    std::vector<std::pair<double, size_t>> order;
    for (size_t k = i; k < j; ++k) order.emplace_back(glm::dot(edge_points[k].p - a, b - a) / length, k);
    std::sort(order.begin(), order.end());
    double first = -1.0;
    DVec3 to{};
    for (const auto& [x, k] : order) {
      if (x <= eps) edge_points[k].to = a;
      else if (x >= length - eps) edge_points[k].to = b;
      else {
        if (first < 0.0 || x - first > eps) first = x, to = edge_points[k].p;
        edge_points[k].to = to;
      }
    }
    i = j;
  }
  return edge_points;
}

/// The points on the edge `key`, out of merged_edge_points' list.
std::span<const EdgePoint> points_on(const std::vector<EdgePoint>& edge_points, uint64_t key) {
  const auto lo = std::lower_bound(edge_points.begin(), edge_points.end(), key,
                                   [](const EdgePoint& x, uint64_t k) { return x.key < k; });
  auto hi = lo;
  while (hi != edge_points.end() && hi->key == key) ++hi;
  return std::span<const EdgePoint>(lo, hi);
}

/// Reads the merged edge points; moves every segment end on an edge to the point it was merged
/// into (a corner, when it is one), and drops segments that shrink to a point.
void snap_segment_ends(const TriangleSoup& surface, const std::vector<EdgePoint>& edge_points,
                       std::vector<std::vector<Segment>>& segments) {
  rc::util::parallel_for(segments.size(), [&](size_t f) {
    const auto& t = surface.triangles[f];
    for (Segment& s : segments[f])
      for (LinePoint* p : {&s.a, &s.b}) {
        if (p->where > kEdge2) continue;
        const int k = p->where;
        for (const EdgePoint& e : points_on(edge_points, edge_key(t[k], t[(k + 1) % 3])))
          if (e.p == p->p) {
            p->p = e.to;
            break;
          }
        if (p->p == surface.points[t[k]]) p->where = kCorner0 + k;
        if (p->p == surface.points[t[(k + 1) % 3]]) p->where = kCorner0 + (k + 1) % 3;
      }
    std::erase_if(segments[f], [](const Segment& s) { return s.a.p == s.b.p; });
  });
}

/// Reads the segments and edge points; marks in `cut` the faces with a segment or a point on an
/// edge and retriangulates each of them on its own, into `cuts` (segments it could not keep: `lost`).
void cut_faces(const TriangleSoup& surface, const std::vector<EdgePoint>& edge_points,
               const std::vector<std::vector<Segment>>& segments, std::vector<char>& cut, std::vector<CutFace>& cuts,
               std::vector<size_t>& lost) {
  const size_t n = surface.triangles.size();
  cut.assign(n, 0);
  for (size_t f = 0; f < n; ++f) {
    const auto& t = surface.triangles[f];
    cut[f] = !segments[f].empty();
    for (int k = 0; k < 3 && !cut[f]; ++k) cut[f] = !points_on(edge_points, edge_key(t[k], t[(k + 1) % 3])).empty();
  }
  cuts.assign(n, CutFace{});
  lost.assign(n, 0);
  rc::util::parallel_for(n, [&](size_t f) {
    if (!cut[f]) return;
    const auto& t = surface.triangles[f];
    const Triangle corner = face_of(surface, f);
    std::array<std::vector<DVec3>, 3> splits;
    for (int k = 0; k < 3; ++k) {
      const DVec3 from = corner[k], dir = corner[(k + 1) % 3] - from;
      for (const EdgePoint& e : points_on(edge_points, edge_key(t[k], t[(k + 1) % 3])))
        if (e.to != corner[k] && e.to != corner[(k + 1) % 3]) splits[k].push_back(e.to);
      std::sort(splits[k].begin(), splits[k].end(),
                [&](const DVec3& a, const DVec3& b) { return glm::dot(a - from, dir) < glm::dot(b - from, dir); });
      splits[k].erase(std::unique(splits[k].begin(), splits[k].end()), splits[k].end());
    }
    cuts[f] = cut_face(corner, t, splits, segments[f], lost[f]);
  });
}

/// Reads the cut faces; returns the surface with them in place, merged in face order: input
/// corners keep their index, new points are numbered as met; the contact lines as `cuts`.
TriangleSoup merge_cut_faces(const TriangleSoup& surface, const std::vector<char>& cut,
                             const std::vector<CutFace>& cuts, const std::vector<size_t>& lost, ImprintCounts& c) {
  TriangleSoup out;
  out.points = surface.points;
  std::unordered_map<DVec3, uint32_t, PointHash> fresh;
  std::vector<std::array<uint32_t, 2>> lines;
  for (size_t f = 0; f < surface.triangles.size(); ++f) {
    if (!cut[f]) {
      out.triangles.push_back(surface.triangles[f]);
      continue;
    }
    ++c.faces_cut;
    c.segments_lost += lost[f];
    const CutFace& piece = cuts[f];
    std::vector<uint32_t> index(piece.points.size());
    for (size_t i = 0; i < piece.points.size(); ++i) {
      const FacePoint& p = piece.points[i];
      if (p.input != kNone) {
        index[i] = p.input;
        continue;
      }
      const auto [it, added] = fresh.try_emplace(p.p + 0.0, static_cast<uint32_t>(out.points.size()));
      if (added) out.points.push_back(p.p + 0.0);
      index[i] = it->second;
    }
    for (const auto& t : piece.triangles) out.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
    for (const auto& [a, b] : piece.lines)
      if (index[a] != index[b]) lines.push_back({std::min(index[a], index[b]), std::max(index[a], index[b])});
  }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  out.cuts = std::move(lines);
  return out;
}

}  // namespace

TriangleSoup imprint(const TriangleSoup& surface, std::span<const std::array<DVec3, 3>> tools, ImprintCounts* counts) {
  return imprint(surface, tools, face_tool_pairs(surface, tools), counts);
}

TriangleSoup imprint(const TriangleSoup& surface, std::span<const std::array<DVec3, 3>> tools,
                     const std::vector<std::pair<uint32_t, uint32_t>>& pairs, ImprintCounts* counts) {
  ImprintCounts local;
  ImprintCounts& c = counts ? *counts : local;
  c = {};
  c.face_pairs = pairs.size();
  std::vector<std::vector<Segment>> segments = contact_segments(surface, tools, pairs);
  const std::vector<EdgePoint> edge_points = merged_edge_points(surface, segments, c);
  snap_segment_ends(surface, edge_points, segments);
  std::vector<char> cut;
  std::vector<CutFace> cuts;
  std::vector<size_t> lost;
  cut_faces(surface, edge_points, segments, cut, cuts, lost);
  return merge_cut_faces(surface, cut, cuts, lost, c);
}

}  // namespace gilt::radiosity::mesh::detail
