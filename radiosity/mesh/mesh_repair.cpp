// Mesh repair and isotropic remeshing with CGAL Polygon Mesh Processing. Orientation of polygon
// soups: Guéziec, Taubin, Lazarus & Horn 2001, "Cutting and Stitching"; remeshing: Botsch &
// Kobbelt 2004, "A Remeshing Approach to Multiresolution Modeling". This is the only file of
// gilt that includes CGAL, so its slow compile is paid once.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <mutex>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Surface_mesh.h>

#include "radiosity/mesh/mesh_detail.h"
#include "radiosity/mesh/imprint.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/progress.h"

namespace gilt::radiosity::mesh::detail {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Polygon = std::vector<std::size_t>;
using face_descriptor = SurfaceMesh::Face_index;
using edge_descriptor = SurfaceMesh::Edge_index;

/// Records which polygons orient_polygon_soup() reversed and how many points it copied. The
/// orienter takes the visitor by value, so the records live outside it.
struct OrientationRecorder : PMP::Default_orientation_visitor {
  std::vector<char>* reversed = nullptr;
  size_t* duplicated = nullptr;

  void polygon_orientation_reversed(std::size_t polygon) { (*reversed)[polygon] ^= 1; }
  void duplicated_vertex(std::size_t, std::size_t) { ++*duplicated; }
};

/// Union–find over polygon indices.
class Components {
 public:
  explicit Components(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), size_t{0}); }
  size_t find(size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(size_t a, size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<size_t> parent_;
};

double polygon_area(const std::vector<Point>& points, const Polygon& polygon) {
  // Fan from the first vertex; the soup holds triangles, but this costs nothing extra.
  Kernel::Vector_3 sum(0.0, 0.0, 0.0);
  for (size_t i = 1; i + 1 < polygon.size(); ++i)
    sum = sum + CGAL::cross_product(points[polygon[i]] - points[polygon[0]],
                                    points[polygon[i + 1]] - points[polygon[0]]);
  return 0.5 * std::sqrt(sum.squared_length());
}

/// orient_polygon_soup() makes every connected component consistent but picks each component's
/// side from whichever polygon it starts at. Where most of a component (by area) was reversed,
/// reverse the whole component back, so the input's front survives wherever the input mostly
/// agreed with itself. `reversed` marks polygons whose winding differs from the input.
void restore_input_fronts(const std::vector<Point>& points, std::vector<Polygon>& polygons,
                          std::vector<char>& reversed) {
  Components components(polygons.size());
  std::unordered_map<uint64_t, size_t> edge_owner;
  edge_owner.reserve(3 * polygons.size());
  for (size_t p = 0; p < polygons.size(); ++p) {
    const Polygon& polygon = polygons[p];
    for (size_t i = 0; i < polygon.size(); ++i) {
      const uint64_t a = polygon[i], b = polygon[(i + 1) % polygon.size()];
      const uint64_t key = (std::min(a, b) << 32) | std::max(a, b);
      const auto [it, inserted] = edge_owner.emplace(key, p);
      if (!inserted) components.join(p, it->second);
    }
  }
  std::unordered_map<size_t, std::pair<double, double>> kept_and_flipped;  // area per component
  for (size_t p = 0; p < polygons.size(); ++p) {
    auto& areas = kept_and_flipped[components.find(p)];
    (reversed[p] ? areas.second : areas.first) += polygon_area(points, polygons[p]);
  }
  for (size_t p = 0; p < polygons.size(); ++p) {
    const auto& areas = kept_and_flipped[components.find(p)];
    if (areas.second > areas.first) {
      std::reverse(polygons[p].begin(), polygons[p].end());
      reversed[p] ^= 1;
    }
  }
}

/// Builds a consistently oriented, manifold triangle mesh from the input, counting repairs.
SurfaceMesh repair(const rc::scene::TriangleMesh& input, RepairCounts& counts) {
  std::vector<Point> points;
  points.reserve(input.positions.size());
  for (const rc::Vec3& p : input.positions) points.emplace_back(p.x, p.y, p.z);
  std::vector<Polygon> polygons;
  polygons.reserve(input.triangle_count());
  for (size_t t = 0; t < input.triangle_count(); ++t)
    polygons.push_back({input.indices[3 * t], input.indices[3 * t + 1], input.indices[3 * t + 2]});

  counts.merged_vertices = PMP::merge_duplicate_points_in_polygon_soup(points, polygons);
  // With equal points merged, a face that names one point twice has no area.
  const auto repeats_a_point = [](const Polygon& polygon) {
    for (size_t i = 0; i < polygon.size(); ++i)
      for (size_t j = i + 1; j < polygon.size(); ++j)
        if (polygon[i] == polygon[j]) return true;
    return false;
  };
  counts.removed_degenerate = std::erase_if(polygons, repeats_a_point);
  counts.removed_duplicates = PMP::merge_duplicate_polygons_in_polygon_soup(points, polygons);
  PMP::remove_isolated_points_in_polygon_soup(points, polygons);

  std::vector<char> reversed(polygons.size(), 0);
  OrientationRecorder recorder;
  recorder.reversed = &reversed;
  recorder.duplicated = &counts.duplicated_vertices;
  PMP::orient_polygon_soup(points, polygons, CGAL::parameters::visitor(recorder));
  restore_input_fronts(points, polygons, reversed);
  counts.reoriented = static_cast<size_t>(std::count(reversed.begin(), reversed.end(), char{1}));

  SurfaceMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);

  // Faces whose three distinct points are collinear: remove_degenerate_faces() collapses or flips
  // them into their neighbours; any it cannot handle (e.g. an isolated sliver) are cut out.
  std::vector<face_descriptor> degenerate;
  PMP::degenerate_faces(mesh, std::back_inserter(degenerate));
  if (!degenerate.empty()) {
    counts.removed_degenerate += degenerate.size();
    PMP::remove_degenerate_faces(mesh);
    degenerate.clear();
    PMP::degenerate_faces(mesh, std::back_inserter(degenerate));
    for (face_descriptor f : degenerate) CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
    mesh.collect_garbage();
  }
  return mesh;
}

/// One connected piece of a repaired mesh: the unit that is imprinted and remeshed.
struct Part {
  SurfaceMesh mesh;
  CGAL::Bbox_3 box;
  size_t self_intersecting = 0;  ///< pairs of its faces that intersect away from shared vertices and edges
  bool counted = true;           ///< false when the deadline cut the count short (self_intersecting is a part)
};

/// Whether an edge of triangle `t` keeps the points `others` strictly off `t` in projection: all of
/// them on the far side of the edge's line from `t`'s third corner, by far more than rounding, in
/// the plane of the two coordinates `t`'s normal leans on least. Then the hull of `others` and `t`
/// are apart in space too (their projections are), whatever planes they lie in. A cheap exit
/// before CGAL's exact tests; false when unsure.
bool apart_in_plane(const Kernel::Triangle_3& t, const std::array<Point, 3>& others) {
  const Kernel::Vector_3 n = CGAL::cross_product(t[1] - t[0], t[2] - t[0]);
  const int drop = std::abs(n.x()) >= std::abs(n.y()) ? (std::abs(n.x()) >= std::abs(n.z()) ? 0 : 2)
                                                       : (std::abs(n.y()) >= std::abs(n.z()) ? 1 : 2);
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  const auto cross = [&](const Point& a, const Point& b, const Point& p, double& scale) {
    const double bx = b[u] - a[u], by = b[v] - a[v], px = p[u] - a[u], py = p[v] - a[v];
    scale = (std::abs(bx) + std::abs(by)) * (std::abs(px) + std::abs(py));
    return bx * py - by * px;
  };
  for (int e = 0; e < 3; ++e) {
    const Point &a = t[e], &b = t[(e + 1) % 3], &c = t[(e + 2) % 3];
    double scale = 0.0;
    const double inside = cross(a, b, c, scale);
    if (!(std::abs(inside) > 1e-9 * scale)) continue;
    bool apart = true;
    for (const Point& p : others) {
      const double side = cross(a, b, p, scale);
      if (!(side * inside < 0.0 && std::abs(side) > 1e-9 * scale)) {
        apart = false;
        break;
      }
    }
    if (apart) return true;
  }
  return false;
}

/// The pairs of faces of `mesh` that intersect other than along the edge or at the vertex they
/// share, as CGAL's PMP::self_intersections counts them (its do_faces_intersect, with a face
/// whose corners are collinear counted once), but with cheap exits in front of its exact tests.
/// On a furnished room most meeting boxes are of neighbours on one flat side of a piece, which
/// CGAL settles with exact arithmetic on every call (the rotated box's quad halves are coplanar,
/// so no filter can decide them); here two faces on an edge whose normals agree, or two faces on a
/// vertex whose far corners lie strictly off the other's plane, are settled in floating point.
/// A count is a warning only, so under a deadline it stops there (`counted` false): the meeting
/// boxes are still visited, but no more are tested.
size_t count_self_intersections(const SurfaceMesh& mesh, std::chrono::steady_clock::time_point deadline,
                                bool& counted) {
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, face_descriptor, CGAL::Box_intersection_d::ID_EXPLICIT>;
  using HalfedgeIndex = SurfaceMesh::Halfedge_index;
  size_t count = 0;
  std::vector<Box> boxes;
  boxes.reserve(mesh.number_of_faces());
  for (face_descriptor f : mesh.faces()) {
    const HalfedgeIndex h = mesh.halfedge(f);
    const Point &p = mesh.point(mesh.target(h)), &q = mesh.point(mesh.target(mesh.next(h))),
                &r = mesh.point(mesh.target(mesh.prev(h)));
    if (CGAL::collinear(p, q, r))
      ++count;
    else
      boxes.emplace_back(p.bbox() + q.bbox() + r.bbox(), f);
  }
  const auto corners = [&](face_descriptor f) {
    const HalfedgeIndex h = mesh.halfedge(f);
    return std::array<SurfaceMesh::Vertex_index, 3>{mesh.target(h), mesh.target(mesh.next(h)), mesh.source(h)};
  };
  const auto meet = [&](face_descriptor f, face_descriptor g) {
    // A shared edge: they intersect only when folded onto each other (coplanar, the far corners
    // on one side). Across a consistently wound edge, (p, q, r) and (q, p, s), a fold turns the
    // normals opposite; normals that agree by far more than their rounding (a few ulps of the
    // edges' products) rule it out.
    for (auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      if (mesh.face(mesh.opposite(h)) != g) continue;
      const Point &p = mesh.point(mesh.source(h)), &q = mesh.point(mesh.target(h)),
                  &r = mesh.point(mesh.target(mesh.next(h))),
                  &s = mesh.point(mesh.target(mesh.next(mesh.opposite(h))));
      const Kernel::Vector_3 pq = q - p, pr = r - p, ps = s - p;
      const Kernel::Vector_3 n1 = CGAL::cross_product(pq, pr), n2 = CGAL::cross_product(ps, pq);
      const double scale = pq.squared_length() * std::sqrt(pr.squared_length() * ps.squared_length());
      if (n1 * n2 > 1e-9 * scale) return false;
      return CGAL::coplanar(p, q, r, s) && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
    }
    const auto fv = corners(f), gv = corners(g);
    const Kernel::Triangle_3 tf(mesh.point(fv[0]), mesh.point(fv[1]), mesh.point(fv[2])),
        tg(mesh.point(gv[0]), mesh.point(gv[1]), mesh.point(gv[2]));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        if (fv[i] != gv[j]) continue;
        // A shared vertex: they intersect when the edge opposite it in either crosses the other.
        // An edge whose ends lie strictly on one side of the other's plane cannot.
        // An edge whose ends lie strictly on one side of the other's plane cannot, nor one in
        // that plane that an edge of the other face's keeps clear of it.
        // Projections that lie apart (apart_in_plane, in floating point with a margin) settle
        // it first whatever the planes: a flat fan's faces all share its centre, and their
        // exact coplanar tests were most of a million-triangle room's count.
        const auto clear = [](const Kernel::Triangle_3& t, const Point& a, const Point& b) {
          if (apart_in_plane(t, std::array<Point, 3>{a, b, b})) return true;
          const CGAL::Orientation oa = CGAL::orientation(t[0], t[1], t[2], a),
                                  ob = CGAL::orientation(t[0], t[1], t[2], b);
          if (oa != ob) return false;
          return oa != CGAL::COPLANAR || apart_in_plane(t, std::array<Point, 3>{a, b, b});
        };
        const Point &f1 = mesh.point(fv[(i + 1) % 3]), &f2 = mesh.point(fv[(i + 2) % 3]),
                    &g1 = mesh.point(gv[(j + 1) % 3]), &g2 = mesh.point(gv[(j + 2) % 3]);
        if (!clear(tf, g1, g2) && CGAL::do_intersect(tf, Kernel::Segment_3(g1, g2))) return true;
        return !clear(tg, f1, f2) && CGAL::do_intersect(tg, Kernel::Segment_3(f1, f2));
      }
    // No corner shared: faces whose projections lie apart (as above), strictly apart by a
    // plane, or in one plane and apart in it.
    if (apart_in_plane(tf, {tg[0], tg[1], tg[2]}) || apart_in_plane(tg, {tf[0], tf[1], tf[2]})) return false;
    std::array<CGAL::Orientation, 3> side;
    for (int k = 0; k < 3; ++k) side[k] = CGAL::orientation(tf[0], tf[1], tf[2], tg[k]);
    if (side[0] == side[1] && side[1] == side[2]) {
      if (side[0] != CGAL::COPLANAR) return false;
      if (apart_in_plane(tf, {tg[0], tg[1], tg[2]}) || apart_in_plane(tg, {tf[0], tf[1], tf[2]})) return false;
    }
    return CGAL::do_intersect(tf, tg);
  };
  counted = std::chrono::steady_clock::now() < deadline;
  size_t tested = 0;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
    if (!counted) return;
    if (++tested % 4096 == 0 && std::chrono::steady_clock::now() >= deadline) {
      counted = false;
      return;
    }
    count += meet(a.info(), b.info());
  });
  return count;
}

/// Splits the mesh into its connected pieces. Pieces of one mesh that meet without sharing
/// edges (a block standing on the floor, both in one OBJ material) are not a self-intersection
/// but a contact, imprinted like a contact between meshes; only what intersects within a piece
/// counts as one.
std::vector<Part> split_parts(const SurfaceMesh& mesh, std::chrono::steady_clock::time_point deadline) {
  // Faces joined across edges, pieces numbered in the order of their first face. One pass over
  // the faces (CGAL's split_connected_components walks the whole mesh once per piece, which on a
  // room of two thousand chairs took most of the repair).
  Components joined(mesh.number_of_faces());
  for (face_descriptor f : mesh.faces())
    for (auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const face_descriptor g = mesh.face(mesh.opposite(h));
      if (g != SurfaceMesh::null_face()) joined.join(f.idx(), g.idx());
    }
  std::vector<size_t> piece_of_root(mesh.number_of_faces(), SIZE_MAX);
  std::vector<Part> parts;
  std::vector<SurfaceMesh::Vertex_index> copy(mesh.number_of_vertices());
  std::vector<uint32_t> copied_into(mesh.number_of_vertices(), UINT32_MAX);
  for (face_descriptor f : mesh.faces()) {
    size_t& piece = piece_of_root[joined.find(f.idx())];
    if (piece == SIZE_MAX) {
      piece = parts.size();
      parts.emplace_back();
    }
    SurfaceMesh& out = parts[piece].mesh;
    std::array<SurfaceMesh::Vertex_index, 3> corners;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (k == 3) break;
      if (copied_into[v.idx()] != piece) {
        copied_into[v.idx()] = static_cast<uint32_t>(piece);
        copy[v.idx()] = out.add_vertex(mesh.point(v));
      }
      corners[k++] = copy[v.idx()];
    }
    if (k == 3) out.add_face(corners[0], corners[1], corners[2]);
  }
  rc::util::parallel_for(parts.size(), [&](size_t i) {
    parts[i].box = PMP::bbox(parts[i].mesh);
    parts[i].self_intersecting = count_self_intersections(parts[i].mesh, deadline, parts[i].counted);
  });
  return parts;
}

/// Cuts every protected edge longer than `max_length` into the fewest equal pieces no longer than
/// it, and fans the faces on either side from their opposite vertex so they stay triangles (the
/// remesher then flips and smooths the fans away). Points are placed by their rank counted from
/// the lexicographically smaller endpoint, so an edge that two input meshes share (a light set into
/// a ceiling) is cut at bit-identical points in both.
void split_protected_edges(SurfaceMesh& mesh, const std::vector<edge_descriptor>& edges, double max_length,
                           SurfaceMesh::Property_map<edge_descriptor, bool>& constrained) {
  using halfedge_descriptor = SurfaceMesh::Halfedge_index;
  for (edge_descriptor e : edges) {
    halfedge_descriptor h = mesh.halfedge(e);
    const Point a = mesh.point(mesh.source(h)), b = mesh.point(mesh.target(h));
    const int pieces = static_cast<int>(std::ceil(std::sqrt(CGAL::squared_distance(a, b)) / max_length));
    if (pieces <= 1) continue;
    const bool a_first = CGAL::compare_xyz(a, b) == CGAL::SMALLER;
    const Point& low = a_first ? a : b;
    const Kernel::Vector_3 span = (a_first ? b : a) - low;

    // Halfedges leading to the vertex opposite the edge, on each side that has a face.
    std::vector<halfedge_descriptor> to_opposite;
    for (halfedge_descriptor side : {h, mesh.opposite(h)})
      if (!mesh.is_border(side)) to_opposite.push_back(mesh.next(side));

    for (int i = 1; i < pieces; ++i) {
      // split_edge(h) inserts a vertex between h's source and target and returns the halfedge
      // into it; h keeps running from the new vertex to the target.
      const halfedge_descriptor into_new = CGAL::Euler::split_edge(h, mesh);
      constrained[mesh.edge(into_new)] = true;
      const int rank = a_first ? i : pieces - i;
      mesh.point(mesh.target(into_new)) = low + span * (double(rank) / double(pieces));
    }
    for (halfedge_descriptor to_apex : to_opposite)
      while (mesh.degree(mesh.face(to_apex)) > 3)
        to_apex = CGAL::Euler::split_face(mesh.prev(mesh.prev(to_apex)), to_apex, mesh);
  }
}

using Constrained = SurfaceMesh::Property_map<edge_descriptor, bool>;

/// Most pieces one mesh may have for its pieces to be imprinted on each other (the pairs are
/// found by bounding boxes, all against all); a mesh of more pieces (foliage, gravel) is
/// imprinted by other meshes only.
constexpr size_t kMaxImprintedParts = 4096;

/// The edge joining a and b, if any: CGAL::halfedge(a, b) walks round one end, which at the centre
/// of a finely cut fan costs its whole degree on every call; this walks round both ends at once
/// and stops with the first to find it or run out, so it costs the smaller degree.
std::optional<edge_descriptor> edge_between(SurfaceMesh::Vertex_index a, SurfaceMesh::Vertex_index b,
                                            const SurfaceMesh& mesh) {
  using HalfedgeIndex = SurfaceMesh::Halfedge_index;
  const HalfedgeIndex start_a = mesh.halfedge(a), start_b = mesh.halfedge(b);
  if (start_a == SurfaceMesh::null_halfedge() || start_b == SurfaceMesh::null_halfedge()) return std::nullopt;
  HalfedgeIndex ha = start_a, hb = start_b;  // halfedges into a and into b
  bool more_a = true, more_b = true;
  while (more_a || more_b) {
    if (more_a) {
      if (mesh.source(ha) == b) return mesh.edge(ha);
      ha = mesh.opposite(mesh.next(ha));
      more_a = ha != start_a;
    }
    if (more_b) {
      if (mesh.source(hb) == a) return mesh.edge(hb);
      hb = mesh.opposite(mesh.next(hb));
      more_b = hb != start_b;
    }
    if (!more_a || !more_b) break;  // one end's whole ring seen: it has no such edge
  }
  return std::nullopt;
}

/// A piece of some mesh that may imprint another piece, cropped to the faces that meet the other
/// piece's faces (found by find_contacts): only they can cut it, so imprinting reads them alone,
/// whatever the size of the tool.
struct ToolContact {
  uint32_t mesh = 0, part = 0;
  std::vector<uint32_t> faces;  ///< ascending
  /// (face of the imprinted piece, index into `faces`) for every pair of faces that meet, ascending
  std::vector<std::array<uint32_t, 2>> pairs;
};

/// The mesh as a soup (face f is triangle f), with its constrained edges as cuts when given.
TriangleSoup to_soup(const SurfaceMesh& mesh, const Constrained* constrained = nullptr);

/// Imprints on `part` the lines where other surfaces touch or cross it (a block standing on a
/// floor leaves its outline there) and marks them as constrained edges. Radiosity jumps across
/// such a line (Heckbert 1992 and Lischinski, Tampieri & Greenberg 1992 call it a D0
/// discontinuity: the floor is lit on one side and buried on the other); an element that
/// straddles it would average the two, and Gouraud interpolation would smear the dark into the
/// lit floor. The tools are read as triangles, only the faces of each that can meet the piece
/// (found by find_contacts); imprint() cuts each face of the piece along them on its own, so the
/// cost grows with the faces and the contacts, not with the tools' sizes, and a piece or tool
/// that intersects itself is imprinted like any other. Returns the number of imprinted edges.
size_t imprint_contacts(Part& part, const std::vector<std::pair<const Part*, const ToolContact*>>& tools,
                        Constrained& constrained, RepairCounts& counts) {
  std::vector<std::array<DVec3, 3>> triangles;
  std::vector<std::pair<uint32_t, uint32_t>> pairs;  // (face of the piece, index into triangles)
  for (const auto& [tool, contact] : tools) {
    const auto first = static_cast<uint32_t>(triangles.size());
    for (const auto& [own, k] : contact->pairs) pairs.emplace_back(own, first + k);
    for (uint32_t f : contact->faces) {
      std::array<DVec3, 3> t;
      int k = 0;
      for (auto v : CGAL::vertices_around_face(tool->mesh.halfedge(face_descriptor(f)), tool->mesh)) {
        if (k == 3) break;
        const Point& p = tool->mesh.point(v);
        t[k++] = DVec3(p.x(), p.y(), p.z());
      }
      triangles.push_back(t);
    }
  }
  if (triangles.empty()) return 0;
  std::sort(pairs.begin(), pairs.end());
  if (part.mesh.has_garbage()) part.mesh.collect_garbage();
  ImprintCounts imprinted;
  const TriangleSoup cut = imprint(to_soup(part.mesh), triangles, pairs, &imprinted);
  counts.contact_segments_lost += imprinted.segments_lost;
  if (imprinted.faces_cut == 0) return 0;

  SurfaceMesh mesh;
  std::vector<SurfaceMesh::Vertex_index> vertex;
  vertex.reserve(cut.points.size());
  for (const DVec3& p : cut.points) vertex.push_back(mesh.add_vertex(Point(p.x, p.y, p.z)));
  for (const auto& t : cut.triangles)
    if (mesh.add_face(vertex[t[0]], vertex[t[1]], vertex[t[2]]) == SurfaceMesh::null_face()) {
      // The cut faces do not fit together (a rounding case imprint() did not foresee): the piece
      // is meshed without its contact lines, and the report says how many tools were left out.
      counts.contacts_failed += tools.size();
      return 0;
    }
  Constrained marks = mesh.add_property_map<edge_descriptor, bool>("e:gilt_constrained", false).first;
  size_t lines = 0;
  for (const auto& [a, b] : cut.cuts) {
    const std::optional<edge_descriptor> e = edge_between(vertex[a], vertex[b], mesh);
    if (e && !marks[*e]) {
      marks[*e] = true;
      ++lines;
    }
  }
  part.mesh = std::move(mesh);
  constrained = marks;
  return lines;
}

/// Whether the triangles (a, b, c) and (b, a, d), which share the edge a–b, lie in one plane up to
/// the rounding of imprinting's constructed points to float (snap_new_points): each far corner
/// within 1e-9 of the longest edge, or four float steps of the largest coordinate, of the other
/// triangle's plane, and the two facing the same way.
bool flat_pair(const Point& a, const Point& b, const Point& c, const Point& d) {
  const Kernel::Vector_3 n1 = CGAL::cross_product(b - a, c - a), n2 = CGAL::cross_product(a - b, d - b);
  if (!(n1 * n2 > 0.0)) return false;
  const double volume = std::abs(CGAL::determinant(b - a, c - a, d - a));
  const double longest = std::sqrt(std::max({CGAL::squared_distance(a, b), CGAL::squared_distance(a, c),
                                             CGAL::squared_distance(a, d), CGAL::squared_distance(b, c),
                                             CGAL::squared_distance(b, d)}));
  double largest = 0.0;
  for (const Point* p : {&a, &b, &c, &d})
    largest = std::max({largest, std::abs(p->x()), std::abs(p->y()), std::abs(p->z())});
  const double tolerance = std::max(1e-9 * longest, 4.0 * 0x1p-24 * largest);
  return volume <= tolerance * std::sqrt(n1.squared_length()) && volume <= tolerance * std::sqrt(n2.squared_length());
}

/// Rounds the points that imprinting added to `mesh` (those not among `input`, sorted) to
/// float. One contact point may be constructed from different pairs of faces (a leg's corner as
/// the floor sees it and as the leg's own imprint does), differing in the last bits of the
/// double; rounded to float, which is all gilt's elements keep, they agree (unless they straddle
/// a float rounding boundary: a chance of about 2⁻²⁹ per coordinate for a one-ulp difference),
/// and so do the floor's and the block's copies of one contact point. Input points are floats
/// already and stay where they are. Every −0 becomes +0.
void snap_new_points(SurfaceMesh& mesh, const std::vector<std::array<double, 3>>& input) {
  // Through a volatile float: GCC 12 folded double(float(x)) to x in this translation unit.
  const auto to_float = [](double x) {
    volatile float f = static_cast<float>(x);
    return static_cast<double>(f);
  };
  for (auto v : mesh.vertices()) {
    const Point p = mesh.point(v);
    // x + 0.0 turns −0 into +0, which sorting could not tell apart.
    if (std::binary_search(input.begin(), input.end(), std::array<double, 3>{p.x(), p.y(), p.z()}))
      mesh.point(v) = Point(p.x() + 0.0, p.y() + 0.0, p.z() + 0.0);
    else
      mesh.point(v) = Point(to_float(p.x()) + 0.0, to_float(p.y()) + 0.0, to_float(p.z()) + 0.0);
  }
}

/// The point in the coordinate plane that `normal` is most nearly perpendicular to, with the
/// two kept coordinates ordered so that counter-clockwise about `normal` stays counter-clockwise.
Kernel::Point_2 project(const Point& p, const Kernel::Vector_3& normal) {
  const double ax = std::abs(normal.x()), ay = std::abs(normal.y()), az = std::abs(normal.z());
  if (az >= ax && az >= ay) return normal.z() > 0 ? Kernel::Point_2(p.x(), p.y()) : Kernel::Point_2(p.y(), p.x());
  if (ax >= ay) return normal.x() > 0 ? Kernel::Point_2(p.y(), p.z()) : Kernel::Point_2(p.z(), p.y());
  return normal.y() > 0 ? Kernel::Point_2(p.z(), p.x()) : Kernel::Point_2(p.x(), p.z());
}

/// The remesher follows the order of a piece's vertices and faces and the diagonals of its flat
/// regions, which imprinting chose face by face and snap_new_points may have pinched. This
/// rebuilds the piece in a form that depends on its points and constrained edges alone: one vertex per
/// position in lexicographic order, faces in order of their corners, and every flat region
/// triangulated as its constrained Delaunay triangulation (Lawson flips with exact 2D
/// predicates in the region's projection; a diagonal of four cocircular points avoids the
/// lowest-ranked of them, which is a symbolic perturbation and so picks one triangulation).
void canonicalize(SurfaceMesh& mesh, Constrained& constrained) {
  using vertex_descriptor = SurfaceMesh::Vertex_index;
  // Points in lexicographic order, each once: vertices that rounding put in one place (two
  // imprinted points a float step apart) become one, or their order would depend on the input's order.
  const auto less = [](const Point& p, const Point& q) { return CGAL::compare_xyz(p, q) == CGAL::SMALLER; };
  std::vector<Point> points;
  points.reserve(mesh.number_of_vertices());
  for (auto v : mesh.vertices()) points.push_back(mesh.point(v));
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  const auto index_of = [&](vertex_descriptor v) {
    return static_cast<std::size_t>(std::lower_bound(points.begin(), points.end(), mesh.point(v), less) - points.begin());
  };
  std::vector<Polygon> polygons;
  polygons.reserve(mesh.number_of_faces());
  for (face_descriptor f : mesh.faces()) {
    Polygon polygon;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) polygon.push_back(index_of(v));
    std::rotate(polygon.begin(), std::min_element(polygon.begin(), polygon.end()), polygon.end());
    if (std::adjacent_find(polygon.begin(), polygon.end()) != polygon.end() || polygon.front() == polygon.back())
      continue;  // two corners merged: no area
    polygons.push_back(std::move(polygon));
  }
  std::sort(polygons.begin(), polygons.end());
  polygons.erase(std::unique(polygons.begin(), polygons.end()), polygons.end());
  std::vector<std::pair<std::size_t, std::size_t>> kept;  // constrained edges, low index first
  for (edge_descriptor e : mesh.edges())
    if (constrained[e]) {
      const std::size_t a = index_of(mesh.source(mesh.halfedge(e))), b = index_of(mesh.target(mesh.halfedge(e)));
      if (a != b) kept.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(kept.begin(), kept.end());

  // Merged points can pinch the surface: orient_polygon_soup() copies a vertex where it would be
  // non-manifold, deterministically since the soup is canonical; each copy keeps its constraints.
  std::vector<std::vector<std::size_t>> copies(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) copies[i].push_back(i);
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    struct CopyRecorder : PMP::Default_orientation_visitor {
      std::vector<std::vector<std::size_t>>* copies = nullptr;
      void duplicated_vertex(std::size_t original, std::size_t copy) { (*copies)[original].push_back(copy); }
    } recorder;
    recorder.copies = &copies;
    PMP::orient_polygon_soup(points, polygons, CGAL::parameters::visitor(recorder));
  }

  SurfaceMesh out;
  std::vector<vertex_descriptor> vertex(points.size());
  std::vector<char> used(points.size(), 0);
  for (const Polygon& polygon : polygons)
    for (std::size_t i : polygon) used[i] = 1;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (used[i]) vertex[i] = out.add_vertex(points[i]);
  for (const Polygon& polygon : polygons) {
    std::vector<vertex_descriptor> corners;
    for (std::size_t i : polygon) corners.push_back(vertex[i]);
    CGAL::Euler::add_face(corners, out);  // a face the soup could not take stays out
  }
  Constrained marks = out.add_property_map<edge_descriptor, bool>("e:gilt_constrained", false).first;
  for (const auto& [a, b] : kept)
    for (std::size_t ca : copies[a])
      for (std::size_t cb : copies[b]) {
        if (ca >= points.size() || cb >= points.size() || !used[ca] || !used[cb]) continue;
        if (const std::optional<edge_descriptor> e = edge_between(vertex[ca], vertex[cb], out)) marks[*e] = true;
      }

  // Lawson flips, in edge order, until none applies. Each flip removes a locally non-Delaunay
  // edge, so the loop ends; the pass limit only guards against an unforeseen cycle.
  for (int pass = 0; pass < 64; ++pass) {
    bool flipped = false;
    for (edge_descriptor e : out.edges()) {
      if (marks[e] || out.is_border(e)) continue;
      const auto h = out.halfedge(e), o = out.opposite(h);
      const vertex_descriptor a = out.source(h), b = out.target(h), c = out.target(out.next(h)),
                              d = out.target(out.next(o));
      if (c == d || edge_between(c, d, out)) continue;
      const Point &pa = out.point(a), &pb = out.point(b), &pc = out.point(c), &pd = out.point(d);
      if (!flat_pair(pa, pb, pc, pd)) continue;
      const Kernel::Vector_3 normal = CGAL::cross_product(pb - pa, pc - pa) + CGAL::cross_product(pa - pb, pd - pb);
      const Kernel::Point_2 qa = project(pa, normal), qb = project(pb, normal), qc = project(pc, normal),
                            qd = project(pd, normal);
      // The flipped triangles (c, a, d) and (d, b, c) must both be proper.
      if (CGAL::orientation(qc, qa, qd) != CGAL::LEFT_TURN || CGAL::orientation(qd, qb, qc) != CGAL::LEFT_TURN)
        continue;
      bool flip = false;
      if (CGAL::orientation(qa, qb, qc) != CGAL::LEFT_TURN || CGAL::orientation(qb, qa, qd) != CGAL::LEFT_TURN) {
        flip = true;  // a flat or folded triangle: the flip makes both proper
      } else {
        const CGAL::Oriented_side side = CGAL::side_of_oriented_circle(qa, qb, qc, qd);
        if (side == CGAL::ON_POSITIVE_SIDE) {
          flip = true;
        } else if (side == CGAL::ON_ORIENTED_BOUNDARY) {
          const auto lowest = std::min({a.idx(), b.idx(), c.idx(), d.idx()});
          flip = lowest == a.idx() || lowest == b.idx();
        }
      }
      if (!flip) continue;
      CGAL::Euler::flip_edge(h, out);
      flipped = true;
    }
    if (!flipped) break;
  }
  mesh = std::move(out);
  constrained = mesh.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
}

/// Cuts out the faces whose corners are collinear, which CGAL 5.5's remesher cannot take (a
/// patch made of them alone makes it throw std::out_of_range from check_normals, or index past
/// its per-patch trees). They have no area, so nothing visible goes. Returns how many there were.
size_t remove_flat_faces(SurfaceMesh& mesh) {
  std::vector<face_descriptor> degenerate;
  PMP::degenerate_faces(mesh, std::back_inserter(degenerate));
  for (face_descriptor f : degenerate) CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
  if (!degenerate.empty()) mesh.collect_garbage();
  return degenerate.size();
}

/// CGAL's isotropic remeshing of `mesh` as it is, with its borders and `constrained` edges
/// protected (neither moved, split nor collapsed) and the vertices `fixed` marks kept where
/// they are (remesh_by_patches fixes each patch's border, where the patches are welded). Three tangential relaxation steps per pass instead of CGAL's one: on the
/// Cornell box they raise the 5th percentile of the elements' smallest angle from 33.7° to
/// 37.3° for no measurable time. Returns false, with `mesh` as it came, if CGAL gives up.
template <class FixedVertices>
bool isotropic_remesh(SurfaceMesh& mesh, const RemeshParams& params, Constrained& constrained, const FixedVertices& fixed) {
  for (edge_descriptor e : mesh.edges())
    if (mesh.is_border(e)) constrained[e] = true;
  SurfaceMesh before = mesh;
  try {
    PMP::isotropic_remeshing(faces(mesh), params.edge_length, mesh,
                             CGAL::parameters::number_of_iterations(static_cast<unsigned>(params.iterations))
                                 .edge_is_constrained_map(constrained)
                                 .vertex_is_constrained_map(fixed)
                                 .protect_constraints(true)
                                 .number_of_relaxation_steps(3));
  } catch (const std::exception&) {
    mesh = std::move(before);
    constrained = mesh.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
    return false;
  }
  mesh.collect_garbage();
  return true;
}

/// Remeshes `mesh` one patch at a time, a patch being the faces reached from each other without
/// crossing a constrained edge, and puts the patches back together at their borders. The result
/// is what remeshing the whole piece gives (the remesher neither moves nor crosses a protected
/// edge), but CGAL computes every vertex's normal in each relaxation step, and at a vertex where
/// faces of many directions meet (a box's corner with a contact fan on it) its normal search
/// tries every pair and triple of those faces against the rest, O(k⁴) for k faces: a chair of
/// 3,000 faces took a second. Within a patch no vertex sees more than one direction's faces.
/// Returns false, with `mesh` untouched, if the patches cannot be cut out or welded back as
/// manifold triangles (a vertex where one patch touches itself at a point); `failed` counts the
/// patches CGAL gave up on (they keep their triangles).
bool remesh_by_patches(SurfaceMesh& mesh, const RemeshParams& params, Constrained& constrained, size_t& failed) {
  using vertex_descriptor = SurfaceMesh::Vertex_index;
  auto patch_of = mesh.add_property_map<face_descriptor, std::size_t>("f:gilt_patch", 0).first;
  const std::size_t count =
      PMP::connected_components(mesh, patch_of, CGAL::parameters::edge_is_constrained_map(constrained));
  std::vector<std::vector<face_descriptor>> patch_faces(count);
  for (face_descriptor f : mesh.faces()) patch_faces[patch_of[f]].push_back(f);
  mesh.remove_property_map(patch_of);

  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<SurfaceMesh> patches(count);
  std::vector<uint32_t> stamp(mesh.number_of_vertices(), kNone);
  std::vector<vertex_descriptor> local(mesh.number_of_vertices());
  for (std::size_t p = 0; p < count; ++p) {
    SurfaceMesh& patch = patches[p];
    auto parent = patch.add_property_map<vertex_descriptor, uint32_t>("v:gilt_parent", kNone).first;
    Constrained marks = patch.add_property_map<edge_descriptor, bool>("e:gilt_constrained", false).first;
    for (face_descriptor f : patch_faces[p]) {
      std::array<vertex_descriptor, 3> corners;
      int k = 0;
      for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
        if (stamp[v.idx()] != p) {
          stamp[v.idx()] = static_cast<uint32_t>(p);
          local[v.idx()] = patch.add_vertex(mesh.point(v));
          parent[local[v.idx()]] = static_cast<uint32_t>(v.idx());
        }
        if (k < 3) corners[k] = local[v.idx()];
        ++k;
      }
      if (k != 3 || patch.add_face(corners[0], corners[1], corners[2]) == SurfaceMesh::null_face()) return false;
    }
    // Constraints inside a patch (a contact line that ends in the open) stay constrained.
    for (face_descriptor f : patch_faces[p])
      for (auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
        if (constrained[mesh.edge(h)]) {
          const auto [ph, found] = CGAL::halfedge(local[mesh.source(h).idx()], local[mesh.target(h).idx()], patch);
          if (found) marks[patch.edge(ph)] = true;
        }
  }

  std::vector<char> ok(count, 1);
  rc::util::parallel_for(count, [&](std::size_t p) {
    SurfaceMesh& patch = patches[p];
    Constrained marks = patch.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
    auto fixed = patch.add_property_map<vertex_descriptor, bool>("v:gilt_fixed", false).first;
    for (vertex_descriptor v : patch.vertices()) fixed[v] = patch.is_border(v, false);
    if (!isotropic_remesh(patch, params, marks, fixed)) ok[p] = 0;
  });
  failed += static_cast<size_t>(std::count(ok.begin(), ok.end(), 0));

  // Weld: a vertex of the piece gets one vertex in the result, whichever patches share it.
  SurfaceMesh out;
  std::vector<vertex_descriptor> welded(mesh.number_of_vertices(), SurfaceMesh::null_vertex());
  std::vector<std::pair<uint32_t, uint32_t>> kept;  // constrained edges, by the result's vertices
  for (std::size_t p = 0; p < count; ++p) {
    const SurfaceMesh& patch = patches[p];
    const auto parent = patch.property_map<vertex_descriptor, uint32_t>("v:gilt_parent").first;
    const auto marks = patch.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
    std::vector<vertex_descriptor> to_out(patch.number_of_vertices());
    for (vertex_descriptor v : patch.vertices()) {
      const uint32_t from = parent[v];
      if (from == kNone) {
        if (patch.is_border(v, false)) return false;  // the remesher moved a border vertex
        to_out[v.idx()] = out.add_vertex(patch.point(v));
      } else if (welded[from] == SurfaceMesh::null_vertex()) {
        to_out[v.idx()] = welded[from] = out.add_vertex(patch.point(v));
      } else {
        if (out.point(welded[from]) != patch.point(v)) return false;
        to_out[v.idx()] = welded[from];
      }
    }
    for (face_descriptor f : patch.faces()) {
      std::array<vertex_descriptor, 3> corners;
      int k = 0;
      for (auto v : CGAL::vertices_around_face(patch.halfedge(f), patch))
        if (k < 3) corners[k++] = to_out[v.idx()];
      if (k != 3 || out.add_face(corners[0], corners[1], corners[2]) == SurfaceMesh::null_face()) return false;
    }
    for (edge_descriptor e : patch.edges())
      if (marks[e]) {
        const auto h = patch.halfedge(e);
        kept.emplace_back(to_out[patch.source(h).idx()].idx(), to_out[patch.target(h).idx()].idx());
      }
  }
  Constrained out_marks = out.add_property_map<edge_descriptor, bool>("e:gilt_constrained", false).first;
  for (const auto& [a, b] : kept) {
    const auto [h, found] = CGAL::halfedge(vertex_descriptor(a), vertex_descriptor(b), out);
    if (found) out_marks[out.edge(h)] = true;
  }
  mesh = std::move(out);
  constrained = mesh.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
  return true;
}

/// Isotropic remeshing to `params.edge_length` with border, sharp and contact edges kept in
/// place: they are cut to at most the target length first, then protected, so the remesher
/// neither moves nor collapses them. The piece is remeshed patch by patch (remesh_by_patches),
/// or whole if it cannot be cut into patches.
/// Faces with collinear corners are cut out first. If CGAL gives up on a piece, the piece keeps
/// its triangles as imprinted (protected edges cut to the target length), and
/// `counts.remesh_failed` says so.
void remesh_part(SurfaceMesh& mesh, const RemeshParams& params, Constrained& constrained, RepairCounts& counts) {
  counts.removed_degenerate += remove_flat_faces(mesh);
  PMP::detect_sharp_edges(mesh, params.sharp_angle_degrees, constrained);
  std::vector<edge_descriptor> protected_edges;
  for (edge_descriptor e : mesh.edges()) {
    if (mesh.is_border(e)) constrained[e] = true;
    if (constrained[e]) protected_edges.push_back(e);
  }
  split_protected_edges(mesh, protected_edges, params.edge_length, constrained);
  size_t failed = 0;
  if (remesh_by_patches(mesh, params, constrained, failed)) {
    if (failed > 0) ++counts.remesh_failed;
    return;
  }
  if (!isotropic_remesh(mesh, params, constrained, CGAL::Constant_property_map<SurfaceMesh::Vertex_index, bool>(false)))
    ++counts.remesh_failed;
}

TriangleSoup to_soup(const SurfaceMesh& mesh, const Constrained* constrained) {
  TriangleSoup soup;
  // A contact line is where light may jump (one side lit, the other under a wall): the vertices
  // on it get a copy for each side (split_sharp_vertices), so that neither side's light is
  // interpolated into the other's elements. (Borders have no other side; creases are cut by angle.)
  if (constrained)
    for (edge_descriptor e : mesh.edges())
      if ((*constrained)[e] && !mesh.is_border(e)) {
        const auto h = mesh.halfedge(e);
        soup.cuts.push_back({static_cast<uint32_t>(mesh.source(h).idx()), static_cast<uint32_t>(mesh.target(h).idx())});
      }
  soup.points.reserve(mesh.number_of_vertices());
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    soup.points.emplace_back(p.x(), p.y(), p.z());
  }
  soup.triangles.reserve(mesh.number_of_faces());
  for (face_descriptor f : mesh.faces()) {
    const auto h = mesh.halfedge(f);
    soup.triangles.push_back({static_cast<uint32_t>(mesh.target(h).idx()),
                              static_cast<uint32_t>(mesh.target(mesh.next(h)).idx()),
                              static_cast<uint32_t>(mesh.target(mesh.next(mesh.next(h))).idx())});
  }
  return soup;
}

/// Appends `piece` to `soup`, renumbering its vertices.
void append_soup(TriangleSoup& soup, const TriangleSoup& piece) {
  const auto offset = static_cast<uint32_t>(soup.points.size());
  soup.points.insert(soup.points.end(), piece.points.begin(), piece.points.end());
  for (const auto& t : piece.triangles) soup.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  for (const auto& c : piece.cuts) soup.cuts.push_back({c[0] + offset, c[1] + offset});
}

}  // namespace

struct RepairedMeshes::Impl {
  std::vector<RepairCounts> counts;       ///< per mesh, what repair() did
  std::vector<std::vector<Part>> parts;   ///< per mesh, its connected pieces (empty until repaired)
  std::vector<std::vector<Part>> imprinted;  ///< per mesh, its pieces imprinted, until remeshed
  /// Per mesh and piece, the pieces that may imprint it, cropped (find_contacts), in order of
  /// (mesh, piece).
  std::vector<std::vector<std::vector<ToolContact>>> contacts;
  /// Per mesh and piece, whether its contact search was cut short by the deadline.
  std::vector<std::vector<char>> searched_in_part;
  std::once_flag contacts_found;

  void find_contacts(rc::util::Progress* progress, std::chrono::steady_clock::time_point deadline);
};

namespace {

using FaceBox = CGAL::Box_intersection_d::Box_with_info_d<double, 3, uint32_t, CGAL::Box_intersection_d::ID_EXPLICIT>;

/// One piece's faces as corner triples (face f is entry f) with their boxes.
struct PieceFaces {
  std::vector<std::array<Point, 3>> corners;
  std::vector<CGAL::Bbox_3> boxes;
};

PieceFaces piece_faces(const SurfaceMesh& mesh) {
  PieceFaces out;
  out.corners.resize(mesh.number_of_faces());
  out.boxes.resize(mesh.number_of_faces());
  for (face_descriptor f : mesh.faces()) {
    std::array<Point, 3>& t = out.corners[f.idx()];
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      if (k < 3) t[k++] = mesh.point(v);
    out.boxes[f.idx()] = t[0].bbox() + t[1].bbox() + t[2].bbox();
  }
  return out;
}

/// Whether the corners of `t` all lie on one side of the plane of `plane`, or all in it: then the
/// two faces meet in no line, and imprint() would skip the pair by the same exact test
/// (imprint.cpp), so leaving it out changes nothing but the time spent on it.
bool one_side(const std::array<Point, 3>& plane, const std::array<Point, 3>& t) {
  const auto s0 = CGAL::orientation(plane[0], plane[1], plane[2], t[0]);
  return s0 == CGAL::orientation(plane[0], plane[1], plane[2], t[1]) &&
         s0 == CGAL::orientation(plane[0], plane[1], plane[2], t[2]);
}

/// Whether the two closed triangles meet (exact), where each crosses the other's plane: a finely
/// cut round table top's fan and its leg's strips cross each other's planes pairwise, nearly all
/// far from the leg, and those pairs grow as the square of the tessellation (a million-triangle
/// room kept 104 million of them, 2.5 GB, and imprinting re-tested each). A triangle with
/// collinear corners is kept: CGAL's test does not take it.
bool faces_meet(const std::array<Point, 3>& s, const std::array<Point, 3>& t) {
  if (one_side(s, t) || one_side(t, s)) return false;
  if (CGAL::collinear(s[0], s[1], s[2]) || CGAL::collinear(t[0], t[1], t[2])) return true;
  return CGAL::do_intersect(Kernel::Triangle_3(s[0], s[1], s[2]), Kernel::Triangle_3(t[0], t[1], t[2]));
}

/// The faces of one piece whose boxes meet `box`, ascending.
std::vector<uint32_t> faces_in_box(const PieceFaces& faces, const CGAL::Bbox_3& box) {
  std::vector<uint32_t> out;
  for (size_t f = 0; f < faces.boxes.size(); ++f)
    if (CGAL::do_overlap(faces.boxes[f], box)) out.push_back(static_cast<uint32_t>(f));
  return out;
}

/// For each of `boxes`, the faces of a piece whose boxes meet it (ascending): one box-intersection
/// pass, O((n + k) log n), so a floor that a thousand chairs stand on is not scanned a thousand
/// times.
std::vector<std::vector<uint32_t>> faces_in_boxes(const PieceFaces& faces, const std::vector<CGAL::Bbox_3>& boxes) {
  std::vector<std::vector<uint32_t>> out(boxes.size());
  if (boxes.size() == 1) {
    out[0] = faces_in_box(faces, boxes[0]);
    return out;
  }
  std::vector<FaceBox> face_boxes, other;
  face_boxes.reserve(faces.boxes.size());
  for (size_t f = 0; f < faces.boxes.size(); ++f) face_boxes.emplace_back(faces.boxes[f], static_cast<uint32_t>(f));
  for (size_t k = 0; k < boxes.size(); ++k) other.emplace_back(boxes[k], static_cast<uint32_t>(k));
  CGAL::box_intersection_d(face_boxes.begin(), face_boxes.end(), other.begin(), other.end(),
                           [&](const FaceBox& f, const FaceBox& b) { out[b.info()].push_back(f.info()); });
  for (auto& list : out) std::sort(list.begin(), list.end());
  return out;
}

/// The pairs (face of a, face of b) that meet, of the faces `fa` of a and `fb` of b.
std::vector<std::array<uint32_t, 2>> meeting_faces(const PieceFaces& a, const std::vector<uint32_t>& fa,
                                                   const PieceFaces& b, const std::vector<uint32_t>& fb) {
  std::vector<std::array<uint32_t, 2>> out;
  std::vector<FaceBox> boxes_a, boxes_b;
  boxes_a.reserve(fa.size());
  boxes_b.reserve(fb.size());
  for (uint32_t f : fa) boxes_a.emplace_back(a.boxes[f], f);
  for (uint32_t f : fb) boxes_b.emplace_back(b.boxes[f], f);
  CGAL::box_intersection_d(boxes_a.begin(), boxes_a.end(), boxes_b.begin(), boxes_b.end(),
                           [&](const FaceBox& x, const FaceBox& y) {
                             if (faces_meet(a.corners[x.info()], b.corners[y.info()])) out.push_back({x.info(), y.info()});
                           });
  return out;
}

}  // namespace

/// Finds, for every piece of every repaired mesh, the faces of other pieces that meet its own
/// faces, in three passes, each O((n + k) log n) for n faces and k meeting pairs (Zomorodian &
/// Edelsbrunner's streamed segment tree, CGAL's box_intersection_d), where testing every piece
/// against every other costs the product of their sizes:
///   1. pairs of pieces whose boxes meet;
///   2. per piece, in parallel, its faces inside each such neighbour's box (the crop);
///   3. per pair of pieces, in parallel, the cropped faces of the two whose boxes meet, kept where
///      the closed triangles meet (faces_meet).
/// Pieces of one mesh of more than kMaxImprintedParts pieces (foliage, gravel) do not imprint each
/// other. Boxes are closed, so faces that only touch are found. Every list is sorted by its
/// indices (mesh, piece, face), so the result does not depend on memory addresses or the thread
/// count. Piece pairs are searched largest first; those not begun by `deadline` are left out, and
/// their pieces marked as searched only in part.
void RepairedMeshes::Impl::find_contacts(rc::util::Progress* progress, std::chrono::steady_clock::time_point deadline) {
  // Pieces numbered in (mesh, piece) order.
  std::vector<std::array<uint32_t, 2>> pieces;
  for (size_t m = 0; m < parts.size(); ++m)
    for (size_t p = 0; p < parts[m].size(); ++p) pieces.push_back({uint32_t(m), uint32_t(p)});
  const auto part = [&](uint32_t i) -> const Part& { return parts[pieces[i][0]][pieces[i][1]]; };
  std::vector<PieceFaces> faces(pieces.size());
  rc::util::parallel_for(pieces.size(), [&](size_t i) { faces[i] = piece_faces(part(uint32_t(i)).mesh); });

  // 1. Pieces whose boxes meet.
  std::vector<FaceBox> piece_boxes;
  for (size_t i = 0; i < pieces.size(); ++i)
    if (!faces[i].boxes.empty()) piece_boxes.emplace_back(part(uint32_t(i)).box, static_cast<uint32_t>(i));
  std::vector<std::array<uint32_t, 2>> pairs;
  CGAL::box_self_intersection_d(piece_boxes.begin(), piece_boxes.end(), [&](const FaceBox& x, const FaceBox& y) {
    const uint32_t i = std::min(x.info(), y.info()), j = std::max(x.info(), y.info());
    if (pieces[i][0] == pieces[j][0] && parts[pieces[i][0]].size() > kMaxImprintedParts) return;
    pairs.push_back({i, j});
  });
  std::sort(pairs.begin(), pairs.end());

  // 2. Each piece's faces inside each neighbour's box, neighbours in the order of `pairs`.
  std::vector<std::vector<uint32_t>> neighbours(pieces.size());
  for (const auto& [i, j] : pairs) neighbours[i].push_back(j), neighbours[j].push_back(i);
  std::vector<std::vector<std::vector<uint32_t>>> crop(pieces.size());
  rc::util::parallel_for(pieces.size(), [&](size_t i) {
    std::vector<CGAL::Bbox_3> boxes;
    for (uint32_t j : neighbours[i]) boxes.push_back(part(j).box);
    if (!boxes.empty()) crop[i] = faces_in_boxes(faces[i], boxes);
  });
  // Where each pair's crops sit: pair (i, j) is neighbour k of i and neighbour l of j.
  std::vector<std::array<uint32_t, 2>> slot(pairs.size());
  {
    std::vector<uint32_t> next(pieces.size(), 0);
    for (size_t q = 0; q < pairs.size(); ++q) slot[q] = {next[pairs[q][0]]++, next[pairs[q][1]]++};
  }

  // 3. Meeting faces per pair, the pairs with the most cropped faces begun first.
  std::vector<size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  const auto cropped = [&](size_t q) {
    return crop[pairs[q][0]][slot[q][0]].size() + crop[pairs[q][1]][slot[q][1]].size();
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return cropped(x) > cropped(y); });
  std::vector<std::vector<std::array<uint32_t, 2>>> met(pairs.size());
  std::vector<char> skipped(pairs.size(), 0);
  if (progress) progress->set_total(pairs.size());
  rc::util::parallel_for(order.size(), [&](size_t k) {
    const size_t q = order[k];
    const auto [i, j] = pairs[q];
    if (std::chrono::steady_clock::now() >= deadline) {
      skipped[q] = 1;
    } else {
      met[q] = meeting_faces(faces[i], crop[i][slot[q][0]], faces[j], crop[j][slot[q][1]]);
      crop[i][slot[q][0]] = {};
      crop[j][slot[q][1]] = {};
    }
    if (progress) progress->advance(1);
  });
  faces = {};
  crop = {};

  // Per receiving piece, its (tool mesh, piece, face, own face) quadruples, both ways round; each
  // piece's list is sorted on its own, in parallel, so no list of every pair is ever sorted.
  std::vector<std::vector<std::array<uint32_t, 4>>> found(pieces.size());
  searched_in_part.assign(parts.size(), {});
  for (size_t m = 0; m < parts.size(); ++m) searched_in_part[m].assign(parts[m].size(), 0);
  for (size_t q = 0; q < pairs.size(); ++q) {
    const auto [i, j] = pairs[q];
    if (skipped[q]) {
      searched_in_part[pieces[i][0]][pieces[i][1]] = searched_in_part[pieces[j][0]][pieces[j][1]] = 1;
      continue;
    }
    for (const auto& [fi, fj] : met[q]) {
      found[i].push_back({pieces[j][0], pieces[j][1], fj, fi});
      found[j].push_back({pieces[i][0], pieces[i][1], fi, fj});
    }
    met[q] = {};
  }
  contacts.assign(parts.size(), {});
  for (size_t m = 0; m < parts.size(); ++m) contacts[m].resize(parts[m].size());
  rc::util::parallel_for(found.size(), [&](size_t i) {
    std::vector<std::array<uint32_t, 4>>& tools = found[i];
    std::sort(tools.begin(), tools.end());
    std::vector<ToolContact>& list = contacts[pieces[i][0]][pieces[i][1]];
    for (const auto& [tm, tp, tf, own] : tools) {
      if (list.empty() || list.back().mesh != tm || list.back().part != tp) list.push_back({tm, tp, {}, {}});
      ToolContact& c = list.back();
      if (c.faces.empty() || c.faces.back() != tf) c.faces.push_back(tf);
      c.pairs.push_back({own, static_cast<uint32_t>(c.faces.size() - 1)});
    }
    for (ToolContact& c : list) std::sort(c.pairs.begin(), c.pairs.end());
    tools = {};
  });
}

RepairedMeshes::RepairedMeshes(size_t mesh_count) : impl_(std::make_unique<Impl>()) {
  impl_->counts.resize(mesh_count);
  impl_->parts.resize(mesh_count);
  impl_->imprinted.resize(mesh_count);
}

RepairedMeshes::~RepairedMeshes() = default;

void RepairedMeshes::find_contacts(rc::util::Progress* progress,
                                   std::chrono::steady_clock::time_point deadline) {
  std::call_once(impl_->contacts_found, [&] { impl_->find_contacts(progress, deadline); });
}

void RepairedMeshes::repair(size_t m, const rc::scene::TriangleMesh& mesh, std::chrono::steady_clock::time_point deadline) {
  const SurfaceMesh repaired = detail::repair(mesh, impl_->counts[m]);
  if (repaired.number_of_faces() > 0) impl_->parts[m] = split_parts(repaired, deadline);
}

TriangleSoup RepairedMeshes::imprint(size_t m, std::span<const size_t> touching, RepairCounts* counts,
                                     rc::util::Progress* progress,
                                     std::chrono::steady_clock::time_point deadline) {
  RepairCounts local;
  RepairCounts& c = counts ? *counts : local;
  c = impl_->counts[m];
  find_contacts();
  const std::vector<Part>& own = impl_->parts[m];
  std::vector<Part>& imprinted = impl_->imprinted[m];
  imprinted.assign(own.begin(), own.end());  // the shared copies stay as they are, tools for the others
  // Pieces are imprinted in parallel, each reading only the shared copies; the soup is put
  // together in piece order, so it does not depend on the thread count.
  std::vector<TriangleSoup> soups(own.size());
  std::vector<RepairCounts> piece_counts(own.size());
  // Only the meshes this one touches lend tools (every contact lies within them, but a caller
  // may ask for fewer).
  std::vector<std::vector<std::pair<const Part*, const ToolContact*>>> tools(own.size());
  std::vector<std::pair<size_t, size_t>> order;  // (contact faces, piece), most first
  for (size_t i = 0; i < own.size(); ++i) {
    size_t faces = 0;
    for (const ToolContact& contact : impl_->contacts[m][i]) {
      if (contact.mesh != m && std::find(touching.begin(), touching.end(), contact.mesh) == touching.end()) continue;
      tools[i].emplace_back(&impl_->parts[contact.mesh][contact.part], &contact);
      faces += contact.faces.size();
    }
    order.emplace_back(faces, i);
    // A piece whose contact search ran out of time keeps what was found, and is counted.
    if (impl_->searched_in_part[m][i]) ++piece_counts[i].not_imprinted;
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  rc::util::parallel_for(order.size(), [&](size_t k) {
    const size_t i = order[k].second;
    Part& part = imprinted[i];
    auto constrained = part.mesh.add_property_map<edge_descriptor, bool>("e:gilt_constrained", false).first;
    if (!tools[i].empty() && std::chrono::steady_clock::now() >= deadline) {
      // Out of time: the piece keeps its input triangles, remeshed without contact lines.
      piece_counts[i].not_imprinted = 1;
      soups[i] = to_soup(part.mesh);
      if (progress) progress->advance(part.mesh.number_of_faces());
      return;
    }
    std::vector<std::array<double, 3>> input;
    for (auto v : part.mesh.vertices()) {
      const Point& p = part.mesh.point(v);
      input.push_back({p.x(), p.y(), p.z()});
    }
    std::sort(input.begin(), input.end());
    const size_t faces = part.mesh.number_of_faces();
    RepairCounts& pc = piece_counts[i];
    pc.contact_edges += imprint_contacts(part, tools[i], constrained, pc);
    if (part.mesh.number_of_faces() != faces) {
      snap_new_points(part.mesh, input);
      canonicalize(part.mesh, constrained);
    }
    if (part.mesh.has_garbage()) part.mesh.collect_garbage();  // face f is soup triangle f
    soups[i] = to_soup(part.mesh);
    if (progress) progress->advance(faces);
  });
  TriangleSoup soup;
  for (size_t i = 0; i < own.size(); ++i) {
    c.self_intersecting += own[i].self_intersecting;
    c.self_intersections_uncounted += !own[i].counted;
    c.contact_edges += piece_counts[i].contact_edges;
    c.contacts_failed += piece_counts[i].contacts_failed;
    c.contact_segments_lost += piece_counts[i].contact_segments_lost;
    c.not_imprinted += piece_counts[i].not_imprinted;
    append_soup(soup, soups[i]);
  }
  return soup;
}

TriangleSoup RepairedMeshes::remesh(size_t m, const std::vector<char>& remove, const RemeshParams& params,
                                    RepairCounts* counts, rc::util::Progress* progress,
                                    std::chrono::steady_clock::time_point deadline) {
  RepairCounts local;
  RepairCounts& c = counts ? *counts : local;
  std::vector<Part> imprinted = std::move(impl_->imprinted[m]);
  // Pieces are remeshed in parallel (a furnished room's furniture is one mesh of thousands), and
  // put together in piece order, so the result does not depend on the thread count.
  std::vector<size_t> first(imprinted.size() + 1, 0);  // index in `remove` of each piece's first face
  for (size_t i = 0; i < imprinted.size(); ++i) first[i + 1] = first[i] + imprinted[i].mesh.number_of_faces();
  std::vector<TriangleSoup> soups(imprinted.size());
  std::vector<RepairCounts> piece_counts(imprinted.size());
  rc::util::parallel_for(imprinted.size(), [&](size_t i) {
    SurfaceMesh& mesh = imprinted[i].mesh;
    const size_t faces = mesh.number_of_faces();
    std::vector<face_descriptor> removed;
    for (face_descriptor f : mesh.faces())
      if (first[i] + f.idx() < remove.size() && remove[first[i] + f.idx()]) removed.push_back(f);
    for (face_descriptor f : removed) CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
    if (!removed.empty()) mesh.collect_garbage();
    if (mesh.number_of_faces() > 0) {
      Constrained constrained = mesh.property_map<edge_descriptor, bool>("e:gilt_constrained").first;
      if (std::chrono::steady_clock::now() < deadline) {
        remesh_part(mesh, params, constrained, piece_counts[i]);
      } else {
        // Out of time: the piece keeps its imprinted triangles, as one CGAL cannot remesh does.
        piece_counts[i].removed_degenerate += remove_flat_faces(mesh);
        ++piece_counts[i].not_remeshed;
      }
      soups[i] = to_soup(mesh, &constrained);
    }
    mesh = SurfaceMesh();  // freed as soon as it is copied out
    if (progress) progress->advance(faces);
  });
  TriangleSoup soup;
  for (size_t i = 0; i < imprinted.size(); ++i) {
    c.removed_degenerate += piece_counts[i].removed_degenerate;
    c.remesh_failed += piece_counts[i].remesh_failed;
    c.not_remeshed += piece_counts[i].not_remeshed;
    append_soup(soup, soups[i]);
  }
  return soup;
}

}  // namespace gilt::radiosity::mesh::detail
