#pragma once
// A radiosity solution seen through a camera, in one of two ways:
// - the mesh view shows the solution as it is exported: radiance Gouraud-interpolated over the
//   elements, with mirrors and glass ray traced against it (Wallace, Cohen & Greenberg 1987);
// - the two-pass view traces the input's own surfaces, takes the direct light per pixel by
//   shadow rays and the light reflected by other surfaces from the solution, interpolated over
//   the element found at the point (Chen, Rushmeier, Miller & Turner 1991); where none stands
//   for it (the back of a one-sided surface), and for light through mirrors and glass, one
//   final-gather ray per sample reads the solution where it lands. Sharp shadows and a sun
//   patch then need no mesh to resolve them, and a scanned or curved surface shows its own
//   shape rather than its elements' chords.

#include <array>
#include <optional>
#include <vector>

#include "radiosity/solver/solver.h"
#include "raytrace_core/render/render.h"

namespace gilt::radiosity::bake {

/// How the view shows a solution.
enum class ViewMode {
  two_pass,  ///< the input's surfaces: direct light per pixel, reflected light from the solution
  mesh,      ///< the elements: the solution's radiance as exported
};

/// The hierarchical link tolerance of the two-pass view when none is asked for: ten times the
/// exports' (kDefaultLinkTolerance), since the view takes the direct light per pixel and the
/// links carry only the reflected light.
/// On Šibenik at a 60-s budget it solves in 23 s instead of running out of time while linking.
inline constexpr double kTwoPassLinkTolerance = 2e-5;
/// The two-pass view's receiver share (HierarchicalSettings::receiver_share): its solve has no
/// final gather, so the links' light is what a gather ray reads. A hundredth: each link into a
/// receiver may carry wrongly at most a hundred times the tolerance of the receiver's own light.
/// Untimed at 128 × 96, 16 spp, the lit family's atrium read 0.943 of the path tracer without it
/// and 0.970 with it, the outward storeys 0.966 and 0.982, in 2.2 and 1.4 times the solve's time.
inline constexpr double kTwoPassReceiverShare = 0.01;

/// The solver settings a view of the solution needs: the two-pass view takes the direct light
/// and the last bounce per pixel, so its solve skips adaptive subdivision at shadow boundaries
/// and the hierarchical solver's vertex final gather, and links at kTwoPassLinkTolerance unless
/// a tolerance is set, bounded by kTwoPassReceiverShare unless a share is set; the mesh view shows the
/// vertices as they are and needs them all. Both gather a partial solution's unshot light for its ambient
/// term (SolverSettings::gather_ambient).
solver::SolverSettings solver_settings_for(ViewMode mode, solver::SolverSettings settings);

/// Display of a solution; radiance() is a RadianceFunction for raytrace_core::render::render_image.
class RadiosityView {
 public:
  /// Builds the display scenes. Both arguments must outlive the view. With `ambient`, a partial
  /// solution is shown with each vertex's reflectance times the solution's ambient term added
  /// (display only).
  RadiosityView(const rc::scene::Scene& scene, const solver::Solution& solution,
                ViewMode mode = ViewMode::two_pass, bool ambient = true);

  /// Radiance along a camera ray, through any chain of mirror and glass bounces (at most 64).
  Rgb radiance(const rc::scene::Ray& ray, rc::render::SampleContext& ctx) const;

  /// Irradiance (W·m⁻²) the solution gives a point of the input at p whose lit side faces along
  /// the unit normal n from other surfaces' reflections (the direct light left out): interpolated
  /// at the nearest point of an element that faces the same way (within 60°) and lies within
  /// reach (twice the target edge), unless p lies farther from the element than a curved surface
  /// the element is a chord of could. Nothing where no element does:
  /// the back of a one-sided surface, the inside of an open shell, a face removed as buried, a
  /// mirror or glass.
  std::optional<Rgb> indirect_irradiance(const rc::scene::SurfacePoint& p, const Vec3& n) const;

  /// Where irradiance() reads the solution for a point of the input at p with lit side along n:
  /// the element's index and the barycentrics of its second and third vertex.
  struct Location {
    uint32_t element;
    float u, v;
    float distance;  ///< from p to the element
  };
  std::optional<Location> locate(const Vec3& p, const Vec3& n) const;
  /// How far from an element locate() looks: twice the solution's target edge.
  float reach() const { return reach_; }

  /// Irradiance (W·m⁻²) at a point p of the input whose lit side faces along its unit geometric
  /// normal p.ng, estimated from `rays` samples, each one shadow ray's direct light
  /// (rc::render::estimate_direct, as the two-pass view takes it at a pixel) and one cosine-distributed
  /// gather ray that reads the solution where it lands (its element's direct light and reflected
  /// light, through mirrors and glass). The final gather of a bake: what a point sees is traced,
  /// so light does not leak across a roof line or a wall that no element edge follows, and the
  /// solution's own error enters one bounce later, damped by the reflectance there. A gather ray
  /// that lands closer than twice its element's size bounces on (up to 8 times) instead of reading
  /// it: in a crevice or a contact shadow the elements smear the light that the point sees.
  Rgb gathered_irradiance(const rc::scene::SurfacePoint& p, int rays, rc::render::SampleContext& ctx) const;
  /// One sample of gathered_irradiance: one shadow ray and one gather ray, drawn from ctx's
  /// sampler as it stands (a sub-sample of a set the caller split).
  Rgb gathered_sample(const rc::scene::SurfacePoint& p, rc::render::SampleContext& ctx) const;

 private:
  /// Radiance reflected by other surfaces towards a diffuse point si, estimated by one
  /// cosine-distributed gather ray (through mirrors and glass), times π: where it lands, the
  /// element's mean direct light (or a shadow ray's) and the reflected light interpolated.
  /// With via_specular_only, only what the ray brings through a mirror or glass it meets first.
  /// With sky_on_escape, a ray that escapes straight away brings the uniform sky's radiance
  /// (the caller's direct light left it out: rc::render::sky_left_to_bsdf_sampling).
  Rgb gather(const rc::scene::SurfaceInteraction& si, const rc::Frame& frame, bool wo_above,
             rc::render::SampleContext& ctx, bool via_specular_only = false,
             bool sky_on_escape = false) const;
  /// locate(), unless p lies farther from the element than a curved surface the element is a
  /// chord of could (see indirect_irradiance); seen from behind its face (n against p.ng), within
  /// the sagitta of the element's own size.
  std::optional<Location> locate_on(const rc::scene::SurfacePoint& p, const Vec3& n) const;
  Rgb indirect_at(const Location& at) const;
  float longest_edge(uint32_t element) const;
  /// Whether a gather ray that met the surface `distance` from its origin, where `at` locates
  /// it, is too close to read the solution there (kNearHit).
  bool near_hit(const Location& at, float distance) const;
  Rgb mesh_radiance(const rc::scene::Ray& ray, rc::render::SampleContext& ctx) const;
  Rgb two_pass_radiance(const rc::scene::Ray& ray, rc::render::SampleContext& ctx) const;

  const rc::scene::Scene& scene_;
  ViewMode mode_;
  rc::scene::Scene display_;                        ///< the elements (geometry 0) and the specular surfaces
  std::vector<Rgb> vertex_radiance_;         ///< mesh view: W·sr⁻¹·m⁻²
  std::vector<Rgb> vertex_indirect_;         ///< two-pass view: W·m⁻² from reflections, ambient term included
  std::vector<Vec3> positions_;              ///< of the elements' vertices
  std::vector<Rgb> element_direct_;          ///< per element (Solution::element_direct; may be empty)
  bool has_specular_ = false;                ///< the scene has mirrors or glass
  bool sky_by_gather_ = false;               ///< gathered_sample takes the uniform sky by its gather ray
  Rgb constant_sky_{0.0f};                   ///< radiance of the scene's environments without a map
  std::vector<std::array<uint32_t, 3>> elements_;
  float reach_ = 0.0f;                       ///< how far from an element the two-pass view looks it up
};

}  // namespace gilt::radiosity::bake
