#pragma once
// Lightmaps (`gilt radiosity --lightmap SIZE`): the solution baked into one square texture atlas,
// addressed by a UV set laid out for it over the input model's faces.
//
// UVs: the input's own TEXCOORD_1, else TEXCOORD_0 (OBJ and PLY: their one set), when every
// baked mesh has it inside [0, 1]², without faces flattened to no area and without two faces on
// the same texels, and no mesh is instanced; else a layout of gilt's own.
//
// Layout (after Blender's "Smart UV Project", which most lightmap workflows in Blender start
// from): the faces of each mesh are grown into charts of neighbours (across edges of welded
// positions) whose normals lie within kChartAngle of the chart's first, largest face, and each
// chart is projected onto that face's plane. A face joins only when its projection overlaps none
// of the chart's faces, so no two faces of the atlas share texels. Charts are turned to their
// smallest bounding rectangle, given a uniform texel density (texels per metre, the largest at
// which they all fit) and packed in shelves, each inside a border of kLightmapPad texels.
//
// Texels: each texel within 1.5 texels of a face (so that bilinear reads anywhere inside a face
// find values, not the border) takes the face nearest its centre, and its value is the mean of
// the solution at four points of its footprint clamped onto that face, read as `--onto input`'s
// fit reads it (SolutionAtInput: the element solution, with point and directional lights by
// their own shadow rays). The border's remaining texels take their filled neighbours' mean, so
// mipmaps and filtering in viewers do not pull in black.
//
// The atlas is a half-float EXR beside the model; glTF outputs get the UV set as a new
// TEXCOORD_n and name the file in each baked material's extras (see write_lightmap).

#include <cstddef>
#include <string>
#include <vector>

#include "radiosity/bake/export.h"
#include "radiosity/bake/onto_input.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/util/image_io.h"

namespace gilt::radiosity::bake {

/// A face joins a chart when its normal is within this angle (degrees) of the chart's first face.
inline constexpr float kChartAngle = 45.0f;
/// Empty texels around each chart's rectangle in the atlas.
inline constexpr int kLightmapPad = 2;

struct LightmapStats {
  size_t charts = 0;
  size_t faces = 0;             ///< faces laid out
  size_t buried_faces = 0;      ///< laid out but not baked (input_faces_buried)
  size_t texels = 0;            ///< texels holding a face's value
  double texels_per_metre = 0;  ///< the atlas's texel density (per unit of the scene's length); 0 with the input's UVs
  int uv_set = -1;              ///< the input's UV set used (glTF TEXCOORD_n; OBJ/PLY 0), or −1: gilt's own
  std::string uv_source;        ///< which UVs, and why the input's were not used
  double layout_seconds = 0, bake_seconds = 0;
  BakeGatherCount gather;       ///< with a final gather: how the texels' points were evaluated
  BakeSides sides;              ///< which side of the surface the texels' points read
};

struct Lightmap {
  int size = 0;
  int32_t file = -1;  ///< index into Scene::model_files
  /// Per scene mesh: the atlas UV of each face corner (three per face, in index order), u to the
  /// right and v down from the image's top-left as glTF has it; empty for meshes not baked.
  std::vector<std::vector<rc::Vec2>> corner_uv;
  rc::util::Image image;  ///< size × size, the quantity itself (HDR, linear)
  LightmapStats stats;

  /// The atlas read bilinearly at face `face` of scene mesh `mesh`, at barycentrics (u, v) of its
  /// second and third corner: what a viewer shows there.
  Rgb at(size_t mesh, size_t face, float u, float v) const;
};

/// Lays out and bakes a size × size lightmap of the solution's `quantity` over the non-specular
/// meshes read from the scene's model file (onto_input_file). Throws InputError when size is
/// outside 16..16384.
Lightmap bake_lightmap(const rc::scene::Scene& scene, const solver::Solution& solution, Quantity quantity,
                       int size, BakeGather gather = {});

/// Throws InputError when bake_lightmap could not lay out a size × size atlas for the scene
/// (size outside 16..16384, nothing to bake, more charts than fit): called before solving.
void check_lightmap_layout(const rc::scene::Scene& scene, int size);

/// The atlas's file for a model output: `<folder>/<stem>_lightmap.exr`.
std::string lightmap_image_path(const std::string& model_output);

/// Throws InputError unless write_lightmap can write `path` for the scene (called before solving).
void check_lightmap_output(const std::string& path, const rc::scene::Scene& scene);

/// Writes the atlas (lightmap_image_path, half float) and the model:
/// - glTF in, glTF out, in the input's own UV set: the input unchanged but for the extras;
/// - glTF in, glTF out, in gilt's layout: the input as write_onto_gltf keeps it, each baked primitive with its
///   vertices split where the atlas's charts meet (each vertex attribute gathered over the new
///   vertices, positions bit for bit) and the UV set in a new TEXCOORD_n; each baked material
///   (one is added for primitives without one) gets extras.gilt_lightmap = {uri, texCoord,
///   quantity, exposure};
/// - OBJ or PLY in: a glTF (.gltf or .glb) of the meshes as read (OBJ and PLY hold one UV set),
///   TEXCOORD_0 the input's own UVs where it has them, the lightmap's UV set after it.
void write_lightmap(const std::string& path, const rc::scene::Scene& scene, const Lightmap& lightmap,
                    const ExportSettings& settings);

}  // namespace gilt::radiosity::bake
