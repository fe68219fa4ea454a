// Gathering in the hierarchical solver (see tree_walk.h): packing the source nodes for a gather
// over the links, and the walk down the tree that gathers at one vertex. Reads the tree, the
// nodes' sums and the scene; writes the packed sources and the irradiance it returns.

#include "radiosity/solver/tree_walk.h"

#include "radiosity/solver/cluster_kernel.h"
#include "radiosity/solver/probe_fraction.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::radiosity::solver::detail {

void PackedSources::pack(const Tree& tree, std::span<const Rgb> power, std::span<const Moments> moment) {
  const size_t n = tree.nodes.size();
  nodes.resize(n + 1);
  bins.clear();
  for (size_t i = 0; i < n; ++i) {
    nodes[i] = {tree.nodes[i].center, uint32_t(bins.size()), power[i], tree.nodes[i].area};
    for (const RgbVec& b : moment[i].bins)
      if (b.c[0] != Vec3(0.0f) || b.c[1] != Vec3(0.0f) || b.c[2] != Vec3(0.0f)) bins.push_back(b);
  }
  nodes[n] = {Vec3(0.0f), uint32_t(bins.size()), Rgb(0.0f), 0.0f};
}

Rgb TreeWalk::irradiance(size_t v, double epsilon, int rays, rc::util::Rng& rng, std::vector<uint32_t>& stack,
                         WalkCounts& counts) const {
  const RadiosityMesh& mesh = in.mesh;
  const Vec3 p = in.vertex_point[v].p, n = mesh.normals[v];
  Rgb sum(0.0f);
  stack.assign(1, 0u);
  while (!stack.empty()) {
    const uint32_t s = stack.back();
    stack.pop_back();
    const Node& S = tree.nodes[s];
    ++counts.nodes;
    if (!(power[s].average() > 0.0f) || sends_nothing(S, p, n)) continue;
    Rgb value(0.0f);
    if (S.leaf()) {
      ++counts.form_factors;
      const uint32_t e = tree.element(S);
      const float f = float(tree.triangles[e].form_factor(p, n));
      if (!(f > 0.0f)) continue;
      value = radiosity[e] * f;
    } else {
      const Vec3 d = S.center - p;
      const float dist = glm::length(d), gap = dist - S.radius;
      bool accept = false;
      if (gap > 0.0f) {
        const double bound = std::min(1.0, double(S.area) / (double(kPi) * gap * gap));
        double error = bound * power[s].average() / S.area;
        if (facing(S, -d / dist) == Facing::front)
          error *= std::min(1.0, std::pow(double(S.radius) / gap, 2.0));
        accept = error <= epsilon;
      }
      if (!accept) {
        stack.push_back(S.right);
        stack.push_back(s + 1);
        continue;
      }
      const float cos_receiver = glm::dot(n, d) / dist;
      if (!(cos_receiver > 0.0f)) continue;
      // The kernel averaged over the source's extent (cluster_kernel_scale), the receiver a point.
      const Vec3 n_s = facing(S, -d / dist) == Facing::front ? S.normal : -d / dist;
      const float scale = cluster_kernel_scale(d, n, n_s, S.covariance);
      value = intensity(moment[s], -d / dist) * (cos_receiver * scale / (dist * dist));
    }
    rc::Bounds3 reach = S.box;
    reach.extend(p);
    if (in.may_be_blocked(reach)) {
      const Vec3 omega = glm::normalize(p - S.center);
      auto sends = [&](uint32_t c) {
        const RgbVec m = moment[c].total();
        return towards(tree.nodes[c], power[c].average(), (m.c[0] + m.c[1] + m.c[2]) * (1.0f / 3.0f), omega);
      };
      auto open = [&](int count) {
        int hits = 0;
        // The vertex's visibility origins in turn, from a random one.
        const size_t first = size_t(rng.uniform() * float(kVisibilityOrigins));
        for (int i = 0; i < count; ++i) {
          const rc::scene::SurfacePoint& at =
              in.visibility_origin[kVisibilityOrigins * v + (first + size_t(i)) % kVisibilityOrigins];
          hits +=
              !in.geometry.occluded(rc::scene::spawn_shadow_ray(at, sample_point(tree, mesh, s, sends, rng)));
        }
        counts.rays += uint64_t(count);
        return hits;
      };
      const int probe = std::min(rays, 4);
      const int probe_hits = open(probe);
      if (probe_hits == 0) continue;
      float visible = float(probe_hits) / float(probe);
      if (probe_hits < probe && rays > probe)
        visible = float(extended_fraction(probe_hits + open(rays - probe), rays, probe));
      value = value * visible;
    }
    sum += value;
  }
  return sum;
}

}  // namespace gilt::radiosity::solver::detail
