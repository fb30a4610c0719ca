// The LiDAR odometry against its peers on real scans: the 16 consecutive KITTI sweeps of
// ../shared/fixtures/lidar/kitti00_pcd (a Velodyne HDL-64E at 10 Hz on a car, about 124,000
// points each, no per-point times). The peers, on the same sweeps in the same run: Open3D 0.16's
// point-to-plane ICP and PCL 1.13's GICP, each frame to frame and frame to map, each given the
// same voxel sampling, range limits and constant-velocity guess as rigcal, at three
// correspondence distances; rigcal is held to the best of the twelve.
//
// The sweeps cannot be scored against KITTI 00's ground truth, as the fixture's name suggests:
// every method here, even started from the ground truth's motion, measures a car accelerating
// from 6.6 to 8.5 m/s while turning 3 deg, where KITTI 00's first 16 poses hold 8.3 m/s straight,
// and no 16 poses of the 4541 match in both translation and rotation (doc/odometry.md). So the
// measure is one that needs no ground truth: how well each trajectory puts every sweep's
// surfaces on the other sweeps' points (map_consistency). The per-step difference to KITTI 00's
// first poses is printed for the record.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "../unit/fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/lidar/odometry.h"
#include "rigcal/lidar/preprocess.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;

// The calibration file's "Tr:" line: the row-major 3x4 transform of Velodyne points into cam0.
SE3 read_T_cam0_velo(const fs::path& calib) {
  std::ifstream in(calib);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("Tr:", 0) != 0) continue;
    std::istringstream values(line.substr(3));
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) values >> m(r, c);
    if (!values) break;
    SE3 T = SE3::from_matrix(m);
    T.R = nearest_rotation(T.R);  // printed to 10 digits
    return T;
  }
  throw Error(calib.string() + ": no Tr line");
}

struct KittiFrames {
  std::vector<Scan> scans;
  std::vector<SE3> T_prev_cur_truth;  // Velodyne frame, one fewer than scans
};

KittiFrames kitti_frames(const fs::path& pcd_folder, const fs::path& gt, const fs::path& times,
                         const fs::path& calib) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& e : fs::directory_iterator(pcd_folder))
    if (e.path().extension() == ".pcd") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  io::TrajectoryReadOptions options;
  options.format = io::TrajectoryFormat::kitti;
  options.kitti_times = times;
  const Trajectory T_world_cam0 = io::read_trajectory(gt, options).trajectory;
  const SE3 T_cam0_velo = read_T_cam0_velo(calib);
  KittiFrames f;
  for (size_t k = 0; k < files.size(); ++k) {
    Scan s = io::read_scan(files[k]);
    s.stamp = T_world_cam0.stamps[k];
    f.scans.push_back(std::move(s));
    if (k == 0) continue;
    const SE3 T_cam0prev_cam0 =
        T_world_cam0.T_world_body[k - 1].inverse() * T_world_cam0.T_world_body[k];
    f.T_prev_cur_truth.push_back(T_cam0_velo.inverse() * T_cam0prev_cam0 * T_cam0_velo);
  }
  return f;
}

struct StepErrors {
  double translation_mean_m = 0, translation_max_m = 0, rotation_mean_deg = 0, rotation_max_deg = 0;
};

StepErrors step_errors(const std::vector<SE3>& T_odom_velo, const std::vector<SE3>& truth) {
  StepErrors e;
  EXPECT_EQ(T_odom_velo.size(), truth.size() + 1);
  for (size_t k = 0; k < truth.size(); ++k) {
    const SE3 d = truth[k].inverse() * (T_odom_velo[k].inverse() * T_odom_velo[k + 1]);
    const double deg = rotation_angle(d.R) * 180.0 / M_PI;
    e.translation_mean_m += d.t.norm() / double(truth.size());
    e.rotation_mean_deg += deg / double(truth.size());
    e.translation_max_m = std::max(e.translation_max_m, d.t.norm());
    e.rotation_max_deg = std::max(e.rotation_max_deg, deg);
  }
  return e;
}

// A measure of a trajectory that needs no ground truth. The points measured are chosen once,
// whatever the trajectory: the registration points of each sweep whose 10 nearest points of
// their own sweep lie within 1 m and are planar (PCA: the smallest spread under a tenth of the
// middle one), each with that plane. With a trajectory, every such plane is put into the
// odometry frame and the nearest map point of all the other sweeps (put there by the same
// trajectory) measured from it, capped at 1 m. A wrong pose moves its sweep off the others'
// surfaces. Neighbours come from Open3D's kd-tree, planes from Eigen, not from rigcal's map.
struct Consistency {
  double median_m = 0, mean_m = 0;
  size_t planes = 0;
};

struct Plane {
  size_t sweep;
  Eigen::Vector3d point, normal;  // sensor frame
};

std::vector<Plane> sweep_planes(const std::vector<std::vector<Eigen::Vector3d>>& frames,
                                const std::vector<std::vector<Eigen::Vector3d>>& sources) {
  std::vector<Plane> planes;
  for (size_t k = 0; k < frames.size(); ++k) {
    open3d::geometry::PointCloud own(frames[k]);
    const open3d::geometry::KDTreeFlann tree(own);
    std::vector<int> index;
    std::vector<double> squared;
    for (const Eigen::Vector3d& p : sources[k]) {
      if (tree.SearchKNN(p, 10, index, squared) < 10 || squared.back() > 1.0) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int i : index) mean += own.points_[i] / 10.0;
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (int i : index) {
        const Eigen::Vector3d d = own.points_[i] - mean;
        covariance += d * d.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(covariance);
      if (pca.eigenvalues()(0) > 0.01 * pca.eigenvalues()(1)) continue;
      planes.push_back({k, mean, pca.eigenvectors().col(0)});
    }
  }
  return planes;
}

Consistency map_consistency(const std::vector<std::vector<Eigen::Vector3d>>& frames,
                            const std::vector<Plane>& planes, const std::vector<SE3>& T_odom_velo) {
  std::vector<double> distances;
  for (size_t k = 0; k < frames.size(); ++k) {
    open3d::geometry::PointCloud others;
    for (size_t j = 0; j < frames.size(); ++j)
      for (const Eigen::Vector3d& p : frames[j])
        if (j != k) others.points_.push_back(T_odom_velo[j] * p);
    const open3d::geometry::KDTreeFlann tree(others);
    std::vector<int> index;
    std::vector<double> squared;
    for (const Plane& plane : planes) {
      if (plane.sweep != k) continue;
      const Eigen::Vector3d point = T_odom_velo[k] * plane.point;
      const Eigen::Vector3d normal = T_odom_velo[k].R * plane.normal;
      double d = 1.0;
      if (tree.SearchKNN(point, 1, index, squared) == 1 && squared[0] < 1.0)
        d = std::min(1.0, std::abs(normal.dot(others.points_[index[0]] - point)));
      distances.push_back(d);
    }
  }
  Consistency c;
  c.planes = distances.size();
  if (distances.empty()) return c;
  for (double d : distances) c.mean_m += d / double(distances.size());
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  c.median_m = distances[distances.size() / 2];
  return c;
}

// What every peer is given: rigcal's sampling of each sweep (the map at half the voxel, the
// registered points at 1.5 voxels, the same range limits).
struct Sampled {
  std::vector<Eigen::Vector3d> frame, source;
};

Sampled sampled(const Scan& scan, const lidar::OdometryConfig& c) {
  const std::vector<ScanPoint> frame =
      lidar::voxel_sample(scan.points, 0.5 * c.voxel_size_m, c.min_range_m, c.max_range_m);
  const std::vector<ScanPoint> source = lidar::voxel_sample(frame, 1.5 * c.voxel_size_m, 0, 1e9);
  return {lidar::deskew(frame, SE3::identity(), 0, false),
          lidar::deskew(source, SE3::identity(), 0, false)};
}

// A registration of `source` (sensor frame) against `target` (odometry frame) from a guess.
using Register = std::function<SE3(const std::vector<Eigen::Vector3d>& source,
                                   const std::vector<Eigen::Vector3d>& target, const SE3& T_guess)>;

// A peer's odometry: constant-velocity guess, each sweep registered against the previous sweep
// (frame to frame) or against the union of all earlier sweeps within the range limit, resampled
// at the map voxel (frame to map, the map KISS-ICP keeps).
std::vector<SE3> peer_odometry(const std::vector<Sampled>& sweeps, const lidar::OdometryConfig& c,
                               bool to_map, const Register& registration) {
  std::vector<SE3> T_odom_velo{SE3::identity()};
  std::vector<Eigen::Vector3d> map;
  for (size_t k = 0; k < sweeps.size(); ++k) {
    const SE3 T_odom_prev = T_odom_velo.back();
    if (k > 0) {
      const SE3 T_prev_cur = k >= 2 ? T_odom_velo[k - 2].inverse() * T_odom_prev : SE3::identity();
      std::vector<Eigen::Vector3d> target;
      if (to_map) {
        target = map;
      } else {
        for (const Eigen::Vector3d& p : sweeps[k - 1].frame) target.push_back(T_odom_prev * p);
      }
      T_odom_velo.push_back(registration(sweeps[k].source, target, T_odom_prev * T_prev_cur));
    }
    for (const Eigen::Vector3d& p : sweeps[k].frame) map.push_back(T_odom_velo.back() * p);
    open3d::geometry::PointCloud cloud(map);
    auto kept = cloud.VoxelDownSample(0.5 * c.voxel_size_m);
    map.clear();
    for (const Eigen::Vector3d& p : kept->points_)
      if ((p - T_odom_velo.back().t).norm() <= c.max_range_m) map.push_back(p);
  }
  return T_odom_velo;
}

Register open3d_point_to_plane(double max_distance_m) {
  return [max_distance_m](const std::vector<Eigen::Vector3d>& source,
                          const std::vector<Eigen::Vector3d>& target, const SE3& T_guess) {
    namespace reg = open3d::pipelines::registration;
    open3d::geometry::PointCloud s(source), t(target);
    t.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(20));
    const reg::RegistrationResult r = reg::RegistrationICP(
        s, t, max_distance_m, T_guess.matrix(), reg::TransformationEstimationPointToPlane(),
        reg::ICPConvergenceCriteria(1e-6, 1e-6, 50));
    return SE3::from_matrix(r.transformation_);
  };
}

pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_cloud(const std::vector<Eigen::Vector3d>& points) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const Eigen::Vector3d& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

Register pcl_gicp(double max_distance_m) {
  return [max_distance_m](const std::vector<Eigen::Vector3d>& source,
                          const std::vector<Eigen::Vector3d>& target, const SE3& T_guess) {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    gicp.setInputSource(pcl_cloud(source));
    gicp.setInputTarget(pcl_cloud(target));
    gicp.setMaxCorrespondenceDistance(max_distance_m);
    gicp.setMaximumIterations(50);
    gicp.setTransformationEpsilon(1e-6);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    gicp.align(aligned, T_guess.matrix().cast<float>());
    Eigen::Matrix4d m = gicp.getFinalTransformation().cast<double>();
    SE3 T = SE3::from_matrix(m);
    T.R = nearest_rotation(T.R);  // float precision
    return T;
  };
}

TEST(OdometryPeersOnKitti, RigcalPutsTheSixteenKittiSweepsOnEachOtherAtLeastAsWellAsOpen3dAndPcl) {
  RIGCAL_REQUIRE_FIXTURE(pcd, "lidar/kitti00_pcd");
  RIGCAL_REQUIRE_FIXTURE(gt, "trajectories/evo/KITTI_00_gt.txt");
  RIGCAL_REQUIRE_FIXTURE(times, "trajectories/evo/KITTI_00_gt_times.txt");
  RIGCAL_REQUIRE_FIXTURE(calib, "lidar/kitti00_calib.txt");
  const KittiFrames f = kitti_frames(pcd, gt, times, calib);
  ASSERT_EQ(f.scans.size(), 16u);
  for (const Scan& s : f.scans) ASSERT_FALSE(s.point_times);
  const lidar::OdometryConfig config = lidar::os1_64_car();
  std::vector<std::vector<Eigen::Vector3d>> frames, sources;
  std::vector<Sampled> sweeps;
  for (const Scan& s : f.scans) {
    sweeps.push_back(sampled(s, config));
    frames.push_back(sweeps.back().frame);
    sources.push_back(sweeps.back().source);
  }
  const std::vector<Plane> planes = sweep_planes(frames, sources);
  auto evaluate = [&](const std::string& name, const std::vector<SE3>& T_odom_velo) {
    const Consistency c = map_consistency(frames, planes, T_odom_velo);
    const StepErrors e = step_errors(T_odom_velo, f.T_prev_cur_truth);
    const SE3 T_first_last = T_odom_velo.front().inverse() * T_odom_velo.back();
    std::printf(
        "[ figures ] 16 KITTI sweeps, %-34s on the other sweeps %5.1f mm median, %5.1f mm mean "
        "(%zu planes); 15 steps %.3f m, %.2f deg; against KITTI 00's first poses %5.1f mm, "
        "%.3f deg a step\n",
        name.c_str(), 1e3 * c.median_m, 1e3 * c.mean_m, c.planes, T_first_last.t.norm(),
        rotation_angle(T_first_last.R) * 180 / M_PI, 1e3 * e.translation_mean_m,
        e.rotation_mean_deg);
    return c;
  };

  lidar::Odometry odometry = lidar::start_odometry(config);
  for (const Scan& s : f.scans) lidar::register_scan(odometry, s);
  const Consistency ours = evaluate("rigcal", odometry.T_odom_lidar.T_world_body);
  // The measure's scale: every sweep left at the first pose (11.7 m of motion ignored) moves the
  // planes off each other, though the road, seen alike from every pose, keeps the median low.
  std::vector<SE3> T_identity(f.scans.size(), SE3::identity());
  const Consistency unregistered = evaluate("all sweeps at the first pose", T_identity);
  EXPECT_GT(unregistered.mean_m, 3 * ours.mean_m);

  Consistency best;
  best.median_m = 1e9;
  struct Peer {
    std::string name;
    std::function<Register(double)> make;
  };
  for (const Peer& peer :
       {Peer{"Open3D point-to-plane", open3d_point_to_plane}, Peer{"PCL GICP", pcl_gicp}}) {
    for (bool to_map : {false, true}) {
      for (double distance_m : {0.5, 1.0, 2.0}) {
        const Consistency c = evaluate(
            fmt::format("{} {}, {} m", peer.name, to_map ? "to map" : "to frame", distance_m),
            peer_odometry(sweeps, config, to_map, peer.make(distance_m)));
        if (c.median_m < best.median_m) best = c;
      }
    }
  }
  EXPECT_LE(ours.median_m, best.median_m);
  EXPECT_LE(ours.mean_m, best.mean_m);
}

}  // namespace
}  // namespace rigcal
