// Tile-parallel image loop with per-sample random streams.

#include "raytrace_core/render/render.h"

#include <atomic>
#include <chrono>
#include <cmath>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/progress.h"

namespace gilt::raytrace_core::render {
namespace {

struct Tile {
  int x0, y0, x1, y1;
};

std::vector<Tile> make_tiles(int width, int height, int size) {
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += size)
    for (int x = 0; x < width; x += size) tiles.push_back({x, y, std::min(x + size, width), std::min(y + size, height)});
  return tiles;
}

}  // namespace

scene::Ray camera_ray(const scene::Camera& camera, const RenderSettings& settings, int x, int y,
                      Sampler& sampler) {
  const Vec2 offset = settings.filter.sample(sampler.uniform2());
  const Vec2 film_pos((float(x) + 0.5f + offset.x) / float(settings.width), (float(y) + 0.5f + offset.y) / float(settings.height));
  const Vec2 lens = camera.has_lens() ? sampler.uniform2() : Vec2(0.5f);
  scene::Ray ray = camera.generate_ray(film_pos, lens, float(settings.width) / float(settings.height));
  ray.spread = camera.pixel_spread(settings.height);
  return ray;
}

Film render_image(const scene::Scene& scene, const scene::Camera& camera, const RenderSettings& settings,
                  const RadianceFunction& radiance, RenderStats* stats) {
  if (!scene.committed()) throw std::logic_error("render_image: the scene was not committed");
  if (settings.width <= 0 || settings.height <= 0) throw InputError("image size must be positive");
  if (settings.time_limit <= 0.0 && settings.spp <= 0) throw InputError("samples per pixel must be positive");
  if (settings.tile_size <= 0) throw InputError("tile size must be positive");
  const util::ThreadLimit limit(settings.threads);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  Film film(settings.width, settings.height);
  const std::vector<Tile> tiles = make_tiles(settings.width, settings.height, settings.tile_size);
  const uint64_t pixels = uint64_t(settings.width) * settings.height;
  std::atomic<uint64_t> rays{0}, non_finite{0};

  const bool timed = settings.time_limit > 0.0;
  // Under several processes each renders the tiles it owns, and rank 0 shows the progress.
  const util::Processes& group = util::processes();
  std::vector<size_t> owned;
  for (size_t ti = 0; ti < tiles.size(); ++ti)
    if (group.owns(ti)) owned.push_back(ti);
  util::Progress progress(timed ? "render (time budget)" : "render", timed ? 0 : pixels * settings.spp,
                          "samples", settings.progress && group.rank() == 0);

  // One pass renders samples [first, first + count) of every pixel.
  auto run_pass = [&](int first, int count) {
    util::parallel_for(owned.size(), [&](size_t k) {
      const Tile& tile = tiles[owned[k]];
      uint64_t tile_rays = 0, tile_bad = 0;
      for (int y = tile.y0; y < tile.y1; ++y) {
        for (int x = tile.x0; x < tile.x1; ++x) {
          const uint64_t pixel = uint64_t(y) * settings.width + x;
          for (int s = first; s < first + count; ++s) {
            SampleContext ctx{Sampler::for_pixel_sample(settings.sampler, settings.seed, pixel, uint64_t(s)), 0};
            const Rgb value = radiance(camera_ray(camera, settings, x, y, ctx.sampler), ctx);
            tile_rays += ctx.rays;
            if (value.is_finite()) film.add_sample(x, y, value);
            else ++tile_bad;
          }
        }
      }
      rays += tile_rays;
      non_finite += tile_bad;
      progress.advance(uint64_t(tile.x1 - tile.x0) * (tile.y1 - tile.y0) * count * group.count());
    });
  };

  int done = 0;
  if (!timed) {
    // Passes of a few samples keep the progress bar lively without changing the result.
    const int step = std::max(1, std::min(settings.spp, 8));
    for (; done < settings.spp; done += std::min(step, settings.spp - done)) run_pass(done, std::min(step, settings.spp - done));
  } else {
    // Whole passes until the budget is spent; a pass that would overrun it by more than half
    // its own length is not started. Rank 0's clock decides for every process.
    int count = 1;
    while (true) {
      const double before = elapsed();
      progress.set_total(pixels * (done + count));
      run_pass(done, count);
      done += count;
      const double pass_time = elapsed() - before;
      const double left = settings.time_limit - elapsed();
      const double per_sample = pass_time / count;
      count = std::max(1, std::min(count * 2, int(left / std::max(per_sample, 1e-9))));
      count = group.broadcast_value(left <= 0.0 || per_sample * count > left * 1.5 ? 0 : count);
      if (count == 0) break;
    }
  }
  progress.finish();

  if (group.count() > 1) {
    // Every process gets every tile's sums, copied from the process that rendered it.
    std::vector<std::vector<Film::Accumulated>> sums(tiles.size());
    auto for_pixels = [&](size_t ti, auto&& f) {
      const Tile& t = tiles[ti];
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) f(size_t(y) * settings.width + x);
    };
    for (size_t ti : owned) for_pixels(ti, [&](size_t i) { sums[ti].push_back(film.accumulated(i)); });
    util::join_chunks(sums);
    for (size_t ti = 0; ti < tiles.size(); ++ti) {
      size_t k = 0;
      for_pixels(ti, [&](size_t i) { film.set_accumulated(i, sums[ti][k++]); });
    }
  }
  uint64_t counts[2] = {rays, non_finite};
  group.sum(counts);
  if (stats) {
    stats->spp = done;
    stats->samples = pixels * done;
    stats->rays = counts[0];
    stats->seconds = elapsed();
    stats->non_finite = counts[1];
  }
  return film;
}

}  // namespace gilt::raytrace_core::render
