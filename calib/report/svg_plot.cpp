#include "rigcal/report/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "rigcal/report/png.h"

namespace rigcal::report {
namespace {

constexpr double kW = 900, kH = 620, kLeft = 80, kRight = 150, kTop = 50, kBottom = 60;
constexpr const char* kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

// Viridis, five anchors, linear in between.
std::string viridis(double f) {
  static const double anchors[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  f = std::clamp(std::isfinite(f) ? f : 0.0, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(f));
  const double t = f - i;
  int rgb[3];
  for (int k = 0; k < 3; ++k)
    rgb[k] = static_cast<int>(anchors[i][k] + t * (anchors[i + 1][k] - anchors[i][k]));
  return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
}

double nice_step(double range, int target) {
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= m * mag) return m * mag;
  }
  return 10 * mag;
}

// The data bounds of a plot (x0..x1, y0..y1) and of its colour values (v0..v1), widened where
// degenerate and made equal-scaled when the plot asks for it.
struct Bounds {
  double x0, x1, y0, y1, v0, v1, sx, sy;
};

Bounds bounds(const Plot& plot, double pw, double ph) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  double v0 = x0, v1 = -x0;
  for (const PlotSeries& s : plot.series) {
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {  // boxes have no y
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const double e = i < s.y_error.size() && std::isfinite(s.y_error[i]) ? s.y_error[i] : 0.0;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i] - e), y1 = std::max(y1, s.y[i] + e);
    }
    for (double v : s.values) {
      if (std::isfinite(v)) v0 = std::min(v0, v), v1 = std::max(v1, v);
    }
    if (s.bars && !s.x.empty()) y0 = std::min(y0, 0.0), y1 = std::max(y1, 0.0);
    const double half = 0.5 * s.width;
    for (size_t i = 0; i < s.x.size() && (s.bars || !s.boxes.empty()); ++i) {
      if (std::isfinite(s.x[i])) x0 = std::min(x0, s.x[i] - half), x1 = std::max(x1, s.x[i] + half);
    }
    for (const auto& b : s.boxes) y0 = std::min(y0, b[0]), y1 = std::max(y1, b[4]);
  }
  for (const auto& [x, label] : plot.x_ticks) x0 = std::min(x0, x), x1 = std::max(x1, x);
  if (plot.grid) {
    const PlotGrid& g = *plot.grid;
    x0 = std::min(x0, g.x0), x1 = std::max(x1, g.x0 + g.cols * g.cell);
    y0 = std::min(y0, g.y0), y1 = std::max(y1, g.y0 + g.rows * g.cell);
    for (double v : g.values) {
      if (std::isfinite(v)) v0 = std::min(v0, v), v1 = std::max(v1, v);
    }
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (plot.limits.size() == 4)
    x0 = plot.limits[0], x1 = plot.limits[1], y0 = plot.limits[2], y1 = plot.limits[3];
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12) y0 -= 0.5, y1 += 0.5;
  if (!plot.equal_axes &&
      plot.limits.size() !=
          4) {  // a margin, so that points on the extremes are not cut by the frame
    const double m = 0.03 * (y1 - y0);
    y0 -= m, y1 += m;
    // Bars and boxes are drawn whole, clear of the frame.
    const bool blocks = std::any_of(plot.series.begin(), plot.series.end(),
                                    [](const auto& s) { return s.bars || !s.boxes.empty(); });
    const double mx = blocks ? 0.04 * (x1 - x0) : 0.0;
    x0 -= mx, x1 += mx;
  }
  double sx = pw / (x1 - x0), sy = ph / (y1 - y0);
  if (plot.equal_axes) {
    const double s = std::min(sx, sy);
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    sx = sy = s;
    x0 = cx - pw / (2 * s), x1 = cx + pw / (2 * s);
    y0 = cy - ph / (2 * s), y1 = cy + ph / (2 * s);
  }
  return {x0, x1, y0, y1, v0, v1, sx, sy};
}

// The grid's cells, then its contour lines (marching squares over the cells' centres, a saddle
// split the same way every time), as SVG in plot coordinates mapped by X and Y.
template <typename FX, typename FY>
std::string grid_svg(const PlotGrid& g, double v0, double v1, FX X, FY Y) {
  std::string out;
  auto at = [&](int c, int r) { return g.values[static_cast<size_t>(r) * g.cols + c]; };
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      const double xa = X(g.x0 + c * g.cell), xb = X(g.x0 + (c + 1) * g.cell);
      const double ya = Y(g.y0 + r * g.cell), yb = Y(g.y0 + (r + 1) * g.cell);
      const double f = v1 > v0 ? (at(c, r) - v0) / (v1 - v0) : 0.0;
      out += fmt::format(
          "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\"/>\n",
          std::min(xa, xb), std::min(ya, yb), std::abs(xb - xa) + 0.4, std::abs(yb - ya) + 0.4,
          viridis(f));
    }
  }
  for (const double level : g.contours) {
    std::string path;
    for (int r = 0; r + 1 < g.rows; ++r) {
      for (int c = 0; c + 1 < g.cols; ++c) {
        // The square's corners counter-clockwise and the crossings on its four edges.
        const int cc[4] = {c, c + 1, c + 1, c}, rr[4] = {r, r, r + 1, r + 1};
        std::vector<std::pair<double, double>> cross;
        for (int e = 0; e < 4; ++e) {
          const double a = at(cc[e], rr[e]), b = at(cc[(e + 1) % 4], rr[(e + 1) % 4]);
          if (!std::isfinite(a) || !std::isfinite(b) || (a < level) == (b < level)) continue;
          const double t = (level - a) / (b - a);
          const double x = cc[e] + t * (cc[(e + 1) % 4] - cc[e]);
          const double y = rr[e] + t * (rr[(e + 1) % 4] - rr[e]);
          cross.emplace_back(g.x0 + (x + 0.5) * g.cell, g.y0 + (y + 0.5) * g.cell);
        }
        for (size_t k = 0; k + 1 < cross.size(); k += 2) {
          path += fmt::format("M{:.1f} {:.1f}L{:.1f} {:.1f}", X(cross[k].first), Y(cross[k].second),
                              X(cross[k + 1].first), Y(cross[k + 1].second));
        }
      }
    }
    if (path.empty()) continue;
    // Labelled where the line starts (its first segment's first point).
    double lx = 0, ly = 0;
    std::sscanf(path.c_str(), "M%lf %lf", &lx, &ly);
    out += fmt::format(
        "<path d=\"{}\" fill=\"none\" stroke=\"white\" stroke-width=\"1.2\"/>\n<text x=\"{:.1f}\" "
        "y=\"{:.1f}\" fill=\"white\" font-size=\"11\">{:g}</text>\n",
        path, lx + 3, ly - 3, level);
  }
  return out;
}

}  // namespace

std::string render_svg(const Plot& plot) {
  const double pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  // The lambdas copy the bindings: clang 14 (the sanitizer build) cannot capture a binding.
  const auto [x0, x1, y0, y1, v0, v1, sx, sy] = bounds(plot, pw, ph);
  auto X = [&, x0 = x0, sx = sx](double x) { return kLeft + (x - x0) * sx; };
  auto Y = [&, y0 = y0, sy = sy](double y) {
    return plot.y_down ? kTop + (y - y0) * sy : kTop + ph - (y - y0) * sy;
  };

  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
      "font-family=\"sans-serif\" "
      "font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      kW, kH);
  out += fmt::format("<text x=\"{}\" y=\"28\" font-size=\"16\" text-anchor=\"middle\">{}</text>\n",
                     kLeft + pw / 2, escape(plot.title));
  // Grid and ticks.
  const double xs = nice_step(x1 - x0, 8), ys = nice_step(y1 - y0, 8);
  for (double x = std::ceil(x0 / xs) * xs; plot.x_ticks.empty() && x <= x1 + 1e-9 * xs; x += xs) {
    out += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#e0e0e0\"/>"
        "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\">{4:g}</text>\n",
        X(x), kTop, kTop + ph, kTop + ph + 16, std::abs(x) < 1e-12 * xs ? 0.0 : x);
  }
  for (const auto& [x, label] : plot.x_ticks) {
    out += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", X(x),
                       kTop + ph + 16, escape(label));
  }
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys) {
    out += fmt::format(
        "<line x1=\"{1:.1f}\" y1=\"{0:.1f}\" x2=\"{2:.1f}\" y2=\"{0:.1f}\" stroke=\"#e0e0e0\"/>"
        "<text x=\"{3:.1f}\" y=\"{4:.1f}\" text-anchor=\"end\">{5:g}</text>\n",
        Y(y), kLeft, kLeft + pw, kLeft - 6, Y(y) + 4, std::abs(y) < 1e-12 * ys ? 0.0 : y);
  }
  out += fmt::format(
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n",
      kLeft, kTop, pw, ph);
  out += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", kLeft + pw / 2,
                     kH - 18, escape(plot.x_label));
  out += fmt::format(
      "<text transform=\"translate(20 {}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
      kTop + ph / 2, escape(plot.y_label));
  out += fmt::format(
      "<clipPath id=\"area\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n<g "
      "clip-path=\"url(#area)\">\n",
      kLeft, kTop, pw, ph);
  if (plot.grid) out += grid_svg(*plot.grid, v0, v1, X, Y);
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const size_t stride = std::max<size_t>(1, s.x.size() / 4000);
    const char* colour = kPalette[k % 10];
    const double w = s.width * sx;  // in pixels
    if (s.bars) {
      for (size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        const double ya = Y(std::max(s.y[i], 0.0)), yb = Y(std::min(s.y[i], 0.0));
        out += fmt::format(
            "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\" "
            "fill-opacity=\"0.55\" stroke=\"{}\" stroke-width=\"0.6\"/>\n",
            X(s.x[i]) - 0.5 * w, std::min(ya, yb), w, std::abs(yb - ya), colour, colour);
      }
      continue;
    }
    if (!s.boxes.empty()) {
      for (size_t i = 0; i < s.boxes.size() && i < s.x.size(); ++i) {
        const auto& b = s.boxes[i];
        const double cx = X(s.x[i]), l = cx - 0.5 * w, r = cx + 0.5 * w;
        out += fmt::format(
            "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"{5}\"/>"
            "<line x1=\"{0:.1f}\" y1=\"{3:.1f}\" x2=\"{0:.1f}\" y2=\"{4:.1f}\" stroke=\"{5}\"/>\n",
            cx, Y(b[0]), Y(b[1]), Y(b[3]), Y(b[4]), colour);
        for (double y : {b[0], b[4]}) {
          out += fmt::format(
              "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\"/>\n",
              cx - 0.25 * w, Y(y), cx + 0.25 * w, Y(y), colour);
        }
        out += fmt::format(
            "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\" "
            "fill-opacity=\"0.35\" stroke=\"{}\"/>\n",
            l, Y(b[3]), w, Y(b[1]) - Y(b[3]), colour, colour);
        out += fmt::format(
            "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
            "stroke-width=\"2.5\"/>\n",
            l, Y(b[2]), r, Y(b[2]), colour);
      }
      continue;
    }
    if (!s.values.empty()) {
      for (size_t i = 0; i < s.x.size(); i += stride) {
        const double f = v1 > v0 ? (s.values[i] - v0) / (v1 - v0) : 0.0;
        out += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2\" fill=\"{}\"/>\n", X(s.x[i]),
                           Y(s.y[i]), viridis(f));
      }
      continue;
    }
    if (s.points || !s.y_error.empty()) {
      for (size_t i = 0; i < s.x.size(); i += stride) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        if (i < s.y_error.size() && std::isfinite(s.y_error[i])) {
          out += fmt::format(
              "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" "
              "stroke=\"{3}\"/>\n",
              X(s.x[i]), Y(s.y[i] - s.y_error[i]), Y(s.y[i] + s.y_error[i]), kPalette[k % 10]);
        }
        out += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"{}\"/>\n",
                           X(s.x[i]), Y(s.y[i]), kPalette[k % 10]);
      }
      continue;
    }
    std::string points;
    for (size_t i = 0; i < s.x.size(); i += stride) {
      if (!std::isfinite(s.y[i])) continue;
      if (plot.step && !points.empty())
        points += fmt::format("{:.1f},{:.1f} ", X(s.x[i]), Y(s.y[i - stride]));
      points += fmt::format("{:.1f},{:.1f} ", X(s.x[i]), Y(s.y[i]));
    }
    out +=
        fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" points=\"{}\"/>\n",
                    kPalette[k % 10], points);
  }
  out += "</g>\n";
  // Legend and colour bar on the right.
  double ly = kTop + 10;
  for (size_t k = 0; k < plot.series.size(); ++k) {
    if (!plot.series[k].values.empty() || plot.series[k].label.empty()) continue;
    out += fmt::format(
        "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{3}\" stroke-width=\"3\"/>"
        "<text x=\"{4}\" y=\"{5}\">{6}</text>\n",
        kW - kRight + 10, ly, kW - kRight + 30, kPalette[k % 10], kW - kRight + 35, ly + 4,
        escape(plot.series[k].label));
    ly += 18;
  }
  if (std::isfinite(v0)) {
    const double bx = kW - kRight + 20, bh = ph * 0.6, by = kTop + ph * 0.3;
    for (int i = 0; i < 50; ++i) {
      out +=
          fmt::format("<rect x=\"{}\" y=\"{:.1f}\" width=\"16\" height=\"{:.1f}\" fill=\"{}\"/>\n",
                      bx, by + bh - (i + 1) * bh / 50, bh / 50 + 0.5, viridis(i / 49.0));
    }
    out +=
        fmt::format("<text x=\"{}\" y=\"{}\">{:.3g}</text><text x=\"{}\" y=\"{}\">{:.3g}</text>\n",
                    bx + 22, by + 4, v1, bx + 22, by + bh + 4, v0);
    out += fmt::format("<text x=\"{}\" y=\"{}\">{}</text>\n", bx - 4, by - 10,
                       escape(plot.value_label));
  }
  out += "</svg>\n";
  return out;
}

}  // namespace rigcal::report

namespace rigcal::report {

std::string render_png(const Plot& plot) {
  const double pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  // The lambdas copy the bindings: clang 14 (the sanitizer build) cannot capture a binding.
  const auto [x0, x1, y0, y1, v0, v1, sx, sy] = bounds(plot, pw, ph);
  auto X = [&, x0 = x0, sx = sx](double x) { return kLeft + (x - x0) * sx; };
  auto Y = [&, y0 = y0, sy = sy](double y) {
    return plot.y_down ? kTop + (y - y0) * sy : kTop + ph - (y - y0) * sy;
  };
  auto P = [](double x, double y) { return cv::Point(cvRound(x), cvRound(y)); };
  cv::Mat img(static_cast<int>(kH), static_cast<int>(kW), CV_8UC3, cv::Scalar(255, 255, 255));
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  auto text = [&](const std::string& t, double x, double y, double scale, int align) {
    int base = 0;
    const cv::Size size = cv::getTextSize(t, font, scale, 1, &base);
    const double left = align == 0 ? x : (align == 1 ? x - size.width / 2.0 : x - size.width);
    cv::putText(img, t, P(left, y), font, scale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  };
  text(plot.title, kLeft + pw / 2, 22, 0.6, 1);
  const double xs = nice_step(x1 - x0, 8), ys = nice_step(y1 - y0, 8);
  for (double x = std::ceil(x0 / xs) * xs; plot.x_ticks.empty() && x <= x1 + 1e-9 * xs; x += xs) {
    cv::line(img, P(X(x), kTop), P(X(x), kTop + ph), cv::Scalar(224, 224, 224));
    text(fmt::format("{:g}", std::abs(x) < 1e-12 * xs ? 0.0 : x), X(x), kTop + ph + 18, 0.4, 1);
  }
  for (const auto& [x, label] : plot.x_ticks) text(label, X(x), kTop + ph + 18, 0.4, 1);
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys) {
    cv::line(img, P(kLeft, Y(y)), P(kLeft + pw, Y(y)), cv::Scalar(224, 224, 224));
    text(fmt::format("{:g}", std::abs(y) < 1e-12 * ys ? 0.0 : y), kLeft - 6, Y(y) + 4, 0.4, 2);
  }
  cv::rectangle(img, P(kLeft, kTop), P(kLeft + pw, kTop + ph), cv::Scalar(0, 0, 0));
  text(plot.x_label, kLeft + pw / 2, kH - 18, 0.45, 1);
  text(plot.y_label, 8, kTop - 8, 0.45, 0);
  // Series, clipped to the plot area; colours as in the SVG (BGR).
  cv::Mat area = img(cv::Rect(static_cast<int>(kLeft), static_cast<int>(kTop), static_cast<int>(pw),
                              static_cast<int>(ph)));
  auto colour = [](size_t k) {
    unsigned v = 0;
    std::sscanf(kPalette[k % 10] + 1, "%x", &v);
    return cv::Scalar(v & 0xff, (v >> 8) & 0xff, (v >> 16) & 0xff);
  };
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const double w = s.width * sx;
    auto box = [&](double xc, double ya, double yb, int thickness) {
      cv::rectangle(area, P(X(xc) - 0.5 * w - kLeft, Y(ya) - kTop),
                    P(X(xc) + 0.5 * w - kLeft, Y(yb) - kTop), colour(k), thickness);
    };
    if (s.bars) {
      for (size_t i = 0; i < s.x.size(); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) box(s.x[i], 0.0, s.y[i], 1);
      }
      continue;
    }
    for (size_t i = 0; i < s.boxes.size() && i < s.x.size(); ++i) {
      const auto& b = s.boxes[i];
      const double cx = X(s.x[i]) - kLeft;
      cv::line(area, P(cx, Y(b[0]) - kTop), P(cx, Y(b[1]) - kTop), colour(k));
      cv::line(area, P(cx, Y(b[3]) - kTop), P(cx, Y(b[4]) - kTop), colour(k));
      box(s.x[i], b[1], b[3], 1);
      cv::line(area, P(cx - 0.5 * w, Y(b[2]) - kTop), P(cx + 0.5 * w, Y(b[2]) - kTop), colour(k),
               2);
    }
    if (!s.boxes.empty()) continue;
    std::vector<cv::Point> pts;
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]))
        pts.push_back(P(X(s.x[i]) - kLeft, Y(s.y[i]) - kTop));
    }
    if (!s.values.empty() || s.points || !s.y_error.empty()) {
      const int radius = s.values.empty() && s.x.size() < 50 ? 5 : 2;  // a few marked points
      for (size_t i = 0; i < pts.size(); ++i)
        cv::circle(area, pts[i], radius, colour(k), cv::FILLED);
    } else if (pts.size() > 1) {
      cv::polylines(area, pts, false, colour(k), 1, cv::LINE_AA);
    }
  }
  double ly = kTop + 10;
  for (size_t k = 0; k < plot.series.size(); ++k) {
    if (plot.series[k].label.empty()) continue;
    cv::line(img, P(kW - kRight + 10, ly), P(kW - kRight + 30, ly), colour(k), 3);
    text(plot.series[k].label, kW - kRight + 35, ly + 4, 0.4, 0);
    ly += 18;
  }
  return encode_png(img);
}

}  // namespace rigcal::report
