// Environment maps; see environment_map.h for the orientation and the sampling scheme.

#include "raytrace_core/scene/environment_map.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_io.h"

namespace gilt::raytrace_core::scene {

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<Rgb> texels, float scale, float rotate_degrees)
    : width_(width), height_(height), texels_(std::move(texels)), rotate_degrees_(rotate_degrees) {
  if (width <= 0 || height <= 0 || texels_.size() != size_t(width) * size_t(height))
    throw InputError("environment map: empty, or its texel count is not width × height");
  if (!(scale >= 0.0f) || !std::isfinite(scale)) throw InputError("environment map: scale must be a finite number ≥ 0");
  if (!std::isfinite(rotate_degrees)) throw InputError("environment map: rotation must be finite");
  const float radians = rotate_degrees * (kPi / 180.0f);
  cos_rotation_ = std::cos(radians);
  sin_rotation_ = std::sin(radians);

  std::vector<float> row_weights(size_t(height), 0.0f);
  std::vector<float> column_weights(static_cast<size_t>(width), 0.0f);
  columns_.reserve(size_t(height));
  double mean[3] = {0.0, 0.0, 0.0};
  for (int row = 0; row < height; ++row) {
    const float omega = cell_solid_angle(row);
    double row_sum = 0.0;
    for (int col = 0; col < width; ++col) {
      Rgb& t = texels_[size_t(row) * size_t(width) + size_t(col)];
      if (!t.is_finite()) throw InputError("environment map: texel (" + std::to_string(col) + ", " +
                                           std::to_string(row) + ") is not a finite number");
      t = clamp(t, 0.0f, kInfinity) * scale;  // a negative texel (compression ringing) emits nothing
      column_weights[size_t(col)] = t.average();
      row_sum += column_weights[size_t(col)];
      for (int c = 0; c < 3; ++c) mean[c] += double(t[c]) * omega;
    }
    row_weights[size_t(row)] = float(row_sum * omega);
    columns_.emplace_back(column_weights);
  }
  rows_ = util::Distribution1D(row_weights);
  for (int c = 0; c < 3; ++c) mean_[c] = float(mean[c] / (4.0 * std::numbers::pi));
}

std::shared_ptr<const EnvironmentMap> EnvironmentMap::load(const std::string& path, float scale, float rotate_degrees) {
  util::Image image = util::read_image(path);
  try {
    return std::make_shared<const EnvironmentMap>(image.width, image.height, std::move(image.pixels), scale,
                                                  rotate_degrees);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

float EnvironmentMap::cell_solid_angle(int row) const {
  const double theta0 = std::numbers::pi * row / height_, theta1 = std::numbers::pi * (row + 1) / height_;
  return float((std::cos(theta0) - std::cos(theta1)) * 2.0 * std::numbers::pi / width_);
}

size_t EnvironmentMap::texel_of(const Vec3& w) const {
  // Into the map's frame: turn back by the rotation about +y.
  const float x = cos_rotation_ * w.x - sin_rotation_ * w.z, z = sin_rotation_ * w.x + cos_rotation_ * w.z;
  const float len = std::sqrt(x * x + w.y * w.y + z * z);
  const float theta = std::acos(std::clamp(len > 0.0f ? w.y / len : 1.0f, -1.0f, 1.0f));
  const float phi = std::atan2(x, -z);  // 0 along −z, π/2 along +x
  const int row = std::clamp(int(theta * (1.0f / kPi) * float(height_)), 0, height_ - 1);
  const int col = std::clamp(int((0.5f + phi * (0.5f / kPi)) * float(width_)), 0, width_ - 1);
  return size_t(row) * size_t(width_) + size_t(col);
}

Rgb EnvironmentMap::radiance(const Vec3& w) const { return texels_[texel_of(w)]; }

EnvironmentMap::Sample EnvironmentMap::sample(Vec2 u) const {
  Sample s;
  if (rows_.size() == 0) return s;
  float u_theta = 0.0f, u_phi = 0.0f;
  const uint32_t row = rows_.sample(u.x, u_theta);
  const util::Distribution1D& columns = columns_[row];
  const uint32_t col = columns.sample(u.y, u_phi);
  // Uniform in solid angle inside the cell: cos θ uniform between its rows' cosines, φ uniform.
  const double cos0 = std::cos(std::numbers::pi * row / height_), cos1 = std::cos(std::numbers::pi * (row + 1) / height_);
  const float cos_theta = float(cos0 - double(u_theta) * (cos0 - cos1));
  const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  const float phi = 2.0f * kPi * ((float(col) + u_phi) / float(width_) - 0.5f);
  const float mx = sin_theta * std::sin(phi), mz = -sin_theta * std::cos(phi);
  s.wi = {cos_rotation_ * mx + sin_rotation_ * mz, cos_theta, -sin_rotation_ * mx + cos_rotation_ * mz};
  s.radiance = texels_[size_t(row) * size_t(width_) + col];
  s.pdf = rows_.pmf(row) * columns.pmf(col) / cell_solid_angle(int(row));
  return s;
}

float EnvironmentMap::pdf(const Vec3& w) const {
  if (rows_.size() == 0) return 0.0f;
  const size_t t = texel_of(w);
  const uint32_t row = uint32_t(t / size_t(width_)), col = uint32_t(t % size_t(width_));
  return rows_.pmf(row) * columns_[row].pmf(col) / cell_solid_angle(int(row));
}

}  // namespace gilt::raytrace_core::scene
