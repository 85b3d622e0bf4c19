#include "render/plot.h"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "render/cairo_image.h"

namespace kinograph::render {

namespace {

constexpr double kTitleHeight = 44;
constexpr double kRowHeight = 210;
constexpr double kLeft = 70, kRight = 18, kTop = 26, kBottom = 40;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void settle() {
    if (!(lo <= hi)) lo = -1, hi = 1;
    if (hi - lo < 1e-9) {
      const double pad = std::max(1.0, std::abs(lo) * 0.1);
      lo -= pad;
      hi += pad;
    }
  }
};

std::string tick_label(double v, double step) {
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 6);
  if (std::abs(v) < step * 1e-6) v = 0.0;
  return fmt::format("{:.{}f}", v, decimals);
}

void text(cairo_t* cr, const std::string& s, double x, double y, double size, double align_x,
          double align_y) {
  cairo_set_font_size(cr, size);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, s.c_str(), &ext);
  cairo_move_to(cr, x - align_x * ext.x_advance, y - ext.y_bearing - align_y * ext.height);
  cairo_show_text(cr, s.c_str());
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || target < 1) return ticks;
  const double p = std::pow(10.0, std::floor(std::log10((hi - lo) / target)));
  const auto count = [&](double step) {
    return std::floor(hi / step + 1e-9) - std::ceil(lo / step - 1e-9) + 1;
  };
  double step = p;
  for (double m : {2.0, 5.0, 10.0}) {  // the step whose tick count is nearest the target
    if (std::abs(count(m * p) - target) < std::abs(count(step) - target)) step = m * p;
  }
  const double first = std::ceil(lo / step - 1e-9);
  for (double k = first; k * step <= hi + step * 1e-9; k += 1.0) {
    ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);  // k·step, not a running sum
  }
  return ticks;
}

Eigen::Vector3d series_color(int i) {
  static const Eigen::Vector3d kColors[] = {
      {0.12, 0.35, 0.75}, {0.90, 0.42, 0.05}, {0.15, 0.60, 0.25}, {0.55, 0.25, 0.65}};
  return kColors[i % 4];
}

Image plot_torques(const std::vector<PlotSeries>& series, const TorquePlotOptions& options) {
  if (series.empty()) throw std::invalid_argument("plot: no series to plot");
  int joints = -1;
  for (const PlotSeries& s : series) {
    if (s.values.empty() || s.values.size() != s.t.size()) {
      throw std::invalid_argument(fmt::format("plot: series '{}' has {} times and {} value rows",
                                              s.label, s.t.size(), s.values.size()));
    }
    for (const Eigen::VectorXd& v : s.values) {
      if (joints < 0) joints = static_cast<int>(v.size());
      if (v.size() != joints) {
        throw std::invalid_argument(fmt::format("plot: series '{}' has rows of {} and {} joints",
                                                s.label, joints, v.size()));
      }
    }
  }
  if (joints <= 0) throw std::invalid_argument("plot: series have no joints");
  const int columns = options.columns > 0 ? options.columns : (joints <= 3 ? 1 : 2);
  const int rows = (joints + columns - 1) / columns;
  const int width = options.width;
  const int height =
      options.height > 0 ? options.height : static_cast<int>(kTitleHeight + rows * kRowHeight);
  if (width < 200 || height < 100) {
    throw std::invalid_argument(fmt::format("plot: {}x{} pixels is too small", width, height));
  }

  Range t_range;
  for (const PlotSeries& s : series) {
    t_range.add(s.t.front());
    t_range.add(s.t.back());
  }
  t_range.settle();

  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  // Title and legend.
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  text(cr, options.title, width / 2.0, 12, 18, 0.5, 0);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  double legend_x = width - kRight;
  for (int i = static_cast<int>(series.size()) - 1; i >= 0; --i) {
    cairo_set_font_size(cr, 13);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, series[i].label.c_str(), &ext);
    legend_x -= ext.x_advance;
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    text(cr, series[i].label, legend_x, 14, 13, 0, 0);
    const Eigen::Vector3d c = series_color(i);
    cairo_set_source_rgb(cr, c.x(), c.y(), c.z());
    cairo_set_line_width(cr, 2.5);
    cairo_move_to(cr, legend_x - 32, 21);
    cairo_line_to(cr, legend_x - 6, 21);
    cairo_stroke(cr);
    legend_x -= 50;
  }
  if (!options.limits.empty()) {
    cairo_set_font_size(cr, 13);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, "limit", &ext);
    legend_x -= ext.x_advance;
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    text(cr, "limit", legend_x, 14, 13, 0, 0);
    const double dash[] = {6, 4};
    cairo_set_dash(cr, dash, 2, 0);
    cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
    cairo_set_line_width(cr, 1.5);
    cairo_move_to(cr, legend_x - 32, 21);
    cairo_line_to(cr, legend_x - 6, 21);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
  }

  const double cell_w = double(width) / columns;
  const double cell_h = (height - kTitleHeight) / rows;
  for (int j = 0; j < joints; ++j) {
    const int row = j / columns, col = j % columns;
    const double x0 = col * cell_w + kLeft, x1 = (col + 1) * cell_w - kRight;
    const double y0 = kTitleHeight + row * cell_h + kTop,
                 y1 = kTitleHeight + (row + 1) * cell_h - kBottom;
    const double limit = j < static_cast<int>(options.limits.size())
                             ? options.limits[j]
                             : std::numeric_limits<double>::infinity();
    // The axes span the data, not the limits: a limit far above two plans' torques would
    // squash both into one flat band.
    Range y_range;
    for (const PlotSeries& s : series) {
      for (const Eigen::VectorXd& v : s.values) y_range.add(v[j]);
    }
    y_range.settle();
    const double pad = 0.06 * (y_range.hi - y_range.lo);
    y_range.lo -= pad;
    y_range.hi += pad;
    const auto px = [&](double t) {
      return x0 + (t - t_range.lo) / (t_range.hi - t_range.lo) * (x1 - x0);
    };
    const auto py = [&](double v) {
      return y1 - (v - y_range.lo) / (y_range.hi - y_range.lo) * (y1 - y0);
    };

    // Grid and ticks.
    cairo_set_line_width(cr, 1.0);
    const std::vector<double> y_ticks = nice_ticks(y_range.lo, y_range.hi, 5);
    const std::vector<double> t_ticks = nice_ticks(t_range.lo, t_range.hi, 6);
    const double y_step = y_ticks.size() > 1 ? y_ticks[1] - y_ticks[0] : 1.0;
    const double t_step = t_ticks.size() > 1 ? t_ticks[1] - t_ticks[0] : 1.0;
    for (double v : y_ticks) {
      cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
      cairo_move_to(cr, x0, std::round(py(v)) + 0.5);
      cairo_line_to(cr, x1, std::round(py(v)) + 0.5);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
      text(cr, tick_label(v, y_step), x0 - 6, py(v), 11, 1.0, 0.5);
    }
    for (double t : t_ticks) {
      cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
      cairo_move_to(cr, std::round(px(t)) + 0.5, y0);
      cairo_line_to(cr, std::round(px(t)) + 0.5, y1);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
      text(cr, tick_label(t, t_step), px(t), y1 + 5, 11, 0.5, 0);
    }
    if (y_range.lo < 0 && y_range.hi > 0) {  // zero line
      cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
      cairo_move_to(cr, x0, py(0));
      cairo_line_to(cr, x1, py(0));
      cairo_stroke(cr);
    }
    // Limits, dashed where they fall within the axes; one beyond them is named at that edge.
    if (std::isfinite(limit)) {
      const double dash[] = {6, 4};
      cairo_set_dash(cr, dash, 2, 0);
      cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
      cairo_set_line_width(cr, 1.5);
      for (double v : {limit, -limit}) {
        if (v < y_range.lo || v > y_range.hi) continue;
        cairo_move_to(cr, x0, py(v));
        cairo_line_to(cr, x1, py(v));
        cairo_stroke(cr);
      }
      cairo_set_dash(cr, nullptr, 0, 0);
      const std::string value = fmt::format("{:g}", limit);
      if (limit > y_range.hi) text(cr, "limit " + value + " \u2191", x1 - 4, y0 + 3, 11, 1.0, 0);
      if (-limit < y_range.lo) text(cr, "limit -" + value + " \u2193", x1 - 4, y1 - 3, 11, 1.0, 1.0);
    }
    // Curves, clipped to the axes.
    cairo_save(cr);
    cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
    cairo_clip(cr);
    cairo_set_line_width(cr, 2.0);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (std::size_t s = 0; s < series.size(); ++s) {
      const Eigen::Vector3d c = series_color(static_cast<int>(s));
      cairo_set_source_rgb(cr, c.x(), c.y(), c.z());
      for (std::size_t k = 0; k < series[s].t.size(); ++k) {
        const double x = px(series[s].t[k]), y = py(series[s].values[k][j]);
        if (k == 0) {
          cairo_move_to(cr, x, y);
        } else {
          cairo_line_to(cr, x, y);
        }
      }
      cairo_stroke(cr);
    }
    cairo_restore(cr);
    // Frame and labels.
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, std::round(x0) + 0.5, std::round(y0) + 0.5, std::round(x1 - x0),
                    std::round(y1 - y0));
    cairo_stroke(cr);
    const std::string name = j < static_cast<int>(options.joint_names.size())
                                 ? options.joint_names[j]
                                 : fmt::format("joint {}", j + 1);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    text(cr, name, 0.5 * (x0 + x1), y0 - 20, 13, 0.5, 0);
    text(cr, options.x_label, x1, y1 + 22, 11, 1.0, 0);
    cairo_save(cr);
    cairo_move_to(cr, x0 - 52, 0.5 * (y0 + y1));
    cairo_rotate(cr, -std::numbers::pi / 2);
    cairo_set_font_size(cr, 12);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, options.y_label.c_str(), &ext);
    cairo_rel_move_to(cr, -0.5 * ext.x_advance, 0);
    cairo_show_text(cr, options.y_label.c_str());
    cairo_restore(cr);
  }
  cairo_destroy(cr);
  Image image = detail::from_cairo(surface);
  cairo_surface_destroy(surface);
  return image;
}

}  // namespace kinograph::render
