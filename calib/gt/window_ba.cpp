#include "rigcal/gt/window_ba.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <thread>
#include <unordered_map>

#include "rigcal/core/error.h"
#include "rigcal/gt/photometric_error.h"
#include "rigcal/gt/point_to_plane_error.h"
#include "rigcal/gt/relative_pose_error.h"
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
  float intensity = 0;
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

// A knot as its parameter block: the quaternion (x y z w), then the translation.
using Knot = Eigen::Matrix<double, 7, 1>;
Knot knot_of(const SE3& T) {
  Knot k;
  k.head<4>() = Eigen::Quaterniond(T.R).normalized().coeffs();
  k.tail<3>() = T.t;
  return k;
}
SE3 knot_pose(const Knot& k) {
  return SE3::from_quaternion(Eigen::Quaterniond(k[3], k[0], k[1], k[2]).normalized(), k.tail<3>());
}

int threads(const WindowBaConfig& config) {
  return config.threads > 0 ? config.threads
                            : int(std::max(1u, std::thread::hardware_concurrency()));
}

// Solves `problem` with the planes eliminated (Schur) and the knots solved; throws on failure,
// naming the solve (`what`: "" or "photometric ").
void solve_knots(ceres::Problem& problem, std::vector<Eigen::Vector4d>& plane, std::vector<Knot>& x,
                 int iterations, const WindowBaConfig& config, const char* what) {
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (Eigen::Vector4d& p : plane)
    if (problem.HasParameterBlock(p.data())) ordering->AddElementToGroup(p.data(), 0);
  for (Knot& k : x)
    if (problem.HasParameterBlock(k.data())) ordering->AddElementToGroup(k.data(), 1);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;  // the planes eliminated, the poses solved
  options.linear_solver_ordering.reset(ordering);
  options.max_num_iterations = iterations;
  options.num_threads = threads(config);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Error(std::string("window bundle adjustment: the ") + what +
                "solve failed: " + summary.message);
}

// The motion's covariance between consecutive knots of `pose_knots` (indices into the internal
// knots): the information of the knots from the last solve's Jacobian, the planes
// eliminated (each plane's 3 x 3 block, its Schur complement onto the knots it touches), inverted
// with the held first knot left out. A knot's tangent (KnotManifold) is half the rotation vector
// (exp(2 d) R, on the left, in the world frame), then the world's translation. With the knots
// perturbed so (phi, dt), the motion R_a' R_b, R_a' (t_b - t_a) is perturbed by
// e_rot = R_a' (phi_b - phi_a) and e_t = R_a' (dt_b - dt_a) + R_a' [t_b - t_a]x phi_a, to first
// order. Empty when a knot has no residual or the information is singular.
std::vector<Matrix6d> step_covariances(ceres::Problem& problem, std::vector<Knot>& x,
                                       const std::vector<Eigen::Vector4d*>& planes,
                                       const std::vector<size_t>& pose_knots, double scale) {
  const size_t free_knots = x.size() - 1;  // knot 0 is held
  ceres::Problem::EvaluateOptions options;
  for (size_t k = 1; k < x.size(); ++k) {
    if (!problem.HasParameterBlock(x[k].data())) return {};
    options.parameter_blocks.push_back(x[k].data());
  }
  for (Eigen::Vector4d* p : planes) options.parameter_blocks.push_back(p->data());
  ceres::CRSMatrix J;
  if (!problem.Evaluate(options, nullptr, nullptr, nullptr, &J)) return {};
  const int knot_columns = int(6 * free_knots);
  // Per plane: its own block, and its rows' products with the knots' columns it touches.
  struct PlaneInfo {
    Eigen::Matrix3d Hpp = Eigen::Matrix3d::Zero();
    std::map<int, Eigen::Vector3d> Hpk;  // knot column -> 3 x 1
  };
  std::vector<PlaneInfo> info(planes.size());
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(knot_columns, knot_columns);
  std::vector<std::pair<int, double>> knot_part;
  for (int r = 0; r < J.num_rows; ++r) {
    knot_part.clear();
    int plane = -1;
    Eigen::Vector3d jp = Eigen::Vector3d::Zero();
    for (int i = J.rows[r]; i < J.rows[r + 1]; ++i) {
      const int c = J.cols[i];
      if (c < knot_columns) {
        knot_part.push_back({c, J.values[i]});
      } else {
        plane = (c - knot_columns) / 3;
        jp[(c - knot_columns) % 3] = J.values[i];
      }
    }
    for (const auto& [c1, v1] : knot_part)
      for (const auto& [c2, v2] : knot_part) S(c1, c2) += v1 * v2;
    if (plane < 0) continue;
    info[plane].Hpp += jp * jp.transpose();
    for (const auto& [c, v] : knot_part) {
      auto [it, inserted] = info[plane].Hpk.try_emplace(c, v * jp);
      if (!inserted) it->second += v * jp;
    }
  }
  for (const PlaneInfo& p : info) {
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(p.Hpp);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) continue;
    std::vector<int> cols;
    Eigen::Matrix<double, 3, Eigen::Dynamic> B(3, p.Hpk.size());
    for (const auto& [c, v] : p.Hpk) B.col(Eigen::Index(cols.size())) = v, cols.push_back(c);
    const Eigen::MatrixXd update = B.transpose() * ldlt.solve(B);
    for (size_t i = 0; i < cols.size(); ++i)
      for (size_t j = 0; j < cols.size(); ++j) S(cols[i], cols[j]) -= update(i, j);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return {};
  const Eigen::MatrixXd C = ldlt.solve(Eigen::MatrixXd::Identity(knot_columns, knot_columns));
  auto block = [&](size_t i, size_t j) -> Matrix6d {  // of knots i, j (0: held, zero)
    if (i == 0 || j == 0) return Matrix6d::Zero();
    return C.block<6, 6>(6 * Eigen::Index(i - 1), 6 * Eigen::Index(j - 1));
  };
  std::vector<Matrix6d> out;
  for (size_t k = 0; k + 1 < pose_knots.size(); ++k) {
    const size_t a = pose_knots[k], b = pose_knots[k + 1];
    Eigen::Matrix<double, 12, 12> joint;
    joint << block(a, a), block(a, b), block(b, a), block(b, b);
    const Eigen::Matrix3d Rt = knot_pose(x[a]).R.transpose();
    const Eigen::Vector3d ta = x[a].tail<3>(), tb = x[b].tail<3>();
    Eigen::Matrix<double, 6, 12> M = Eigen::Matrix<double, 6, 12>::Zero();
    M.block<3, 3>(0, 0) = -2.0 * Rt;
    M.block<3, 3>(0, 6) = 2.0 * Rt;
    M.block<3, 3>(3, 0) = 2.0 * Rt * skew(tb - ta);
    M.block<3, 3>(3, 3) = -Rt;
    M.block<3, 3>(3, 9) = Rt;
    out.push_back(scale * M * joint * M.transpose());
  }
  return out;
}

// 1.4826 median absolute deviations from the median: the residuals' sigma, robust to outliers.
double robust_sigma(std::vector<double> r) {
  if (r.empty()) return 0;
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + Eigen::Index(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const double m = median(r);
  for (double& e : r) e = std::abs(e - m);
  return 1.4826 * median(r);
}

// The images of the scans as the knots place them (each in its scan knot's frame), and the
// photometric residuals of each scan's points against the `reference_scans` images before it,
// added to `problem`. The images are kept in `images` and `references` (the residuals read them).
void add_photometric(ceres::Problem& problem, const std::vector<ScanPoints>& dense,
                     const std::vector<ScanPoints>& points, std::vector<Knot>& x,
                     const std::vector<SE3>& T_world_knot, const std::vector<size_t>& scan_knot,
                     const SphericalProjection& projection, const PhotometricConfig& config,
                     std::vector<SphericalImage>& images,
                     std::vector<std::unique_ptr<ReferenceImage>>& references,
                     WindowBaResult& out) {
  const auto dense_world = placed(dense, T_world_knot);
  for (size_t i = 0; i < dense.size(); ++i) {
    const SE3 T_knot_world = T_world_knot[scan_knot[i]].inverse();
    std::vector<Eigen::Vector3d> p_knot;
    std::vector<float> intensity;
    for (size_t k = 0; k < dense[i].size(); ++k) {
      p_knot.push_back(T_knot_world * dense_world[i][k]);
      intensity.push_back(dense[i][k].intensity);
    }
    images.push_back(spherical_image(p_knot, intensity, projection));
  }
  for (const SphericalImage& image : images)
    references.push_back(std::make_unique<ReferenceImage>(image));
  // The usable points of each pair, at the knots as they are, and their residuals' spread.
  struct Use {
    size_t ref = 0, knot = 0;  // the reference scan; the knot before the point's time
    PhotometricError error;
  };
  std::vector<Use> uses;
  std::vector<double> r_range, r_intensity;
  const int rows = projection.rows, cols = projection.cols;
  for (size_t j = 1; j < points.size(); ++j) {
    for (size_t i = j > size_t(config.reference_scans) ? j - size_t(config.reference_scans) : 0;
         i < j; ++i) {
      const SphericalImage& image = images[i];
      std::vector<Use> pair;
      for (const SweepPoint& p : points[j]) {
        PhotometricError e{references[i].get(), p.p_lidar, p.fraction, p.intensity, 1.0, 1.0};
        const Eigen::Vector3d p_ref =
            T_world_knot[scan_knot[i]].inverse() *
            sweep_point_in_world(x[p.knot].data(), x[p.knot].data() + 4, x[p.knot + 1].data(),
                                 x[p.knot + 1].data() + 4, p.p_lidar, p.fraction);
        double u = 0, v = 0;
        projection.project(p_ref, &u, &v);
        const int c0 = int(std::floor(u)) - 1, r0 = int(std::floor(v)) - 1;
        if (c0 < 0 || c0 + 3 >= cols || r0 < 0 || r0 + 3 >= rows) continue;
        double lo = INFINITY, hi = 0;
        for (int r = r0; r < r0 + 4; ++r)
          for (int c = c0; c < c0 + 4; ++c) {
            const double range = image.range_m[size_t(r) * size_t(cols) + size_t(c)];
            lo = std::min(lo, range), hi = std::max(hi, range);
          }
        const double range = p_ref.norm();
        if (!(lo > 0) || hi - lo > config.max_range_spread * range) continue;
        double residual[2];
        e(x[scan_knot[i]].data(), x[p.knot].data(), x[p.knot + 1].data(), residual);
        if (!(std::abs(residual[0]) < config.max_range_error_m)) continue;
        pair.push_back({i, p.knot, e});
      }
      const size_t n = std::min(pair.size(), config.max_points);
      for (size_t k = 0; k < n; ++k) uses.push_back(pair[k * pair.size() / n]);
    }
  }
  for (const Use& use : uses) {
    double residual[2];
    use.error(x[scan_knot[use.ref]].data(), x[use.knot].data(), x[use.knot + 1].data(), residual);
    r_range.push_back(residual[0]);
    r_intensity.push_back(residual[1]);
  }
  const double sigma_range = std::max(1e-3, robust_sigma(r_range));
  const double sigma_intensity = std::max(1e-3, robust_sigma(r_intensity));
  for (const Use& use : uses) {
    PhotometricError e = use.error;
    e.inv_sigma_range = config.range_weight / sigma_range;
    e.inv_sigma_intensity = config.intensity_weight / sigma_intensity;
    double* blocks[3] = {x[scan_knot[use.ref]].data(), x[use.knot].data(), x[use.knot + 1].data()};
    for (double* b : blocks) {
      if (problem.HasParameterBlock(b)) continue;
      problem.AddParameterBlock(b, 7, new KnotManifold);
      if (b == x[0].data()) problem.SetParameterBlockConstant(b);
    }
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PhotometricError, 2, 7, 7, 7>(new PhotometricError(e)),
        new ceres::HuberLoss(config.huber_sigmas), blocks[0], blocks[1], blocks[2]);
  }
  out.photometric_residuals = uses.size();
  out.photometric_sigma_range_m = sigma_range;
  out.photometric_sigma_intensity = sigma_intensity;
}

}  // namespace

WindowBaResult window_ba(const std::vector<Scan>& scans, const std::vector<Time>& stamps,
                         const std::vector<SE3>& T_world_lidar, const WindowBaConfig& config,
                         const std::vector<MotionPrior>& priors) {
  if (T_world_lidar.size() != stamps.size())
    throw Error("window bundle adjustment: one pose a stamp is needed");
  for (size_t p = 1; p < stamps.size(); ++p)
    if (!(stamps[p] > stamps[p - 1]))
      throw Error("window bundle adjustment: the poses' stamps must increase");
  // Each scan's pose (its sweep ends at the next pose); every pose a scan's stamp or the end of
  // the sweep before it.
  std::vector<size_t> scan_pose(scans.size());
  std::vector<bool> starts_scan(stamps.size(), false);
  for (size_t k = 0; k < scans.size(); ++k) {
    const auto it = std::lower_bound(stamps.begin(), stamps.end(), scans[k].stamp);
    if (it == stamps.end() || *it != scans[k].stamp || it + 1 == stamps.end() ||
        (k > 0 && size_t(it - stamps.begin()) <= scan_pose[k - 1]))
      throw Error(
          "window bundle adjustment: each scan, in time order, needs a pose at its stamp and one "
          "after it (its sweep's end)");
    scan_pose[k] = size_t(it - stamps.begin());
    starts_scan[scan_pose[k]] = true;
  }
  for (size_t p = 0; p < stamps.size(); ++p)
    if (!starts_scan[p] && (p == 0 || !starts_scan[p - 1]))
      throw Error(
          "window bundle adjustment: a pose that is neither a scan's stamp nor the end of a sweep");
  for (const MotionPrior& prior : priors)
    if (prior.pose + 1 >= stamps.size())
      throw Error("window bundle adjustment: a motion prior past the window's last pose");
  WindowBaResult out;
  out.T_world_lidar = T_world_lidar;
  if (scans.size() < 2) return out;
  // The internal knots: m a sweep, each pose's first, those within a sweep started on the
  // interpolation of its two poses; a pose that starts no sweep (an end) is one knot.
  const size_t m = config.sweep_motion ? std::max(1, config.knots_per_sweep) : 1;
  std::vector<SE3> T_world_knot;
  std::vector<size_t> pose_knot, scan_knot;
  for (size_t p = 0; p < stamps.size(); ++p) {
    pose_knot.push_back(T_world_knot.size());
    if (!starts_scan[p]) {
      T_world_knot.push_back(T_world_lidar[p]);
      continue;
    }
    const SE3 T_a_b = T_world_lidar[p].inverse() * T_world_lidar[p + 1];
    for (size_t j = 0; j < m; ++j)
      T_world_knot.push_back(T_world_lidar[p] *
                             lidar::motion_fraction(T_a_b, double(j) / double(m)));
  }
  for (size_t k = 0; k < scans.size(); ++k) scan_knot.push_back(pose_knot[scan_pose[k]]);

  // Each point with its knot and fraction: the voxel samples the adjustment uses (`points`) and,
  // for the photometric term's images, every point in range (`dense`).
  const bool photometric = config.photometric.enabled;
  std::vector<ScanPoints> points(scans.size()), dense(photometric ? scans.size() : 0);
  for (size_t k = 0; k < scans.size(); ++k) {
    const double span_ns = double((stamps[scan_pose[k] + 1] - scans[k].stamp).ns);
    const bool timed = config.sweep_motion && scans[k].point_times;
    auto sweep_point = [&](const ScanPoint& p) {
      const double f = timed ? std::clamp(double(p.t_ns) / span_ns, 0.0, 1.0) * double(m) : 0.0;
      const size_t j = std::min(size_t(f), m - 1);
      SweepPoint point;
      point.p_lidar = p.p.cast<double>();
      point.knot = uint32_t(scan_knot[k] + j);
      point.fraction = f - double(j);
      point.intensity = p.intensity;
      return point;
    };
    for (const ScanPoint& p : lidar::voxel_sample(scans[k].points, config.voxel_size_m,
                                                  config.min_range_m, config.max_range_m))
      points[k].push_back(sweep_point(p));
    if (!photometric) continue;
    for (const ScanPoint& p : scans[k].points) {
      const double range = double(p.p.norm());
      if (range >= config.min_range_m && range <= config.max_range_m)
        dense[k].push_back(sweep_point(p));
    }
  }

  const size_t knots = T_world_knot.size();
  std::vector<Knot> x(knots);
  for (size_t k = 0; k < knots; ++k) x[k] = knot_of(T_world_knot[k]);
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
    // One residual block a plane and knot: the points of one scan (or two, where a sweep's
    // knots meet) on one plane, measured from that knot on.
    std::map<std::pair<uint32_t, uint32_t>, std::vector<const SweepPoint*>> groups;
    for (const Association& r : a.points) {
      const SweepPoint& p = points[r.scan][r.index];
      groups[{r.plane, p.knot}].push_back(&p);
    }
    const double w = 1.0 / config.point_sigma_m;
    for (const auto& [key, members] : groups) {
      const auto [j, k] = key;
      const Eigen::Vector3d& c = a.planes[j].centroid;
      const bool moving = std::any_of(members.begin(), members.end(),
                                      [](const SweepPoint* p) { return p->fraction != 0; });
      if (!moving) {
        std::vector<Eigen::Vector3d> p_lidar;
        for (const SweepPoint* p : members) p_lidar.push_back(p->p_lidar);
        problem.AddResidualBlock(new PlanePointsCost(std::move(p_lidar), c, w, config.huber_sigmas),
                                 nullptr, x[k].data(), plane[j].data());
      } else {
        std::vector<SweepPlanePointsCost::Point> sweep;
        for (const SweepPoint* p : members) sweep.push_back({p->p_lidar, p->fraction});
        problem.AddResidualBlock(
            new SweepPlanePointsCost(std::move(sweep), c, w, config.huber_sigmas), nullptr,
            x[k].data(), x[k + 1].data(), plane[j].data());
      }
    }
    for (const MotionPrior& prior : priors) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<KnotMotionError, 6, 7, 7>(
              new KnotMotionError{{prior.T_pose_next.quaternion(), prior.T_pose_next.t,
                                   sqrt_information<6>(prior.covariance)}}),
          nullptr, x[pose_knot[prior.pose]].data(), x[pose_knot[prior.pose + 1]].data());
    }
    for (size_t j = 0; j < a.planes.size(); ++j) {
      problem.SetManifold(
          plane[j].data(),
          new ceres::ProductManifold<ceres::SphereManifold<3>, ceres::EuclideanManifold<1>>{});
    }
    for (size_t k = 0; k < knots; ++k) {
      if (!problem.HasParameterBlock(x[k].data())) continue;
      problem.SetManifold(x[k].data(), new KnotManifold);
    }
    if (problem.HasParameterBlock(x[0].data())) problem.SetParameterBlockConstant(x[0].data());
    solve_knots(problem, plane, x,
                out.rounds == 1 ? config.max_iterations : config.later_iterations, config, "");
    double moved = 0;
    for (size_t k = 1; k < knots; ++k) {
      if (!problem.HasParameterBlock(x[k].data())) continue;
      const SE3 T = knot_pose(x[k]);
      moved = std::max({moved, (T.t - T_world_knot[k].t).norm(),
                        10.0 * rotation_angle(T.R * T_world_knot[k].R.transpose())});
      T_world_knot[k] = T;
    }
    for (size_t p = 0; p < pose_knot.size(); ++p) out.T_world_lidar[p] = T_world_knot[pose_knot[p]];
    out.patches = a.planes.size();
    out.residuals = a.points.size();
    if (moved < config.converged_m) break;
  }
  // The photometric term, with the last round's geometric residuals.
  std::vector<SphericalImage> images;
  std::vector<std::unique_ptr<ReferenceImage>> references;
  const SphericalProjection projection =
      photometric ? spherical_projection(scans.front()) : SphericalProjection{};
  if (photometric && last && projection.rows > 0) {
    add_photometric(*last, dense, points, x, T_world_knot, scan_knot, projection,
                    config.photometric, images, references, out);
    solve_knots(*last, plane, x, config.photometric.iterations, config, "photometric ");
    for (size_t k = 1; k < knots; ++k)
      if (last->HasParameterBlock(x[k].data())) T_world_knot[k] = knot_pose(x[k]);
    for (size_t p = 0; p < pose_knot.size(); ++p) out.T_world_lidar[p] = T_world_knot[pose_knot[p]];
  }
  const auto world = placed(points, T_world_knot);
  out.rms_after_m = rms_distance(associate(world, config), world);
  if (config.step_covariances && last) {
    const double variance = std::pow(out.rms_after_m / config.point_sigma_m, 2);
    // The scale is the points' (their residuals' spread over their sigma); it scales the motion
    // priors' share of the information too, on the safe side.
    std::vector<size_t> scan_and_end_knots = scan_knot;
    scan_and_end_knots.push_back(pose_knot.back());
    std::vector<Eigen::Vector4d*> plane_blocks;
    for (Eigen::Vector4d& p : plane)
      if (last->HasParameterBlock(p.data())) plane_blocks.push_back(&p);
    out.step_covariance =
        step_covariances(*last, x, plane_blocks, scan_and_end_knots, std::max(1.0, variance));
  }
  return out;
}

WindowBaResult window_ba(const std::vector<Scan>& scans, const std::vector<SE3>& T_world_lidar,
                         Time end, const WindowBaConfig& config) {
  std::vector<Time> stamps;
  for (const Scan& scan : scans) stamps.push_back(scan.stamp);
  stamps.push_back(end);
  if (T_world_lidar.size() != stamps.size())
    throw Error("window bundle adjustment: one knot a scan and one at the end are needed");
  return window_ba(scans, stamps, T_world_lidar, config);
}

}  // namespace rigcal::gt
