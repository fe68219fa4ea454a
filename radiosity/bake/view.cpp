// Displays of a radiosity solution: the elements as exported (Wallace, Cohen & Greenberg 1987),
// or the two-pass split of Chen, Rushmeier, Miller & Turner 1991, "A Progressive Multi-Pass
// Method for Global Illumination": at each visible point of the input, direct light by a shadow
// ray and the light reflected by other surfaces from the solution there, or, where no element
// stands for the point, by a final-gather ray that reads the solution where it lands
// (Lischinski, Tampieri & Greenberg 1993 gather at vertices; this at pixels). Specular paths
// are ray traced.

#include "radiosity/bake/view.h"

#include <algorithm>
#include <cmath>

#include "radiosity/mesh/element_scene.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/render/direct_light.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::bake {

using mesh::RadiosityMesh;
using mesh::element_scene;
using solver::FinalGather;
using solver::Solution;
using solver::SolverSettings;

SolverSettings solver_settings_for(ViewMode mode, SolverSettings settings) {
  settings.gather_ambient = true;  // both views show a partial solution's ambient term
  if (mode == ViewMode::two_pass) {
    settings.subdivision_levels = 0;
    settings.hierarchical.final_gather = FinalGather::never;
    if (!(settings.hierarchical.link_tolerance > 0.0)) settings.hierarchical.link_tolerance = kTwoPassLinkTolerance;
    if (!(settings.hierarchical.receiver_share > 0.0))
      settings.hierarchical.receiver_share = kTwoPassReceiverShare;
  }
  return settings;
}

namespace {

/// Beer–Lambert attenuation of the segment `ray` travelled inside a dielectric to reach `si`.
void absorb(const rc::scene::Material& m, const rc::scene::SurfaceInteraction& si, const rc::scene::Hit& hit,
            const rc::scene::Ray& ray, Rgb& beta) {
  if (m.kind == rc::scene::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
    beta *= rc::exp(m.absorption * (-hit.t * glm::length(ray.direction)));
}

/// Continues a path through the mirror or glass at si (outgoing direction wo in `frame`):
/// multiplies beta by the sample's weight and replaces `ray`. False when the path ends there.
bool scatter_specular(const rc::scene::Material& m, const rc::scene::SurfaceInteraction& si, const rc::Frame& frame, const Vec3& wo,
                      rc::render::Sampler& sampler, Rgb& beta, rc::scene::Ray& ray) {
  const float u_lobe = sampler.uniform();
  const auto bs = rc::scene::bsdf_sample(m, wo, u_lobe, sampler.uniform2());
  if (!bs || !(bs->pdf > 0.0f)) return false;
  beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf);
  ray = rc::scene::continue_ray(si, frame.to_world(bs->wi));
  return true;
}

}  // namespace

/// How far from an element, as a fraction of the view's reach (twice the target edge), a point of
/// a curved surface it is a chord of may lie: behind it on a concave surface, in front of it on a
/// convex one (see locate_on).
constexpr float kChordDepth = 0.035f;
/// The sagitta of a chord over 30° of arc, (1 − cos 15°) / (2 sin 15°), over the chord's length.
constexpr float kChordSagitta = 0.066f;
/// Diffuse bounces a gather ray takes past surfaces that have no element on the side it meets
/// (the backs of one-sided surfaces, which the solution leaves out).
constexpr int kUnmeshedBounces = 2;
/// A gather ray that lands closer than this many times its element's longest edge is a near hit
/// (see gather). Under a slab 5 cm above the floor (tests/unit/test_radiosity_view.cpp) the
/// gather finds 1.6 times the path tracer's irradiance when it reads every hit, 1.2 times with
/// near hits within one edge, 1.08 within two and 1.04 within four; four added noise to
/// Šibenik's 8-ray vertex bake (mean relative error 25.3 % → 27.3 %).
constexpr float kNearHit = 2.0f;
/// Diffuse bounces a gather ray takes past near hits before it reads the solution at one anyway.
constexpr int kNearBounces = 8;

/// cos 60°: an element lit on the same side as the input point faces within 60° of it (the
/// mesher splits vertices at sharper creases, so a steeper element belongs to another side).
constexpr float kFacing = 0.5f;

RadiosityView::RadiosityView(const rc::scene::Scene& scene, const Solution& solution, ViewMode mode,
                             bool ambient)
    : scene_(scene), mode_(mode), elements_(solution.mesh.elements) {
  const RadiosityMesh& mesh = solution.mesh;
  const size_t nv = mesh.vertex_count();
  vertex_radiance_.resize(nv);
  vertex_indirect_.resize(nv);
  for (size_t v = 0; v < nv; ++v) {
    const Rgb rho = v < solution.vertex_albedo.size() ? solution.vertex_albedo[v] : rc::scene::diffuse_reflectance(scene.materials[mesh.vertex_material[v]]);
    vertex_radiance_[v] = solution.vertex_radiance(v);
    const Rgb ambient_irradiance =
        !ambient ? Rgb(0.0f)
                 : (v < solution.vertex_ambient.size() ? solution.vertex_ambient[v] : solution.ambient);
    vertex_radiance_[v] += rho * ambient_irradiance * (1.0f / rc::kPi);
    Rgb indirect = solution.vertex_irradiance[v] - solution.vertex_direct[v];
    for (int k = 0; k < 3; ++k) indirect[k] = std::max(0.0f, indirect[k]);
    vertex_indirect_[v] = indirect + ambient_irradiance;
    // Overshooting leaves some unshot light negative, and the ambient term with it: where little
    // light arrives, a vertex would read below zero (the outward-wound atrium's mesh view had 4 %
    // of its pixel values negative). Light is never negative.
    for (int k = 0; k < 3; ++k) {
      vertex_radiance_[v][k] = std::max(0.0f, vertex_radiance_[v][k]);
      vertex_indirect_[v][k] = std::max(0.0f, vertex_indirect_[v][k]);
    }
  }
  positions_ = mesh.positions;
  element_direct_ = solution.element_direct;
  sky_by_gather_ = rc::render::sky_left_to_bsdf_sampling(scene);
  for (const rc::scene::Light& l : scene.lights())
    if (rc::scene::is_constant_environment(l)) constant_sky_ += l.radiance;
  has_specular_ = std::any_of(scene.materials.begin(), scene.materials.end(),
                              [](const rc::scene::Material& m) { return m.is_traced_through(); });
  // An input point lies within about an element's size of the element that stands for it
  // (elements are chords of a curved input); twice the target edge leaves room for bisection
  // and for input faces kept as they were.
  reach_ = 2.0f * std::max(solution.mesh_report.max_edge, 1e-6f * glm::length(scene.bounds().diagonal()));

  // Geometry 0: every element; then the scene's specular meshes and spheres.
  display_ = element_scene(scene, mesh);
}

Rgb RadiosityView::radiance(const rc::scene::Ray& ray, rc::render::SampleContext& ctx) const {
  return mode_ == ViewMode::mesh ? mesh_radiance(ray, ctx) : two_pass_radiance(ray, ctx);
}

std::optional<RadiosityView::Location> RadiosityView::locate(const Vec3& p, const Vec3& n) const {
  const std::optional<rc::scene::Hit> near = display_.nearest_triangle(0, p, reach_, n, kFacing);
  if (!near) return std::nullopt;
  return Location{near->prim_id, near->u, near->v, near->t};
}

std::optional<RadiosityView::Location> RadiosityView::locate_on(const rc::scene::SurfacePoint& p, const Vec3& n) const {
  const std::optional<Location> at = locate(p.p, n);
  if (!at) return std::nullopt;
  // Off the element, p may lie on a curved surface that the element is a chord of, or on another
  // surface entirely: the far side of a wall or slab whose near side has no element, or the
  // inside of an open shell (a scan's holes let rays in) facing the same way as an element on
  // the shell's other side or the floor under it. A chord spans at most the sharp angle (30°) of
  // arc, so a curved surface lies behind or in front of it by at most (1 − cos 15°) / (2 sin 15°)
  // ≈ 0.066 of its length, and over it: p farther from the element than that is not on it.
  // (Bounding the front too took the bunny's vertex gather from 10.5 % to 7.3 % mean relative
  // error: gather rays that entered the open base had read the lit floor and flanks. Bounding the
  // distance, not only the height over the element's plane, keeps a ray inside a solid column
  // base on Šibenik's floor, which hit the back of its moulding, from reading an element of the
  // column's lit outside half a metre away whose plane passed 4 cm from the hit.)
  if (at->distance > kChordDepth * reach_) return std::nullopt;
  // Seen from behind the input face (n against its normal), p lies on the face's unmeshed back
  // unless an element of a face turned the other way lies on it: the other half of a two-sided
  // sheet, or the face itself where the mesher reoriented it. That element is a chord over p, so
  // it lies within the sagitta of its own size, not of the target edge's. In carved stone the
  // looser bound let rays that entered a moulding from behind read small elements of the lit face
  // outside, many times their own size away: a checked vertex of Šibenik's (its disk 3.5 mm in
  // radius) read 2.7 times the path tracer's irradiance.
  if (glm::dot(n, p.ng) < 0.0f && at->distance > kChordSagitta * longest_edge(at->element)) return std::nullopt;
  return at;
}

float RadiosityView::longest_edge(uint32_t element) const {
  const auto& e = elements_[element];
  return std::max({glm::distance(positions_[e[0]], positions_[e[1]]), glm::distance(positions_[e[1]], positions_[e[2]]),
                   glm::distance(positions_[e[2]], positions_[e[0]])});
}

bool RadiosityView::near_hit(const Location& at, float distance) const {
  return distance < kNearHit * longest_edge(at.element);
}

Rgb RadiosityView::indirect_at(const Location& at) const {
  const auto& e = elements_[at.element];
  return vertex_indirect_[e[0]] * (1.0f - at.u - at.v) + vertex_indirect_[e[1]] * at.u + vertex_indirect_[e[2]] * at.v;
}

std::optional<Rgb> RadiosityView::indirect_irradiance(const rc::scene::SurfacePoint& p, const Vec3& n) const {
  const std::optional<Location> at = locate_on(p, n);
  if (!at) return std::nullopt;
  return indirect_at(*at);
}

Rgb RadiosityView::gathered_irradiance(const rc::scene::SurfacePoint& p, int rays,
                                       rc::render::SampleContext& ctx) const {
  Rgb sum(0.0f);
  // The rays are sub-samples of the point's sample: with the Sobol sampler, their shadow rays'
  // points on each light and their gather directions are each a stratified set.
  const rc::render::Sampler::SubSamples samples = ctx.sampler.split(uint32_t(std::max(rays, 1)));
  for (int r = 0; r < rays; ++r) {
    rc::render::SampleContext sub{samples[uint32_t(r)], 0};
    sum += gathered_sample(p, sub);
    ctx.rays += sub.rays;
  }
  return sum / float(std::max(rays, 1));
}

Rgb RadiosityView::gathered_sample(const rc::scene::SurfacePoint& p, rc::render::SampleContext& ctx) const {
  // A white Lambertian stands in for the surface: π times its reflected radiance is irradiance.
  static const rc::scene::Material white = rc::scene::Material::make_diffuse("irradiance probe", Rgb(1.0f));
  rc::scene::SurfaceInteraction si;
  static_cast<rc::scene::SurfacePoint&>(si) = p;
  si.ns = p.ng;
  const rc::Frame frame = rc::Frame::from_normal(p.ng);
  const Vec3 wo(0.0f, 0.0f, 1.0f);
  // A uniform sky comes by the gather ray when it escapes, rather than by a shadow ray of its own
  // (sky_left_to_bsdf_sampling): exact where the sky is open, and one ray fewer.
  return rc::render::estimate_direct(scene_, si, white, frame, wo, true, ctx.sampler, ctx.rays, !sky_by_gather_) * rc::kPi +
         gather(si, frame, true, ctx, false, sky_by_gather_);
}

Rgb RadiosityView::gather(const rc::scene::SurfaceInteraction& si, const rc::Frame& frame, bool wo_above,
                          rc::render::SampleContext& ctx, bool via_specular_only, bool sky_on_escape) const {
  // One cosine-distributed ray on the lit side: its estimate of the irradiance is the radiance
  // it finds times π.
  const Vec3 side = wo_above ? si.ng : -si.ng;
  Vec3 wi = frame.to_world(rc::util::sample_cosine_hemisphere(ctx.sampler.uniform2()));
  if (!wo_above) wi = -wi;                            // the frame's z is the front's shading normal
  if (glm::dot(wi, side) <= 0.0f) return Rgb(0.0f);  // the shading normal leans the ray through the surface
  Rgb beta(rc::kPi), out(0.0f);
  rc::scene::Ray ray = rc::scene::continue_ray(si, wi);
  // Emitters and the sky are next-event estimation's after a diffuse bounce; through glass or a
  // mirror, shadow rays cannot see them, and the ray is their only way in.
  bool via_specular = false;
  int diffuse_left = kUnmeshedBounces;
  int near_left = kNearBounces;
  for (int depth = 0; depth < 64; ++depth) {
    ++ctx.rays;
    const std::optional<rc::scene::Hit> hit = scene_.intersect(ray);
    if (!hit) {
      if (via_specular) return out + beta * rc::scene::escaped_radiance(scene_.punctual_lights, glm::normalize(ray.direction));
      return depth == 0 && sky_on_escape ? out + beta * constant_sky_ : out;
    }
    const rc::scene::SurfaceInteraction sj = scene_.surface(ray, *hit);
    rc::scene::Material textured;
    const rc::scene::Material& mj = scene_.shading_material(sj, textured);
    const Vec3 wo_world = -glm::normalize(ray.direction);
    absorb(mj, sj, *hit, ray, beta);
    if (via_specular && mj.is_emissive()) out += beta * rc::scene::emitted_radiance(mj, sj.ng, wo_world);
    const rc::Frame fj = rc::Frame::from_normal(sj.ns);
    const Vec3 wo = fj.to_local(wo_world);
    if (depth == 0 && via_specular_only && !mj.is_traced_through()) return Rgb(0.0f);
    if (!mj.is_traced_through()) {
      // Direct light: the element's own mean where the solution has it (hierarchical), else by a
      // shadow ray, as at the camera's point. Not the vertices' direct light interpolated:
      // across an element that a shadow edge crosses their mean may be anything from none of it
      // to all of it, and on Šibenik's nave (elements as large as the input's triangles) reading
      // it there made the sunlight's first bounce 1.45 times too bright. The element's mean
      // spreads a sun patch over its element but keeps its power, and one bounce away from the
      // camera that is what counts; a shadow ray there would add the noise of finding the patch.
      //
      // Near hits are the exception, as in photon mapping's final gather, which traces on from
      // hits close to its origin rather than reading the map there (Jensen 2001): closer than
      // about twice its size, an element fills so much of the point's view that the rays land
      // in one part of it, and the solution stands for that part only as well as the mesh
      // resolves the light there. In a contact shadow or a crevice the coarse solution is
      // brightest exactly there (a bunny's rim on the floor read 0.07 where the path tracer finds
      // 0.009), so a near hit takes its direct light by a shadow ray and its reflected light by
      // one more diffuse bounce, up to kNearBounces of them. On the bunny under sun and sky
      // (`--onto input --fit point --bake-gather 256`) the relMSE fell from 0.27 to 0.012, in
      // twice the gather's time; on Šibenik's 8-ray vertex bake from 0.98 to 0.91.
      const bool above = glm::dot(wo_world, sj.ng) > 0.0f;
      const Vec3 lit = above ? sj.ng : -sj.ng;
      const std::optional<Location> at = locate_on(sj, lit);
      const bool near = at && near_hit(*at, hit->t * glm::length(ray.direction));
      if (at && !near && !element_direct_.empty())
        return out + beta * rc::scene::diffuse_reflectance(mj) * (element_direct_[at->element] + indirect_at(*at)) * (1.0f / rc::kPi);
      out += beta * rc::render::estimate_direct(scene_, sj, mj, fj, wo, above, ctx.sampler, ctx.rays);
      if (at && !(near && near_left-- > 0))
        return out + beta * rc::scene::diffuse_reflectance(mj) * indirect_at(*at) * (1.0f / rc::kPi);
      // A near hit, or no element stands for this side of the surface: one more diffuse bounce.
      if (!at && diffuse_left-- == 0) return out;
      Vec3 next = fj.to_world(rc::util::sample_cosine_hemisphere(ctx.sampler.uniform2()));
      if (!above) next = -next;
      if (glm::dot(next, lit) <= 0.0f) return out;
      beta *= rc::scene::diffuse_reflectance(mj);  // Lambertian: f cos / pdf
      ray = rc::scene::continue_ray(sj, next);
      via_specular = false;
      continue;
    }
    if (!scatter_specular(mj, sj, fj, wo, ctx.sampler, beta, ray)) return out;
    via_specular = true;
  }
  return out;
}

Rgb RadiosityView::mesh_radiance(const rc::scene::Ray& camera_ray, rc::render::SampleContext& ctx) const {
  Rgb beta(1.0f);
  rc::scene::Ray ray = camera_ray;
  for (int depth = 0; depth < 64; ++depth) {
    ctx.sampler.start_bounce(depth);
    ++ctx.rays;
    const std::optional<rc::scene::Hit> hit = display_.intersect(ray);
    if (!hit)
      return beta * rc::scene::escaped_radiance(scene_.punctual_lights, glm::normalize(ray.direction));
    const rc::scene::SurfaceInteraction si = display_.surface(ray, *hit);
    if (hit->geom_id == 0) {
      // Radiosity is solved for the element fronts; a back is part of the answer only where an
      // element facing the other way lies on it (a twin, where light reaches both sides, or the
      // other sheet of a surface modelled as two back to back), which the ray may have met in
      // its place.
      Location at{hit->prim_id, hit->u, hit->v, 0.0f};
      if (!si.front_face) {
        const std::optional<Location> behind = locate_on(si, -si.ng);
        if (!behind) return Rgb(0.0f);
        at = *behind;
      }
      const auto& e = elements_[at.element];
      const Rgb l = vertex_radiance_[e[0]] * (1.0f - at.u - at.v) + vertex_radiance_[e[1]] * at.u +
                    vertex_radiance_[e[2]] * at.v;
      return beta * l;
    }
    const rc::scene::Material& m = display_.materials[si.material];
    absorb(m, si, *hit, ray, beta);
    const rc::Frame frame = rc::Frame::from_normal(si.ns);
    if (!scatter_specular(m, si, frame, frame.to_local(-glm::normalize(ray.direction)), ctx.sampler, beta, ray))
      return Rgb(0.0f);
  }
  return Rgb(0.0f);
}

Rgb RadiosityView::two_pass_radiance(const rc::scene::Ray& camera_ray, rc::render::SampleContext& ctx) const {
  Rgb radiance(0.0f), beta(1.0f);
  rc::scene::Ray ray = camera_ray;
  for (int depth = 0; depth < 64; ++depth) {
    ctx.sampler.start_bounce(depth);
    ++ctx.rays;
    const std::optional<rc::scene::Hit> hit = scene_.intersect(ray);
    if (!hit) return radiance + beta * rc::scene::escaped_radiance(scene_.punctual_lights, glm::normalize(ray.direction));
    const rc::scene::SurfaceInteraction si = scene_.surface(ray, *hit);
    rc::scene::Material textured;
    const rc::scene::Material& m = scene_.shading_material(si, textured);
    const Vec3 wo_world = -glm::normalize(ray.direction);
    absorb(m, si, *hit, ray, beta);
    // Only the camera and delta bounces lead here, so emission seen is never sampled twice.
    if (m.is_emissive()) radiance += beta * rc::scene::emitted_radiance(m, si.ng, wo_world);
    const rc::Frame frame = rc::Frame::from_normal(si.ns);
    const Vec3 wo = frame.to_local(wo_world);
    const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f;
    if (!m.is_traced_through()) {
      // Direct light by one shadow ray (the whole BSDF, glossy lobe included), then the light
      // the other surfaces reflect onto its Lambertian part: the solution's, interpolated over
      // the element found here. Where no element stands for this side, a gather ray reads the
      // solution where it lands. (Gathering everywhere hides the mesh one bounce away, at the
      // price of its noise: on Šibenik's nave at 60 s its relMSE was 1.5 times the reading's,
      // on the Cornell box at 1,600 elements its error 1.2 times.)
      radiance +=
          beta * rc::render::estimate_direct(scene_, si, m, frame, wo, wo_above, ctx.sampler, ctx.rays);
      if (const std::optional<Rgb> e = indirect_irradiance(si, wo_above ? si.ng : -si.ng)) {
        // The solution's light comes from diffuse surfaces in view (mirrors and glass block it);
        // what arrives through them, the gather ray brings.
        const Rgb through = has_specular_ ? gather(si, frame, wo_above, ctx, true) : Rgb(0.0f);
        return radiance + beta * rc::scene::diffuse_reflectance(m) * (*e + through) * (1.0f / rc::kPi);
      }
      return radiance + beta * rc::scene::diffuse_reflectance(m) * gather(si, frame, wo_above, ctx) * (1.0f / rc::kPi);
    }
    if (!scatter_specular(m, si, frame, wo, ctx.sampler, beta, ray)) return radiance;
  }
  return radiance;
}

}  // namespace gilt::radiosity::bake
