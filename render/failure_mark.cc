#include "render/failure_mark.h"

#include <cairo.h>

#include <algorithm>

#include "render/cairo_image.h"

namespace kinograph::render {

std::optional<std::string> failure_text(const planning::Plan& plan) {
  const planning::Validation& v = plan.validation;
  const planning::SolveStats& s = plan.stats;
  if (v.valid || (v.failures.empty() && s.status == planning::PlanStatus::kConverged)) {
    return std::nullopt;
  }
  std::string why;
  if (!v.failures.empty()) {
    why = v.failures.front();
    if (v.failures.size() > 1) why += " (+" + std::to_string(v.failures.size() - 1) + " more)";
  } else {
    why = planning::to_string(s.status) + (s.reason.empty() ? "" : ": " + s.reason);
  }
  return "FAILED PLAN: " + why;
}

void mark_failed(Image& image, const std::string& text) {
  if (image.width <= 0 || image.height <= 0) return;
  const int side = std::min(image.width, image.height);
  const double border = std::max(3, side / 60);
  const double font_px = std::clamp(side / 14.0, 10.0, 36.0);
  const double banner_h = std::min(1.8 * font_px, 0.5 * image.height);
  cairo_surface_t* surface = detail::to_cairo(image);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 0.80, 0.05, 0.05);
  cairo_set_line_width(cr, 2 * border);  // half of the stroke falls outside the picture
  cairo_rectangle(cr, 0, 0, image.width, image.height);
  cairo_stroke(cr);
  // At the bottom: the top carries the panels' time labels and the legends.
  const double banner_y = image.height - banner_h;
  cairo_rectangle(cr, 0, banner_y, image.width, banner_h);
  cairo_fill(cr);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, font_px);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  // A long reason is shrunk to fit rather than cut: the reason is the point of the banner.
  const double room = image.width - 4 * border;
  if (ext.x_advance > room && ext.x_advance > 0) {
    cairo_set_font_size(cr, font_px * room / ext.x_advance);
    cairo_text_extents(cr, text.c_str(), &ext);
  }
  cairo_font_extents_t font;
  cairo_font_extents(cr, &font);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_move_to(cr, 0.5 * (image.width - ext.x_advance),
                banner_y + 0.5 * (banner_h + font.ascent - font.descent));
  cairo_show_text(cr, text.c_str());
  cairo_destroy(cr);
  image = detail::from_cairo(surface);
  cairo_surface_destroy(surface);
}

}  // namespace kinograph::render
