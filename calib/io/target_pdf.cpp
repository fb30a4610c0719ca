#include "rigcal/io/target_pdf.h"

#include <cairo-pdf.h>
#include <cairo.h>
#include <fmt/format.h>

#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/version.h"

namespace rigcal::io {
namespace {

constexpr double kPtPerM = 72.0 / 0.0254;  // PDF points per metre
constexpr double kPageMargin = 0.020;      // m

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string target_pdf(const camera::Target& t) {
  camera::validate(t);
  const camera::Outline o = camera::outline(t);
  const double page_w = (o.width() + 2 * kPageMargin) * kPtPerM;
  const double page_h = (o.height() + 2 * kPageMargin) * kPtPerM + 24.0;  // text line below
  std::string pdf;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(append, &pdf, page_w, page_h);
  cairo_t* cr = cairo_create(surface);
  // Board frame -> page: x right; checkerboard rows go down the page, AprilGrid rows go up.
  const bool rows_up = t.type == camera::TargetType::aprilgrid;
  auto X = [&](double x) { return (kPageMargin + x - o.x_min) * kPtPerM; };
  auto Y = [&](double y) {
    return (kPageMargin + (rows_up ? o.y_max - y : y - o.y_min)) * kPtPerM;
  };
  auto black_rect = [&](double x0, double y0, double x1, double y1) {
    const double a = X(x0), b = X(x1), c = Y(y0), d = Y(y1);
    cairo_rectangle(cr, std::min(a, b), std::min(c, d), std::abs(b - a), std::abs(d - c));
  };
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  // The board's outline, thin and grey, to cut along.
  cairo_set_source_rgb(cr, 0.7, 0.7, 0.7);
  cairo_set_line_width(cr, 0.3);
  cairo_rectangle(cr, X(o.x_min), std::min(Y(o.y_min), Y(o.y_max)), o.width() * kPtPerM,
                  o.height() * kPtPerM);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  if (t.type == camera::TargetType::checkerboard) {
    for (int j = -1; j < t.rows; ++j) {
      for (int i = -1; i < t.cols; ++i) {
        if (((i + j) % 2 + 2) % 2 == 0)
          black_rect(i * t.square, j * t.square, (i + 1) * t.square, (j + 1) * t.square);
      }
    }
  } else {
    // Every cell of the pattern, read from the same definition the simulator renders.
    const camera::Pattern pattern(t);
    const double gap = t.tag_size * t.tag_spacing, pitch = t.tag_size + gap, cell = t.tag_size / 10;
    for (int r = 0; r <= t.rows; ++r) {
      for (int c = 0; c <= t.cols; ++c) {
        black_rect(c * pitch - gap, r * pitch - gap, c * pitch, r * pitch);  // corner squares
        if (r == t.rows || c == t.cols) continue;
        for (int v = 0; v < 10; ++v) {
          for (int u = 0; u < 10; ++u) {
            const double x = c * pitch + u * cell, y = r * pitch + v * cell;
            if (pattern.albedo(x + 0.5 * cell, y + 0.5 * cell) < 0.5)
              black_rect(x, y, x + cell, y + cell);
          }
        }
      }
    }
  }
  cairo_fill(cr);
  // Margin text and a 100 mm scale bar.
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 9.0);
  const std::string desc =
      t.type == camera::TargetType::checkerboard
          ? fmt::format(
                "{}: checkerboard, {} x {} inner corners, squares {:.1f} mm; board {:.1f} x {:.1f} "
                "mm.",
                t.name, t.cols, t.rows, 1000 * t.square, 1000 * o.width(), 1000 * o.height())
          : fmt::format(
                "{}: AprilGrid tag36h11, {} x {} tags of {:.1f} mm, spacing {:g}; tag 0 bottom "
                "left; board {:.1f} x {:.1f} mm.",
                t.name, t.cols, t.rows, 1000 * t.tag_size, t.tag_spacing, 1000 * o.width(),
                1000 * o.height());
  const double text_y = (o.height() + 2 * kPageMargin) * kPtPerM + 6.0;
  cairo_move_to(cr, kPageMargin * kPtPerM, text_y);
  cairo_show_text(cr, desc.c_str());
  cairo_move_to(cr, kPageMargin * kPtPerM, text_y + 11.0);
  cairo_show_text(cr, fmt::format("Print at 100 % (no fit-to-page). The bar measures 100 mm. {}",
                                  version_string())
                          .c_str());
  const double bar_y = (o.height() + kPageMargin) * kPtPerM + 0.5 * kPageMargin * kPtPerM;
  cairo_rectangle(cr, kPageMargin * kPtPerM, bar_y, 0.100 * kPtPerM, 2.0);
  cairo_fill(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    throw Error(fmt::format("cairo: {}", cairo_status_to_string(status)));
  return pdf;
}

}  // namespace rigcal::io
