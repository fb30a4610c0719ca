#include "rigcal/gt/spherical_image.h"

#include <algorithm>
#include <numbers>

namespace rigcal::gt {

SphericalProjection spherical_projection(const Scan& scan) {
  SphericalProjection out;
  int rows = 0;
  for (const ScanPoint& p : scan.points) rows = std::max(rows, int(p.ring) + 1);
  if (rows < 2) return out;
  std::vector<double> elevation_sum(size_t(rows), 0.0);
  std::vector<size_t> count(size_t(rows), 0);
  for (const ScanPoint& p : scan.points) {
    const Eigen::Vector3d q = p.p.cast<double>();
    elevation_sum[p.ring] += std::atan2(q.z(), std::hypot(q.x(), q.y()));
    ++count[p.ring];
  }
  const size_t cols = *std::max_element(count.begin(), count.end());
  // The row's line through the beams' mean elevations (least squares over the beams with points:
  // the top ones see the sky outdoors).
  double n = 0, se = 0, sr = 0, see = 0, ser = 0;
  for (size_t r = 0; r < count.size(); ++r) {
    if (count[r] == 0) continue;
    const double e = elevation_sum[r] / double(count[r]);
    n += 1, se += e, sr += double(r), see += e * e, ser += e * double(r);
  }
  const double det = n * see - se * se;
  if (n < 2 || cols < 2 || !(std::abs(det) > 1e-12)) return out;
  const double fy = (n * ser - se * sr) / det;
  if (!(fy < 0)) return out;  // row 0 the top beam
  out.rows = rows;
  out.cols = int(cols);
  out.fx = -double(cols) / (2 * std::numbers::pi);  // azimuth clockwise, as Ouster's columns
  out.cx = double(cols) / 2;
  out.fy = fy;
  out.cy = (sr - fy * se) / n;
  return out;
}

SphericalImage spherical_image(const std::vector<Eigen::Vector3d>& p_sensor,
                               const std::vector<float>& intensity,
                               const SphericalProjection& projection) {
  SphericalImage out;
  out.projection = projection;
  const int rows = projection.rows, cols = projection.cols;
  const size_t n = size_t(rows) * size_t(cols);
  out.range_m.assign(n, 0.0);
  out.intensity.assign(n, 0.0);
  // Where in its pixel each kept point fell (its offset from the pixel's centre, px).
  std::vector<double> du(n, 0.0), dv(n, 0.0);
  for (size_t i = 0; i < p_sensor.size(); ++i) {
    double u = 0, v = 0;
    projection.project(p_sensor[i], &u, &v);
    const long c = std::lround(u), r = std::lround(v);
    if (r < 0 || r >= rows) continue;
    const long col = ((c % cols) + cols) % cols;
    const size_t pixel = size_t(r) * size_t(cols) + size_t(col);
    const double range = p_sensor[i].norm();
    if (out.range_m[pixel] == 0 || range < out.range_m[pixel]) {
      out.range_m[pixel] = range;
      out.intensity[pixel] = intensity[i];
      du[pixel] = u - double(c);
      dv[pixel] = v - double(r);
    }
  }
  // Each value moved to its pixel's centre along the image's slope there (central differences
  // over the neighbours' own positions), where both neighbours hold a point of the same surface
  // (ranges within 5 %): the interpolation reads the pixels as samples at their centres, and a
  // point off its centre by a fraction of a pixel (a deskewed sweep's are, by the turn during
  // the sweep) is otherwise read a fraction of a pixel away: on a wall seen at a slant, centimetres
  // of range, the same way over a whole wall.
  const std::vector<double> range = out.range_m, value = out.intensity;
  auto index = [cols](int r, int c) { return size_t(r) * size_t(cols) + size_t((c + cols) % cols); };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const size_t i = index(r, c);
      if (range[i] == 0) continue;
      auto correct = [&](size_t a, size_t b, double step, double offset) {
        if (range[a] == 0 || range[b] == 0) return;
        if (std::abs(range[a] - range[i]) > 0.05 * range[i] ||
            std::abs(range[b] - range[i]) > 0.05 * range[i])
          return;
        out.range_m[i] -= (range[b] - range[a]) / step * offset;
        out.intensity[i] -= (value[b] - value[a]) / step * offset;
      };
      const size_t left = index(r, c - 1), right = index(r, c + 1);
      correct(left, right, 2.0 + du[right] - du[left], du[i]);
      if (r > 0 && r + 1 < rows) {
        const size_t up = index(r - 1, c), down = index(r + 1, c);
        correct(up, down, 2.0 + dv[down] - dv[up], dv[i]);
      }
    }
  }
  return out;
}

}  // namespace rigcal::gt
