#include "aprilgrid_rates.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "rigcal/camera/detect.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::camera::testing {

double DetectionCounts::rate_from(double side_px) const {
  int e = 0, f = 0;
  for (size_t b = 0; b < kSideBins.size(); ++b) {
    if (kSideBins[b] < side_px) continue;
    e += eligible[b];
    f += found[b];
  }
  return e ? static_cast<double>(f) / e : 1.0;
}

int DetectionCounts::eligible_from(double side_px) const {
  int e = 0;
  for (size_t b = 0; b < kSideBins.size(); ++b) e += kSideBins[b] >= side_px ? eligible[b] : 0;
  return e;
}

DetectionCounts& DetectionCounts::operator+=(const DetectionCounts& o) {
  for (size_t b = 0; b < kSideBins.size(); ++b) {
    eligible[b] += o.eligible[b];
    found[b] += o.found[b];
  }
  wrong += o.wrong;
  corners += o.corners;
  corners_off += o.corners_off;
  images += o.images;
  return *this;
}

std::vector<Condition> detection_conditions(int views) {
  Condition base;
  base.poses.views = views;
  // The board's larger side 8-50 % of the image width: tags of about 15 to 70 px.
  base.poses.min_fill = 0.08;
  base.poses.max_fill = 0.5;
  base.image.supersample = 3;
  std::vector<Condition> all(7, base);
  all[0].name = "default";
  all[1].name = "blur 1 px";  // Gaussian sigma; the default is 0.6
  all[1].image.blur_sigma_px = 1.0;
  all[2].name = "tilt to 60 deg";
  all[2].poses.max_tilt_deg = 60;
  all[3].name = "uneven light";
  all[3].image.vignetting = 0.7;  // the corners of the image at 30 % of its centre
  all[3].image.white_dn = 150;
  all[3].image.black_dn = 20;
  all[4].name = "noise";
  all[4].image.read_noise_dn = 5;
  all[4].image.gain_dn_per_e = 0.6;  // 11 DN at white, 5.5 at black
  all[5].name = "partial boards";
  all[5].shift_off_image = 0.4;
  all[6].name = "defocus 1.5 px";
  all[6].image.blur_sigma_px = 1.5;
  all[6].held_to_bars = false;
  return all;
}

DetectionCounts detection_counts(const Condition& condition, uint64_t seed) {
  const rig::Rig rig = rig::read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  const rig::CameraModel& cam = rig.sensors.at(0).camera;
  const Target target = io::read_target_file(RIGCAL_SOURCE_DIR "/targets/aprilgrid_6x6_88mm.yaml");
  std::mt19937_64 rng(seed);
  std::vector<SE3> poses = sim::board_poses(cam, nullptr, SE3(), target, condition.poses, rng);
  const Outline o = outline(target);
  const Pattern pattern(target);
  const sim::PixelRays rays = sim::pixel_rays(cam);
  const std::vector<Eigen::Vector3d> object = object_points(target);
  DetectionCounts counts;
  for (size_t k = 0; k < poses.size(); ++k) {
    SE3 T_cam_board = poses[k];
    // Partial boards: moved sideways (left or right in turn) so that a part leaves the image.
    const double shift = condition.shift_off_image * o.width() * (k % 2 ? 1.0 : -1.0);
    T_cam_board.t += shift * Eigen::Vector3d::UnitX();
    const cv::Mat image =
        sim::render_board(rays, target, pattern, T_cam_board, condition.image, rng);
    const std::vector<Eigen::Vector2d> truth = sim::project_points(cam, T_cam_board, object);
    const Detection d = detect(image, target);
    std::map<int, std::vector<std::pair<int, Eigen::Vector2d>>> reported;  // tag: (point, px)
    for (size_t i = 0; i < d.point_ids.size(); ++i) {
      const int m = d.point_ids[i] % (2 * target.cols), n = d.point_ids[i] / (2 * target.cols);
      reported[(n / 2) * target.cols + m / 2].emplace_back(d.point_ids[i], d.pixels[i]);
    }
    // Where each reported tag is: the mean of its reported corners against the true one.
    std::map<int, bool> in_place;
    for (const auto& [tag, points] : reported) {
      Eigen::Vector2d mean_px = Eigen::Vector2d::Zero(), mean_truth = Eigen::Vector2d::Zero();
      double side = 0;
      for (const auto& [id, px] : points) {
        mean_px += px / points.size();
        mean_truth += truth[id] / points.size();
      }
      for (size_t q = 0; q < points.size(); ++q)
        side = std::max(side, (truth[points[q].first] - mean_truth).norm());
      in_place[tag] = points.size() == 4 && (mean_px - mean_truth).norm() <= 0.35 * side;
      counts.wrong += !in_place[tag];
      if (!in_place[tag]) continue;
      for (const auto& [id, px] : points) {
        ++counts.corners;
        counts.corners_off += (px - truth[id]).norm() > 1.0;
      }
    }
    for (int tag = 0; tag < target.cols * target.rows; ++tag) {
      const int c = tag % target.cols, r = tag / target.cols, w = 2 * target.cols;
      const std::array<int, 4> ids = {2 * r * w + 2 * c, 2 * r * w + 2 * c + 1,
                                      (2 * r + 1) * w + 2 * c + 1, (2 * r + 1) * w + 2 * c};
      bool inside = true;
      double side = INFINITY;
      for (int q = 0; q < 4; ++q) {
        const Eigen::Vector2d& p = truth[ids[q]];
        inside =
            inside && p.x() >= 0 && p.y() >= 0 && p.x() <= cam.width - 1 && p.y() <= cam.height - 1;
        side = std::min(side, (truth[ids[(q + 1) % 4]] - p).norm());
      }
      if (!inside) continue;
      size_t bin = 0;
      while (bin + 1 < kSideBins.size() && side >= kSideBins[bin + 1]) ++bin;
      ++counts.eligible[bin];
      const auto it = in_place.find(tag);
      counts.found[bin] += it != in_place.end() && it->second;
    }
    ++counts.images;
  }
  return counts;
}

std::string describe(const std::string& name, const DetectionCounts& c) {
  std::string bins;
  for (size_t b = 0; b < kSideBins.size(); ++b) {
    if (!c.eligible[b]) continue;
    const std::string range = b + 1 < kSideBins.size()
                                  ? fmt::format("{:.0f}-{:.0f}", kSideBins[b], kSideBins[b + 1])
                                  : fmt::format("{:.0f}+", kSideBins[b]);
    bins += fmt::format(" {} px {}/{} ({:.1f} %);", range, c.found[b], c.eligible[b],
                        100.0 * c.found[b] / c.eligible[b]);
  }
  return fmt::format(
      "{} ({} images):{} from 30 px {:.1f} %, from 25 px {:.1f} %; wrong {}; corners over 1 px "
      "{} of {}",
      name, c.images, bins, 100 * c.rate_from(30), 100 * c.rate_from(25), c.wrong, c.corners_off,
      c.corners);
}

void expect_bars(const std::string& name, const DetectionCounts& c, bool held_to_bars,
                 int min_eligible) {
  std::printf("[ figures ] %s%s\n", describe(name, c).c_str(),
              held_to_bars ? "" : " (not held to the bars)");
  EXPECT_EQ(c.wrong, 0) << name;
  if (!held_to_bars) return;
  EXPECT_GE(c.eligible_from(25), min_eligible) << name << ": too few tags to measure";
  EXPECT_GE(c.rate_from(30), 0.98) << describe(name, c);
  EXPECT_GE(c.rate_from(25), 0.90) << describe(name, c);
}

}  // namespace rigcal::camera::testing
