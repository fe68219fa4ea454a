// The elements' direct light: the mean over each element of the irradiance from the scene's
// punctual and environment lights, which is what the element reflects into the rest of the scene
// (the vertices' own direct light is gathered per vertex by the solver). And how many samples of
// it fit in a time budget.

#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/util/progress.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::radiosity::solver {

/// The mean over each element of the irradiance from the scene's punctual and environment
/// lights: `samples` stratified points on the element, one light sample each (a cosine-weighted
/// direction for the sky). This, not the mean of the element's vertices, is what the element
/// reflects into the rest of the scene: a vertex reads the light at one corner, and where a
/// shadow edge crosses an element the mean of three corners may be anything from none to all of
/// it. On Šibenik's nave, whose elements are the input's, the vertex mean made the sunlight's
/// first bounce 1.45 times too bright.
///
/// An element larger than the mean takes at least `samples` × its area / the mean area points (a
/// grid of up to 8² times as many): the noise of the light the elements reflect in all is
/// Σ A² σ² / n over them, least for a given number of rays when n grows with A. On an interior
/// such as Šibenik's, whose floor is a few large triangles, the sun patches and the sky through
/// the windows fall on a few dozen large elements, and their first bounce lights everything:
/// with 16 points on every element, the two-pass render's mean moved as a whole with the seed
/// (a standard deviation of 2.2 % over six seeds, 0.6 % now; bench/README.md, "Direct light on
/// large elements: the seed's spread"). Advances `progress` (if any) by one per element.
std::vector<rc::Rgb> element_punctual_irradiance(const rc::scene::Scene& scene,
                                                 const rc::scene::Scene& geometry,
                                                 const mesh::RadiosityMesh& mesh, int samples, uint64_t seed,
                                                 uint64_t& rays, rc::util::Progress* progress = nullptr);

/// Under a time limit: the most samples per element and light, up to `samples` and a square as
/// element_punctual_irradiance takes them, whose rays fit in `seconds` at `rays_per_second`; at
/// least one. A mesh of a million elements takes one: its elements are small, so the noise of
/// the light they reflect in all (Σ A² σ² / n over them) stays small with one ray each.
int element_samples_within(const mesh::RadiosityMesh& mesh, size_t lights, int samples,
                           double rays_per_second, double seconds);

}  // namespace gilt::radiosity::solver
