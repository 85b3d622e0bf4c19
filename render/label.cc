#include "render/label.h"

#include <cairo.h>

#include <algorithm>

#include "render/cairo_image.h"

namespace kinograph::render {

void draw_label(Image& image, const std::string& text, double x, double y, double size_px,
                LabelAnchor anchor, const Eigen::Vector3d& color) {
  // Only the band under the label goes through cairo, so labelling a wide strip stays cheap.
  const int pad = static_cast<int>(0.35 * size_px) + 1;
  const int band_h = static_cast<int>(size_px * 1.6) + 2 * pad;
  int band_y = static_cast<int>(y);
  if (anchor == LabelAnchor::kBottomCenter) band_y -= band_h;
  band_y = std::max(0, std::min(band_y, image.height - band_h));
  if (band_h > image.height) return;
  Image band(image.width, band_h);
  for (int row = 0; row < band_h; ++row) {
    std::copy_n(image.at(0, band_y + row), static_cast<std::size_t>(image.width) * 4,
                band.at(0, row));
  }
  cairo_surface_t* surface = detail::to_cairo(band);
  cairo_t* cr = cairo_create(surface);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_px);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  cairo_font_extents_t font;
  cairo_font_extents(cr, &font);
  double left = x;
  if (anchor != LabelAnchor::kTopLeft) left = x - 0.5 * ext.x_advance;
  const double box_w = ext.x_advance + 2 * pad;
  const double box_h = font.ascent + font.descent + 2 * pad * 0.6;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.75);
  cairo_rectangle(cr, left - pad, 0, box_w, box_h);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, color.x(), color.y(), color.z());
  cairo_move_to(cr, left, pad * 0.6 + font.ascent);
  cairo_show_text(cr, text.c_str());
  cairo_destroy(cr);
  const Image labelled = detail::from_cairo(surface);
  cairo_surface_destroy(surface);
  image.paste(labelled, 0, band_y);
}

}  // namespace kinograph::render
