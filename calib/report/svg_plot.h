#pragma once
// Small SVG plots for reports: lines (one colour a series), points coloured by a value with a
// colour bar, bars and box plots. Enough for trajectory top views, errors along a trajectory and
// cumulative curves; files open in any browser. Long series are thinned to at most 4000 points a
// series.
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rigcal::report {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  std::vector<double> values;  // non-empty: draw points coloured by these (viridis), with a bar
  bool points = false;         // markers in the series' colour instead of a line
  std::vector<double> y_error = {};  // non-empty: markers with bars of +- these (1-sigma) in y
  // Bars: each (x, y) drawn as a bar from 0 to y, `width` wide in x (translucent, so that
  // histograms of several series show through each other).
  bool bars = false;
  double width = 0;
  // Box plots: at each x, {low whisker, first quartile, median, third quartile, high whisker},
  // drawn `width` wide (y unused).
  std::vector<std::array<double, 5>> boxes = {};
};

// A field over a regular grid (an image's cells): drawn as coloured cells (viridis, with the
// colour bar) under the series, with contour lines at `contours` (marching squares over the
// cells' centres). SVG only.
struct PlotGrid {
  int cols = 0, rows = 0;
  double x0 = 0, y0 = 0, cell = 1;  // the first cell's corner and the cells' side (plot units)
  std::vector<double> values;       // row-major, rows along y
  std::vector<double> contours;     // levels, in the values' units
};

struct Plot {
  std::string title, x_label, y_label, value_label;
  std::vector<PlotSeries> series;
  bool equal_axes = false;          // same scale on x and y (top views)
  bool step = false;                // draw lines as steps (cumulative curves)
  bool y_down = false;              // y grows downwards (image rows)
  std::vector<double> limits = {};  // empty, or x0 x1 y0 y1: the axes' range (an image's extent)
  std::optional<PlotGrid> grid = {};
  // Non-empty: these labels at these x instead of numbered ticks (categories: results, statistics).
  std::vector<std::pair<double, std::string>> x_ticks = {};
};

std::string render_svg(const Plot& plot);
// The same plot as PNG bytes (lines and points; no colour bar), for reports that ask for PNG.
std::string render_png(const Plot& plot);

}  // namespace rigcal::report
