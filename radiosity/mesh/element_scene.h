#pragma once
// The radiosity mesh as a ray-traceable scene. The solver traces its visibility rays against it,
// not against the input: the elements are chords of a curved or finely detailed input, and a
// receiver on an element seen against the input's bumps and rounded edges is shadowed by
// geometry the radiosity world does not have (the Stanford bunny came out in black blotches).

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/scene/ray.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::radiosity::mesh {

/// A committed scene whose geometry 0 holds every element (one black diffuse material, so no
/// element is a light), followed by the input's mirror and glass meshes and spheres as they
/// are, which the solver treats as opaque and the view ray traces. Materials are the input's,
/// plus the elements' at the end.
rc::scene::Scene element_scene(const rc::scene::Scene& scene, const RadiosityMesh& mesh);

/// A point of the mesh for spawning rays at p on a surface with unit normal n; the error bound
/// allows for rounding in meshing (γ(16)·|p|).
inline rc::scene::SurfacePoint mesh_surface_point(const Vec3& p, const Vec3& n) {
  rc::scene::SurfacePoint sp;
  sp.p = p;
  sp.p_error = rc::scene::error_gamma(16) * rc::abs(p);
  sp.ng = n;
  return sp;
}

}  // namespace gilt::radiosity::mesh
