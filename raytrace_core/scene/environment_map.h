#pragma once
// An environment map: radiance arriving from infinitely far away, read from a latitude–longitude
// (equirectangular) image such as an HDR panorama, and importance-sampled by its texels' power.
//
// Orientation (+y up, as glTF and gilt's default camera): the image's top row looks straight
// up, its bottom row straight down; its centre column looks along −z (where the default camera
// looks) and its right half towards +x, so the panorama seen from inside is not mirrored. A
// rotation of `rotate_degrees` turns the environment right-handedly about +y.
//
// Each texel is a patch of constant radiance over its cell of the sphere (θ from the row, φ from
// the column). Sampling picks a texel with probability proportional to its mean RGB times the
// cell's solid angle (rows, then a column within the row), then a direction uniformly in
// solid angle inside the cell. So the density of a direction is that probability over the cell's
// solid angle: exact, and non-zero wherever the radiance is. (Piecewise-constant sampling of the
// map as in Pharr, Jakob & Humphreys, "Physically Based Rendering", 4th ed., §12.5.2, with cells
// taken in solid angle rather than with a sin θ weight, so that no direction is singular.)

#include <memory>
#include <string>
#include <vector>

#include "raytrace_core/util/rgb.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {

class EnvironmentMap {
 public:
  /// From texels (row-major from the top-left, linear RGB radiance), multiplied by `scale`.
  /// Throws InputError for an empty image or a negative or non-finite texel or scale.
  EnvironmentMap(int width, int height, std::vector<Rgb> texels, float scale = 1.0f, float rotate_degrees = 0.0f);

  /// Reads an image file (.exr, .hdr, or anything OpenImageIO reads; 8-bit files are taken as
  /// sRGB). Throws InputError naming the file.
  static std::shared_ptr<const EnvironmentMap> load(const std::string& path, float scale, float rotate_degrees);

  /// Radiance arriving from direction w (unit, pointing away from the scene).
  Rgb radiance(const Vec3& w) const;

  struct Sample {
    Vec3 wi{0.0f};  ///< unit direction towards the environment
    Rgb radiance{0.0f};
    float pdf = 0.0f;  ///< per steradian
  };
  /// A direction drawn with density pdf(wi); u in [0, 1)². Zero pdf when the map is black.
  Sample sample(Vec2 u) const;
  /// Density with which sample() draws w.
  float pdf(const Vec3& w) const;

  /// Mean radiance over the sphere (1/4π ∫ L dω).
  Rgb mean_radiance() const { return mean_; }
  int width() const { return width_; }
  int height() const { return height_; }
  float rotate_degrees() const { return rotate_degrees_; }
  /// Radiance per texel (scale applied), row-major from the top-left.
  const std::vector<Rgb>& texels() const { return texels_; }

 private:
  /// The texel that direction w falls in.
  size_t texel_of(const Vec3& w) const;
  /// Solid angle of a texel of row `row`.
  float cell_solid_angle(int row) const;

  int width_ = 0, height_ = 0;
  std::vector<Rgb> texels_;
  float rotate_degrees_ = 0.0f, cos_rotation_ = 1.0f, sin_rotation_ = 0.0f;
  util::Distribution1D rows_;                 ///< row marginals
  std::vector<util::Distribution1D> columns_; ///< per row, its texels
  Rgb mean_{0.0f};
};

}  // namespace gilt::raytrace_core::scene
