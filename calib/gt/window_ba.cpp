#include "rigcal/gt/window_ba.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/gt/sweep_point_to_plane_error.h"
#include "rigcal/lidar/preprocess.h"

namespace rigcal::gt {
namespace {

// A point of a scan: where the sensor saw it, the knot before its time and its time as a
// fraction of the way from that knot to the next.
struct SweepPoint {
  Eigen::Vector3d p_lidar;
  uint32_t knot = 0;
  double fraction = 0;
};
using ScanPoints = std::vector<SweepPoint>;

// Each scan's points placed in the world by the knots (the internal ones, knots_per_sweep a scan).
std::vector<std::vector<Eigen::Vector3d>> placed(const std::vector<ScanPoints>& points,
                                                 const std::vector<SE3>& T_world_knot) {
  std::vector<Eigen::Vector3d> phi(T_world_knot.size() - 1);  // each segment's turn
  std::vector<SE3> T_a_b(T_world_knot.size() - 1);
  for (size_t j = 0; j + 1 < T_world_knot.size(); ++j) {
    T_a_b[j] = T_world_knot[j].inverse() * T_world_knot[j + 1];
    phi[j] = rotation_vector(T_a_b[j].R);
  }
  std::vector<std::vector<Eigen::Vector3d>> out(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    out[k].reserve(points[k].size());
    for (const SweepPoint& p : points[k]) {
      const SE3& T_world_a = T_world_knot[p.knot];
      const SE3 T_world_point =
          p.fraction == 0 ? T_world_a
                          : T_world_a * SE3::from_rotation_vector(p.fraction * phi[p.knot],
                                                                  p.fraction * T_a_b[p.knot].t);
      out[k].push_back(T_world_point * p.p_lidar);
    }
  }
  return out;
}

// One residual: point `index` of scan `scan` on plane `plane`.
struct Association {
  uint32_t scan = 0, index = 0, plane = 0;
};
struct Associations {
  std::vector<PlanePatch> planes;  // those seen by two scans or more; their members cleared
  std::vector<Association> points;
};

// The patches of the scans' placed points, and the points kept of each.
Associations associate(const std::vector<std::vector<Eigen::Vector3d>>& points_world,
                       const WindowBaConfig& config) {
  std::vector<Eigen::Vector3d> world;
  std::vector<uint32_t> scan_of_point, index_in_scan;
  for (size_t k = 0; k < points_world.size(); ++k) {
    for (size_t i = 0; i < points_world[k].size(); ++i) {
      world.push_back(points_world[k][i]);
      scan_of_point.push_back(uint32_t(k));
      index_in_scan.push_back(uint32_t(i));
    }
  }
  Associations out;
  std::unordered_map<uint32_t, std::vector<uint32_t>> by_scan;
  for (PlanePatch& patch : plane_patches(world, config.patches, &scan_of_point)) {
    by_scan.clear();
    for (uint32_t m : patch.members) by_scan[scan_of_point[m]].push_back(index_in_scan[m]);
    size_t scans = 0;
    for (const auto& [scan, members] : by_scan)
      scans += members.size() >= config.min_points_per_scan;
    if (scans < 2) continue;
    const uint32_t plane = uint32_t(out.planes.size());
    for (const auto& [scan, members] : by_scan) {
      if (members.size() < config.min_points_per_scan) continue;
      const size_t n = std::min(members.size(), config.max_points_per_scan);
      for (size_t j = 0; j < n; ++j)
        out.points.push_back({scan, members[j * members.size() / n], plane});
    }
    patch.members.clear();
    out.planes.push_back(std::move(patch));
  }
  return out;
}

// The points' rms distance to their patches' planes (the planes as found).
double rms_distance(const Associations& a,
                    const std::vector<std::vector<Eigen::Vector3d>>& points_world) {
  if (a.points.empty()) return 0;
  double sum = 0;
  for (const Association& r : a.points) {
    const PlanePatch& plane = a.planes[r.plane];
    const double d = plane.normal.dot(points_world[r.scan][r.index] - plane.centroid);
    sum += d * d;
  }
  return std::sqrt(sum / double(a.points.size()));
}

int threads(const WindowBaConfig& config) {
  return config.threads > 0 ? config.threads
                            : int(std::max(1u, std::thread::hardware_concurrency()));
}

// The motion's covariance between consecutive scan knots (`scan_knots`, indices into the internal
// knots), from the joint tangent covariance of their blocks. Ceres' quaternion tangent d is half
// the rotation vector (exp(2 d) R, on the left, in the world frame); the translation's is the
// world's. With the knots perturbed so (phi, dt), the motion R_a' R_b, R_a' (t_b - t_a) is
// perturbed by e_rot = R_a' (phi_b - phi_a) and e_t = R_a' (dt_b - dt_a) + R_a' [t_b - t_a]x phi_a,
// to first order.
std::vector<Matrix6d> step_covariances(ceres::Problem& problem, int threads,
                                       std::vector<Eigen::Quaterniond>& q,
                                       std::vector<Eigen::Vector3d>& t,
                                       const std::vector<size_t>& scan_knots, double scale) {
  const size_t knots = scan_knots.size();
  std::vector<const double*> blocks;
  for (size_t j = 0; j < q.size(); ++j)
    if (!problem.HasParameterBlock(q[j].coeffs().data())) return {};
  for (size_t k : scan_knots) {
    blocks.push_back(q[k].coeffs().data());
    blocks.push_back(t[k].data());
  }
  std::vector<std::pair<const double*, const double*>> pairs;  // each once
  for (size_t k = 0; k + 1 < knots; ++k)
    for (size_t i = 2 * k; i < 2 * k + 4; ++i)
      for (size_t j = std::max(i, 2 * k + 2); j < 2 * k + 4; ++j)
        pairs.push_back({blocks[i], blocks[j]});
  for (size_t i = 0; i < 2; ++i)  // the first knot's own blocks (the others' come with k - 1)
    for (size_t j = i; j < 2; ++j) pairs.push_back({blocks[i], blocks[j]});
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.num_threads = threads;
  ceres::Covariance covariance(options);
  if (!covariance.Compute(pairs, &problem)) return {};
  std::vector<Matrix6d> out;
  for (size_t k = 0; k + 1 < knots; ++k) {
    Eigen::Matrix<double, 12, 12> S;
    for (size_t i = 0; i < 4; ++i) {
      for (size_t j = i; j < 4; ++j) {
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c;
        covariance.GetCovarianceBlockInTangentSpace(blocks[2 * k + i], blocks[2 * k + j], c.data());
        S.block<3, 3>(3 * i, 3 * j) = c;
        S.block<3, 3>(3 * j, 3 * i) = c.transpose();
      }
    }
    const size_t a = scan_knots[k], b = scan_knots[k + 1];
    const Eigen::Matrix3d Rt = q[a].normalized().toRotationMatrix().transpose();
    Eigen::Matrix<double, 6, 12> J = Eigen::Matrix<double, 6, 12>::Zero();
    J.block<3, 3>(0, 0) = -2.0 * Rt;
    J.block<3, 3>(0, 6) = 2.0 * Rt;
    J.block<3, 3>(3, 0) = 2.0 * Rt * skew(t[b] - t[a]);
    J.block<3, 3>(3, 3) = -Rt;
    J.block<3, 3>(3, 9) = Rt;
    out.push_back(scale * J * S * J.transpose());
  }
  return out;
}

}  // namespace

WindowBaResult window_ba(const std::vector<Scan>& scans, const std::vector<SE3>& T_world_lidar,
                         Time end, const WindowBaConfig& config) {
  if (T_world_lidar.size() != scans.size() + 1)
    throw Error("window bundle adjustment: one knot a scan and one at the end are needed");
  for (size_t k = 0; k < scans.size(); ++k) {
    const Time next = k + 1 < scans.size() ? scans[k + 1].stamp : end;
    if (!(next > scans[k].stamp))
      throw Error("window bundle adjustment: the scans' stamps and the end must increase");
  }
  WindowBaResult out;
  out.T_world_lidar = T_world_lidar;
  if (scans.size() < 2) return out;
  // The internal knots: m a sweep, the scans' knots every m-th, those between them started on
  // the interpolation of the scans' knots.
  const size_t m = config.sweep_motion ? std::max(1, config.knots_per_sweep) : 1;
  std::vector<SE3> T_world_knot;
  std::vector<size_t> scan_knot;
  for (size_t k = 0; k < scans.size(); ++k) {
    scan_knot.push_back(T_world_knot.size());
    const SE3 T_a_b = T_world_lidar[k].inverse() * T_world_lidar[k + 1];
    for (size_t j = 0; j < m; ++j)
      T_world_knot.push_back(T_world_lidar[k] *
                             lidar::motion_fraction(T_a_b, double(j) / double(m)));
  }
  scan_knot.push_back(T_world_knot.size());
  T_world_knot.push_back(T_world_lidar.back());

  std::vector<ScanPoints> points(scans.size());
  for (size_t k = 0; k < scans.size(); ++k) {
    const Time next = k + 1 < scans.size() ? scans[k + 1].stamp : end;
    const double span_ns = double((next - scans[k].stamp).ns);
    const bool timed = config.sweep_motion && scans[k].point_times;
    for (const ScanPoint& p : lidar::voxel_sample(scans[k].points, config.voxel_size_m,
                                                  config.min_range_m, config.max_range_m)) {
      const double f = timed ? std::clamp(double(p.t_ns) / span_ns, 0.0, 1.0) * double(m) : 0.0;
      const size_t j = std::min(size_t(f), m - 1);
      SweepPoint point;
      point.p_lidar = p.p.cast<double>();
      point.knot = uint32_t(scan_knot[k] + j);
      point.fraction = f - double(j);
      points[k].push_back(point);
    }
  }

  const size_t knots = T_world_knot.size();
  std::vector<Eigen::Quaterniond> q(knots);
  std::vector<Eigen::Vector3d> t(knots);
  for (size_t k = 0; k < knots; ++k) {
    q[k] = Eigen::Quaterniond(T_world_knot[k].R).normalized();
    t[k] = T_world_knot[k].t;
  }
  std::unique_ptr<ceres::Problem> last;  // the last round's, for the covariances
  std::vector<Eigen::Vector4d> plane;
  for (out.rounds = 0; out.rounds < config.rounds;) {
    const auto world = placed(points, T_world_knot);
    const Associations a = associate(world, config);
    if (out.rounds == 0) out.rms_before_m = rms_distance(a, world);
    ++out.rounds;
    if (a.points.empty()) break;
    // The planes are estimated with the poses (not held at their fits: holding them, each round
    // would move the scans only part of the way towards the first one).
    // Each plane one block (its normal, then its offset): the Schur solver eliminates the planes,
    // which needs no two of its blocks in one residual.
    last.reset();
    plane.assign(a.planes.size(), Eigen::Vector4d::Zero());
    for (size_t j = 0; j < a.planes.size(); ++j) plane[j] << a.planes[j].normal, 0.0;
    last = std::make_unique<ceres::Problem>();
    ceres::Problem& problem = *last;
    auto* ordering = new ceres::ParameterBlockOrdering;
    for (const Association& r : a.points) {
      const SweepPoint& p = points[r.scan][r.index];
      const Eigen::Vector3d& c = a.planes[r.plane].centroid;
      const double w = 1.0 / config.point_sigma_m;
      auto* loss = new ceres::HuberLoss(config.huber_sigmas);
      const size_t k = p.knot;
      if (p.fraction == 0) {
        problem.AddResidualBlock(new PointToPlaneCost({p.p_lidar, c, w}), loss,
                                 q[k].coeffs().data(), t[k].data(), plane[r.plane].data());
      } else {
        problem.AddResidualBlock(new SweepPointToPlaneCost({p.p_lidar, p.fraction, c, w}), loss,
                                 q[k].coeffs().data(), t[k].data(), q[k + 1].coeffs().data(),
                                 t[k + 1].data(), plane[r.plane].data());
      }
    }
    for (size_t j = 0; j < a.planes.size(); ++j) {
      problem.SetManifold(
          plane[j].data(),
          new ceres::ProductManifold<ceres::SphereManifold<3>, ceres::EuclideanManifold<1>>{});
      ordering->AddElementToGroup(plane[j].data(), 0);
    }
    for (size_t k = 0; k < knots; ++k) {
      if (!problem.HasParameterBlock(q[k].coeffs().data())) continue;
      problem.SetManifold(q[k].coeffs().data(), new ceres::EigenQuaternionManifold);
      ordering->AddElementToGroup(q[k].coeffs().data(), 1);
      ordering->AddElementToGroup(t[k].data(), 1);
    }
    if (problem.HasParameterBlock(q[0].coeffs().data())) {
      problem.SetParameterBlockConstant(q[0].coeffs().data());
      problem.SetParameterBlockConstant(t[0].data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_SCHUR;  // the planes eliminated, the poses solved
    options.linear_solver_ordering.reset(ordering);
    options.max_num_iterations = config.max_iterations;
    options.num_threads = threads(config);
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!summary.IsSolutionUsable())
      throw Error("window bundle adjustment: the solve failed: " + summary.message);
    double moved = 0;
    for (size_t k = 1; k < knots; ++k) {
      if (!problem.HasParameterBlock(q[k].coeffs().data())) continue;
      const SE3 T = SE3::from_quaternion(q[k].normalized(), t[k]);
      moved = std::max({moved, (T.t - T_world_knot[k].t).norm(),
                        10.0 * rotation_angle(T.R * T_world_knot[k].R.transpose())});
      T_world_knot[k] = T;
    }
    for (size_t k = 0; k < scan_knot.size(); ++k) out.T_world_lidar[k] = T_world_knot[scan_knot[k]];
    out.patches = a.planes.size();
    out.residuals = a.points.size();
    if (moved < config.converged_m) break;
  }
  const auto world = placed(points, T_world_knot);
  out.rms_after_m = rms_distance(associate(world, config), world);
  if (config.step_covariances && last) {
    const double variance = std::pow(out.rms_after_m / config.point_sigma_m, 2);
    out.step_covariance =
        step_covariances(*last, threads(config), q, t, scan_knot, std::max(1.0, variance));
  }
  return out;
}

}  // namespace rigcal::gt
