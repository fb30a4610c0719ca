#include "rigcal/camera/saddle.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace rigcal::camera {

double bilinear(const cv::Mat& gray, double x, double y) {
  const int u = static_cast<int>(std::floor(x)), v = static_cast<int>(std::floor(y));
  const double a = x - u, b = y - v;
  const uint8_t* r0 = gray.ptr<uint8_t>(v);
  const uint8_t* r1 = gray.ptr<uint8_t>(v + 1);
  return (1 - b) * ((1 - a) * r0[u] + a * r0[u + 1]) + b * ((1 - a) * r1[u] + a * r1[u + 1]);
}

namespace {

// The edges' normal directions from where the grey values on a ring around the corner cross
// their mean: four crossings, the opposite ones on the same edge. False if not four.
bool edge_normals(const cv::Mat& gray, const Eigen::Vector2d& c, double ring_px,
                  std::array<double, 2>& theta) {
  constexpr int kN = 64;
  std::array<double, kN> ring;
  double mean = 0;
  for (int k = 0; k < kN; ++k) {
    const double a = 2 * M_PI * k / kN;
    ring[k] = bilinear(gray, c.x() + ring_px * std::cos(a), c.y() + ring_px * std::sin(a));
    mean += ring[k] / kN;
  }
  std::vector<double> crossings;  // angles, rad
  for (int k = 0; k < kN; ++k) {
    const double v0 = ring[k] - mean, v1 = ring[(k + 1) % kN] - mean;
    if ((v0 < 0) != (v1 < 0)) crossings.push_back(2 * M_PI * (k + v0 / (v0 - v1)) / kN);
  }
  if (crossings.size() != 4) return false;
  for (int e = 0; e < 2; ++e) {
    // The edge's direction: the circular mean of crossings e and e + 2 (one turned by pi).
    const double a0 = crossings[e], a1 = crossings[e + 2] - M_PI;
    const double dir = std::atan2(std::sin(a0) + std::sin(a1), std::cos(a0) + std::cos(a1));
    theta[e] = dir + M_PI / 2;
  }
  return true;
}

struct Pixel {
  double x, y, value;
};

constexpr int kParameters = 7;
using Vector7 = Eigen::Matrix<double, kParameters, 1>;
using Matrix7 = Eigen::Matrix<double, kParameters, kParameters>;

// Residuals (model - image) and, if JtJ is given, the normal equations' terms, in the parameters
// p = [cx, cy, theta1, theta2, s, a, b]; edge k's normal is n_k = (cos theta_k, sin theta_k) and
// a pixel's signed distance to it d_k = n_k . (pixel - corner).
double evaluate(const std::vector<Pixel>& pixels, const Vector7& p, Matrix7* JtJ, Vector7* Jtr) {
  const Eigen::Vector2d n1(std::cos(p[2]), std::sin(p[2])), n2(std::cos(p[3]), std::sin(p[3]));
  const Eigen::Vector2d t1(-n1.y(), n1.x()), t2(-n2.y(), n2.x());  // d n_k / d theta_k
  const double s = p[4], a = p[5], b = p[6];
  const double k = 1.0 / (std::sqrt(2.0) * s), g = std::sqrt(2.0 / M_PI) / s;
  double cost = 0;
  if (JtJ) JtJ->setZero(), Jtr->setZero();
  for (const Pixel& px : pixels) {
    const Eigen::Vector2d u(px.x - p[0], px.y - p[1]);
    const double d1 = n1.dot(u), d2 = n2.dot(u);
    const double e1 = std::erf(k * d1), e2 = std::erf(k * d2);
    const double r = a + b * e1 * e2 - px.value;
    cost += r * r;
    if (!JtJ) continue;
    // d erf(d / (sqrt(2) s)) / dd = sqrt(2 / pi) / s exp(-d^2 / (2 s^2))
    const double de1 = g * std::exp(-d1 * d1 * k * k), de2 = g * std::exp(-d2 * d2 * k * k);
    const double w1 = b * de1 * e2, w2 = b * e1 * de2;  // d model / d d1, d model / d d2
    Vector7 j;
    j.head<2>() = -w1 * n1 - w2 * n2;
    j[2] = w1 * t1.dot(u);
    j[3] = w2 * t2.dot(u);
    j[4] = -(w1 * d1 + w2 * d2) / s;
    j[5] = 1.0;
    j[6] = e1 * e2;
    JtJ->selfadjointView<Eigen::Lower>().rankUpdate(j);
    *Jtr += j * r;
  }
  if (JtJ) *JtJ = JtJ->selfadjointView<Eigen::Lower>();
  return cost;
}

}  // namespace

SaddleFit fit_saddle(const cv::Mat& gray, const Eigen::Vector2d& start, double radius_px,
                     double max_shift_px) {
  CV_Assert(gray.type() == CV_8UC1);
  SaddleFit fit;
  fit.corner = start;
  const int R = static_cast<int>(std::ceil(radius_px));
  const int u0 = static_cast<int>(std::lround(start.x())),
            v0 = static_cast<int>(std::lround(start.y()));
  if (u0 - R - 1 < 0 || v0 - R - 1 < 0 || u0 + R + 1 >= gray.cols || v0 + R + 1 >= gray.rows)
    return fit;
  std::vector<Pixel> pixels;
  for (int v = v0 - R; v <= v0 + R; ++v) {
    for (int u = u0 - R; u <= u0 + R; ++u) {
      if ((Eigen::Vector2d(u, v) - start).norm() <= radius_px)
        pixels.push_back({double(u), double(v), double(gray.at<uint8_t>(v, u))});
    }
  }
  if (pixels.size() < 16) return fit;
  std::array<double, 2> theta;
  if (!edge_normals(gray, start, std::max(1.5, 0.7 * radius_px), theta)) return fit;
  Vector7 p;
  p << start.x(), start.y(), theta[0], theta[1], 1.0, 0.0, 0.0;
  Matrix7 JtJ;
  Vector7 Jtr;
  // a and b, linear given the rest: one Gauss-Newton step in them alone from a = b = 0.
  evaluate(pixels, p, &JtJ, &Jtr);
  p.tail<2>() = JtJ.bottomRightCorner<2, 2>().ldlt().solve(-Jtr.tail<2>());
  double cost = evaluate(pixels, p, &JtJ, &Jtr), lambda = 1e-3;
  bool converged = false;
  for (int it = 0; it < 50 && !converged; ++it) {
    Matrix7 A = JtJ;
    A.diagonal() *= 1.0 + lambda;
    const Vector7 step = A.ldlt().solve(-Jtr);
    if (!step.allFinite()) return fit;
    Vector7 q = p + step;
    q[4] = std::clamp(q[4], 0.2, 10.0);
    const double c = evaluate(pixels, q, nullptr, nullptr);
    if (c < cost) {
      converged = step.head<2>().norm() < 1e-5 && cost - c < 1e-9 * cost + 1e-12;
      p = q, cost = c, lambda = std::max(1e-7, lambda / 10);
      evaluate(pixels, p, &JtJ, &Jtr);
    } else {
      lambda *= 10;
      converged = lambda > 1e6;  // no step lowers the cost: at the minimum
    }
  }
  fit.corner = p.head<2>();
  fit.blur_px = p[4];
  fit.contrast_dn = std::abs(p[6]);
  fit.ok = converged && (fit.corner - start).norm() <= max_shift_px && p[4] < 10.0 &&
           fit.contrast_dn > 5.0;
  if (!fit.ok) fit.corner = start;
  return fit;
}

}  // namespace rigcal::camera
