#include "api/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "raytrace_core/util/staged_file.h"

namespace gilt::api {
namespace {

/// Line colours of the methods in the plot and table (distinct, colour-blind-safe Okabe–Ito).
const char* method_colour(const std::string& method) {
  static const std::map<std::string, const char*> colours = {
      {"path", "#0072B2"}, {"photon", "#D55E00"}, {"sppm", "#009E73"}, {"radiosity", "#CC79A7"}, {"whitted", "#E69F00"}};
  const auto it = colours.find(method);
  return it == colours.end() ? "#000000" : it->second;
}

std::string number(double x, const char* format = "%.4g") {
  char text[64];
  std::snprintf(text, sizeof text, format, x);
  return text;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  raytrace_core::util::StagedFile file(path, text);
  file.commit();
}

/// Log-log plot of relMSE against seconds, one polyline per method, and the reference's noise
/// floor as a dashed line. An error corrected to 0 or below (within the reference's noise) is
/// drawn as an open circle at a tenth of the floor, the bottom of the plot.
std::string plot_svg(const Report& r) {
  const double w = 660, h = 400, left = 70, right = 150, top = 20, bottom = 50;
  const double floor = r.reference_relmse_floor, lowest = 0.1 * floor;
  const auto shown = [&](const ReportEntry& e) { return std::max(e.relmse, lowest); };
  const auto plotted = [&](const ReportEntry& e) { return shown(e) > 0.0 && e.seconds > 0.0; };
  double tmin = 1e30, tmax = 0, emin = floor > 0.0 ? floor : 1e30, emax = floor;
  for (const ReportEntry& e : r.entries) {
    if (!plotted(e)) continue;
    tmin = std::min(tmin, e.seconds), tmax = std::max(tmax, e.seconds);
    emin = std::min(emin, shown(e)), emax = std::max(emax, shown(e));
  }
  if (!(tmax > 0.0)) return "<p>No errors to plot.</p>";
  // Whole decades around the data.
  const double lt0 = std::floor(std::log10(tmin)), lt1 = std::max(lt0 + 1, std::ceil(std::log10(tmax)));
  const double le0 = std::floor(std::log10(emin)), le1 = std::max(le0 + 1, std::ceil(std::log10(emax)));
  auto x_of = [&](double t) { return left + (std::log10(t) - lt0) / (lt1 - lt0) * (w - left - right); };
  auto y_of = [&](double e) { return top + (le1 - std::log10(e)) / (le1 - le0) * (h - top - bottom); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"plot\" width=\"" << w << "\" height=\"" << h
    << "\" viewBox=\"0 0 " << w << ' ' << h << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect x=\"0\" y=\"0\" width=\"" << w << "\" height=\"" << h << "\" fill=\"#ffffff\"/>\n";
  for (double d = lt0; d <= lt1 + 1e-9; ++d) {
    const double x = x_of(std::pow(10.0, d));
    s << "<line x1=\"" << x << "\" y1=\"" << top << "\" x2=\"" << x << "\" y2=\"" << h - bottom
      << "\" stroke=\"#dddddd\"/>\n<text x=\"" << x << "\" y=\"" << h - bottom + 16 << "\" text-anchor=\"middle\">"
      << number(std::pow(10.0, d)) << "</text>\n";
  }
  for (double d = le0; d <= le1 + 1e-9; ++d) {
    const double y = y_of(std::pow(10.0, d));
    s << "<line x1=\"" << left << "\" y1=\"" << y << "\" x2=\"" << w - right << "\" y2=\"" << y
      << "\" stroke=\"#dddddd\"/>\n<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\">1e"
      << int(d) << "</text>\n";
  }
  s << "<text x=\"" << (left + w - right) / 2 << "\" y=\"" << h - 12
    << "\" text-anchor=\"middle\">time (s, log scale)</text>\n";
  s << "<text x=\"16\" y=\"" << (top + h - bottom) / 2 << "\" text-anchor=\"middle\" transform=\"rotate(-90 16 "
    << (top + h - bottom) / 2 << ")\">relative MSE (log scale)</text>\n";
  int legend = 0;
  if (floor > 0.0) {
    const double y = y_of(floor), ly = top + 10 + 20 * legend++;
    s << "<line id=\"noise-floor\" x1=\"" << left << "\" y1=\"" << y << "\" x2=\"" << w - right << "\" y2=\"" << y
      << "\" stroke=\"#777777\" stroke-width=\"2\" stroke-dasharray=\"6 4\"><title>the reference's noise floor: relMSE "
      << number(floor) << "</title></line>\n";
    s << "<line x1=\"" << w - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << w - right + 40 << "\" y2=\"" << ly
      << "\" stroke=\"#777777\" stroke-width=\"2\" stroke-dasharray=\"6 4\"/><text x=\"" << w - right + 46
      << "\" y=\"" << ly + 4 << "\">reference noise</text>\n";
  }
  for (const std::string& m : r.methods) {
    std::ostringstream points;
    int n = 0;
    for (const ReportEntry& e : r.entries)
      if (e.method == m && plotted(e)) points << x_of(e.seconds) << ',' << y_of(shown(e)) << ' ', ++n;
    if (n == 0) continue;
    s << "<polyline class=\"method-line\" data-method=\"" << m << "\" fill=\"none\" stroke=\"" << method_colour(m)
      << "\" stroke-width=\"3\" points=\"" << points.str() << "\"/>\n";
    for (const ReportEntry& e : r.entries)
      if (e.method == m && plotted(e)) {
        const bool below = !(e.relmse > lowest);
        s << "<circle cx=\"" << x_of(e.seconds) << "\" cy=\"" << y_of(shown(e)) << "\" r=\"4\" fill=\""
          << (below ? "#ffffff" : method_colour(m)) << "\" stroke=\"" << method_colour(m) << "\"><title>" << m << ": "
          << number(e.seconds) << " s, relMSE " << number(e.relmse) << " ± " << number(e.relmse_stderr)
          << (below ? " (within the reference's noise)" : "") << "</title></circle>\n";
      }
    const double ly = top + 10 + 20 * legend++;
    s << "<line x1=\"" << w - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << w - right + 40 << "\" y2=\"" << ly
      << "\" stroke=\"" << method_colour(m) << "\" stroke-width=\"3\"/><text x=\"" << w - right + 46 << "\" y=\""
      << ly + 4 << "\">" << m << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

/// Reads the report; writes metrics.json and metrics.csv into the folder.
void write_metrics(const std::filesystem::path& folder, const Report& r) {
  nlohmann::json j = {{"scene", r.scene},       {"width", r.width},         {"height", r.height},
                      {"sampler", r.sampler}, {"light_sampler", r.light_sampler},     {"reference", r.reference}, {"reference_noise_mean_relative_error", r.reference_noise_mre},
                      {"reference_relmse_floor", r.reference_relmse_floor},
                      {"reference_mse_floor", r.reference_mse_floor},
                      {"errors_noise_corrected", r.reference_relmse_floor > 0.0},
                      {"relmse_epsilon", 0.01},  {"entries", nlohmann::json::array()}};
  std::ostringstream csv;
  csv << "method,budget_seconds,seconds,spp_or_iterations,photons,shots,rmse,relmse,mae,mean_relative_error,"
         "mean_ratio,object_space_error,image,relmse_stderr,rmse_measured,relmse_measured\n";
  for (const ReportEntry& e : r.entries) {
    j["entries"].push_back(entry_json(e));
    csv << e.method << ',' << e.budget << ',' << number(e.seconds, "%.4f") << ',' << e.spp << ',' << e.photons << ','
        << e.shots << ',' << number(e.rmse, "%.6g") << ',' << number(e.relmse, "%.6g") << ','
        << number(e.mae, "%.6g") << ',' << number(e.mre, "%.6g") << ',' << number(e.mean_ratio, "%.6g") << ','
        << (e.object_space_error ? number(*e.object_space_error, "%.6g") : std::string()) << ',' << e.image_exr
        << ',' << number(e.relmse_stderr, "%.6g") << ',' << number(e.rmse_measured, "%.6g") << ','
        << number(e.relmse_measured, "%.6g") << '\n';
  }
  write_file(folder / "metrics.json", j.dump(2) + "\n");
  write_file(folder / "metrics.csv", csv.str());
}

/// Reads the report's scene, size, sampler and reference; writes index.html's head, title and the
/// note on the reference's noise to h. Small images are shown enlarged by a whole factor (pixels
/// stay square and sharp).
void write_html_head(std::ostringstream& h, const Report& r) {
  const int scale = std::max(1, 192 / std::max(1, std::max(r.width, r.height)));
  const int display_width = r.width * scale;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>gilt compare: "
    << escape(r.scene) << "</title>\n<style>\n"
    << "body{font-family:sans-serif;margin:20px;color:#222;background:#fafafa}\n"
    << "table{border-collapse:collapse;margin:12px 0}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}\n"
    << "th{background:#eee}td.m{text-align:left;font-weight:bold}td.best{background:#d8f0d8}\n"
    // Each method's images wrap onto further lines where the window is too narrow for one row, and
    // shrink (keeping their shape) where it is narrower than one image; tables and the plot scroll
    // or shrink inside the page rather than widen it.
    << ".row{display:flex;flex-wrap:wrap;gap:8px;margin-bottom:12px}.cell{width:" << display_width
    << "px;max-width:100%}.cell img{width:100%;height:auto;aspect-ratio:" << r.width << "/" << r.height
    << ";image-rendering:pixelated;display:block}\n"
    << ".scroll{overflow-x:auto;max-width:100%}svg{max-width:100%;height:auto}\n"
    << ".cell{font-size:12px}.head{font-weight:bold;margin:8px 0 4px}\n"
    << ".legend{height:14px;width:300px;background:linear-gradient(to right,rgb(10,10,60),rgb(30,80,220),"
       "rgb(40,200,200),rgb(240,220,40),rgb(220,30,30))}\n</style>\n</head>\n<body>\n";
  h << "<h1>gilt compare: " << escape(r.scene) << "</h1>\n<p>" << r.width << " &times; " << r.height
    << " pixels, every method on the same camera, " << escape(r.sampler) << " samples, lights chosen by " << escape(r.light_sampler) << ". Reference: " << escape(r.reference);
  if (r.reference_noise_mre > 0.0)
    h << " (its own noise: mean relative error " << number(100 * r.reference_noise_mre, "%.2f")
      << " %)";
  h << ".</p>\n";
  if (r.reference_relmse_floor > 0.0)
    h << "<p id=\"noise-note\">The reference's own noise, estimated pixel by pixel from its two independent halves, "
         "is subtracted from every RMSE and relMSE below, so that they estimate each method's error against the exact "
         "image (a perfect image would measure relMSE " << number(r.reference_relmse_floor, "%.3g")
      << " against this reference: the dashed line in the plot). An error within the reference's noise may come out "
         "below 0 by its standard error (&plusmn;). The errors against the reference as it is are in the last column "
         "and in the files.</p>\n";
  else
    h << "<p id=\"noise-note\">The reference's noise is not known (a reference file), so the errors include it.</p>\n";
}

/// Reads the report's budgets and entries; writes the table of the best method at each budget to h.
void write_html_winners(std::ostringstream& h, const Report& r) {
  h << "<h2>Best method at each budget</h2>\n<table id=\"winners\"><tr><th>budget</th>";
  for (double b : r.budgets) h << "<th>" << number(b) << " s</th>";
  h << "</tr><tr><td class=\"m\">lowest relMSE</td>";
  for (double b : r.budgets) {
    const ReportEntry* best = nullptr;
    for (const ReportEntry& e : r.entries)
      if (e.budget == b && (!best || e.relmse < best->relmse)) best = &e;
    h << "<td style=\"color:" << (best ? method_colour(best->method) : "#000") << ";font-weight:bold\">"
      << (best ? best->method : "-") << "</td>";
  }
  h << "</tr></table>\n";
}

/// Reads the report's images, methods and budgets; writes the reference and each method's images
/// with their error images to h.
void write_html_images(std::ostringstream& h, const Report& r) {
  h << "<h2>Images</h2>\n<p>All at exposure " << number(r.exposure) << " EV. Under each image its per-pixel "
    << "relative error |I &minus; R| / (R + 0.01), false colour on a log scale:</p>\n"
    << "<div style=\"display:flex;gap:8px;align-items:center;font-size:12px\">0.001<div class=\"legend\"></div>1</div>\n";
  h << "<div class=\"head\">reference</div>\n<div class=\"row\"><div class=\"cell\"><img class=\"render\" src=\""
    << r.reference_png << "\" alt=\"reference\"></div></div>\n";
  for (const std::string& m : r.methods) {
    h << "<div class=\"head\" style=\"color:" << method_colour(m) << "\">" << m << "</div>\n<div class=\"row\">";
    for (double b : r.budgets) {
      const auto it = std::find_if(r.entries.begin(), r.entries.end(),
                                   [&](const ReportEntry& e) { return e.method == m && e.budget == b; });
      if (it == r.entries.end()) continue;
      h << "<div class=\"cell\"><b>" << number(b) << " s</b><img class=\"render\" src=\"" << it->image_png
        << "\" alt=\"" << m << " " << number(b) << " s\"><img class=\"error\" src=\"" << it->error_png
        << "\" alt=\"error of " << m << " " << number(b) << " s\">" << number(it->seconds, "%.2f") << " s, relMSE "
        << number(it->relmse, "%.3g") << "</div>";
    }
    h << "</div>\n";
  }
}

/// Reads the report's entries; writes the metrics table and the page's end to h.
void write_html_metrics(std::ostringstream& h, const Report& r) {
  h << "<h2>Metrics</h2>\n<div class=\"scroll\"><table id=\"metrics\"><tr><th>method</th><th>budget s</th><th>actual s</th>"
       "<th>spp / iterations</th><th>photons</th><th>shots</th><th>RMSE</th><th>relMSE</th><th>MAE</th>"
       "<th>mean rel. error</th><th>mean / reference</th><th>object-space error</th><th>relMSE against the "
       "reference as it is</th></tr>\n";
  for (const ReportEntry& e : r.entries) {
    double best = 1e300;
    for (const ReportEntry& o : r.entries)
      if (o.budget == e.budget) best = std::min(best, o.relmse);
    h << "<tr><td class=\"m\" style=\"color:" << method_colour(e.method) << "\">" << e.method << "</td><td>"
      << number(e.budget) << "</td><td>" << number(e.seconds, "%.2f") << "</td><td>" << e.spp << "</td><td>"
      << e.photons << "</td><td>" << e.shots << "</td><td>" << number(e.rmse, "%.4g") << "</td><td"
      << (e.relmse == best ? " class=\"best\"" : "") << ">" << number(e.relmse, "%.4g") << " &plusmn; "
      << number(e.relmse_stderr, "%.2g") << "</td><td>"
      << number(e.mae, "%.4g") << "</td><td>" << number(100 * e.mre, "%.2f") << " %</td><td>"
      << number(e.mean_ratio, "%.4f") << "</td><td>"
      << (e.object_space_error ? number(100 * *e.object_space_error, "%.2f") + " %" : std::string("")) << "</td><td>"
      << number(e.relmse_measured, "%.4g") << "</td></tr>\n";
  }
  h << "</table></div>\n<p>relMSE = mean over pixels and channels of (I &minus; R)&sup2; / (R&sup2; + 0.01). Times include "
       "each method's preparation (radiosity solve, photon tracing). Mean / reference: the image's sum over pixels and "
       "channels over the reference's, its bias in overall brightness. Object-space error: radiosity vertex radiance "
       "against path-traced estimates at sampled vertices. Files: <a href=\"metrics.json\">metrics.json</a>, "
       "<a href=\"metrics.csv\">metrics.csv</a>.</p>\n</body>\n</html>\n";
}

}  // namespace

void error_colour(double relative_error, unsigned char rgb[3]) {
  // Log scale: 1e-3 → 0, 1 → 1; a ramp dark blue, blue, cyan, yellow, red.
  const double t = std::clamp((std::log10(std::max(relative_error, 1e-12)) + 3.0) / 3.0, 0.0, 1.0);
  static const double stops[5][3] = {{10, 10, 60}, {30, 80, 220}, {40, 200, 200}, {240, 220, 40}, {220, 30, 30}};
  const double x = t * 4.0;
  const int i = std::min(3, int(x));
  const double f = x - i;
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<unsigned char>(std::lround(stops[i][c] * (1 - f) + stops[i + 1][c] * f));
}

nlohmann::json entry_json(const ReportEntry& e) {
  nlohmann::json je = {{"method", e.method}, {"budget_seconds", e.budget}, {"seconds", e.seconds},
                       {"spp_or_iterations", e.spp}, {"photons", e.photons}, {"shots", e.shots},
                       {"rmse", e.rmse}, {"relmse", e.relmse}, {"relmse_stderr", e.relmse_stderr},
                       {"rmse_measured", e.rmse_measured}, {"relmse_measured", e.relmse_measured},
                       {"mae", e.mae}, {"mean_relative_error", e.mre},
                       {"mean_ratio", e.mean_ratio}, {"image_exr", e.image_exr}, {"image_png", e.image_png}, {"error_png", e.error_png},
                       {"notes", e.notes}};
  je["object_space_error"] = e.object_space_error ? nlohmann::json(*e.object_space_error) : nlohmann::json(nullptr);
  return je;
}

void write_report(const std::filesystem::path& folder, const Report& r) {
  write_metrics(folder, r);
  std::ostringstream h;
  write_html_head(h, r);
  write_html_winners(h, r);
  h << "<h2>Error against time</h2>\n" << plot_svg(r);
  write_html_images(h, r);
  write_html_metrics(h, r);
  write_file(folder / "index.html", h.str());
}

}  // namespace gilt::api
