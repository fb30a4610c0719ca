#include "rigcal/rig/export.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <optional>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/io/mrcal_cameramodel.h"
#include "rigcal/rig/rig_yaml.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace rigcal::rig {
namespace {

std::vector<double> row_major(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return std::vector<double>(d.begin<double>(), d.end<double>());
}

const Sensor& camera(const Rig& rig, std::string_view name) {
  const Sensor& s = sensor(rig, name);
  if (s.type != SensorType::camera) {
    throw Error(fmt::format("sensor '{}' is a {}, not a camera", name, to_string(s.type)));
  }
  return s;
}

struct StereoPair {
  const Sensor* cam0;
  const Sensor* cam1;
  SE3 T_cam1_cam0;
};

std::optional<StereoPair> stereo_pair(const Rig& rig) {
  const std::vector<const Sensor*> cams = cameras(rig);
  if (cams.size() < 2) return std::nullopt;
  return StereoPair{cams[0], cams[1], T_a_b(rig, cams[1]->name, cams[0]->name)};
}

cv::Mat to_cv(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

cv::Mat distortion(const CameraModel& c) {
  return cv::Mat(c.distortion_coeffs, true).reshape(1, 1);
}

struct Rectification {
  cv::Mat R1, R2, P1, P2, Q;
};

// Stereo rectification as OpenCV computes it; none when the pair cannot be rectified together
// (different image sizes or different lens models).
std::optional<Rectification> rectification(const StereoPair& pair, double alpha = 0.0) {
  const CameraModel& c0 = pair.cam0->camera;
  const CameraModel& c1 = pair.cam1->camera;
  if (c0.width != c1.width || c0.height != c1.height ||
      c0.distortion_model != c1.distortion_model) {
    return std::nullopt;
  }
  const cv::Size size(c0.width, c0.height);
  const cv::Mat R = to_cv(pair.T_cam1_cam0.R), T = to_cv(pair.T_cam1_cam0.t);
  Rectification r;
  if (c0.distortion_model == DistortionModel::radtan) {
    cv::stereoRectify(to_cv(c0.K()), distortion(c0), to_cv(c1.K()), distortion(c1), size, R, T,
                      r.R1, r.R2, r.P1, r.P2, r.Q, cv::CALIB_ZERO_DISPARITY, alpha, size);
  } else {
    cv::fisheye::stereoRectify(to_cv(c0.K()), distortion(c0), to_cv(c1.K()), distortion(c1), size,
                               R, T, r.R1, r.R2, r.P1, r.P2, r.Q, cv::CALIB_ZERO_DISPARITY, size,
                               alpha, 1.0);
  }
  return r;
}

std::string default_kalibr_imu(const Rig& rig) {
  if (const Sensor* s = find_sensor(rig, "imu"); s && s->type == SensorType::imu) return s->name;
  for (const Sensor& s : rig.sensors) {
    if (s.type == SensorType::imu) return s.name;
  }
  return {};
}

}  // namespace

ExportFormat export_format_from_string(std::string_view name) {
  for (ExportFormat f :
       {ExportFormat::rigcal, ExportFormat::vbr, ExportFormat::kalibr, ExportFormat::opencv,
        ExportFormat::opencv_sample, ExportFormat::ros, ExportFormat::mrcal}) {
    if (name == to_string(f)) return f;
  }
  throw Error(fmt::format(
      "unknown export format '{}'; expected one of rigcal, vbr, kalibr, opencv, opencv-sample, "
      "ros, mrcal",
      name));
}

std::string_view to_string(ExportFormat format) {
  switch (format) {
    case ExportFormat::rigcal:
      return "rigcal";
    case ExportFormat::vbr:
      return "vbr";
    case ExportFormat::kalibr:
      return "kalibr";
    case ExportFormat::opencv:
      return "opencv";
    case ExportFormat::opencv_sample:
      return "opencv-sample";
    case ExportFormat::ros:
      return "ros";
    case ExportFormat::mrcal:
      return "mrcal";
  }
  return "?";
}

bool writes_folder(ExportFormat format) {
  return format == ExportFormat::ros || format == ExportFormat::mrcal ||
         format == ExportFormat::opencv_sample;
}

std::string kalibr_camchain_yaml(const Rig& rig, const ExportOptions& options) {
  validate(rig);
  const std::vector<const Sensor*> cams = cameras(rig);
  if (cams.empty()) throw Error("the rig has no camera: a Kalibr camchain needs at least one");
  const std::string imu = options.kalibr_imu.empty() ? default_kalibr_imu(rig) : options.kalibr_imu;
  if (!imu.empty() && sensor(rig, imu).type != SensorType::imu) {
    throw Error(fmt::format("sensor '{}' is not an IMU", imu));
  }
  std::string out = fmt::format(
      "# Kalibr camchain written by {}. T_cn_cnm1 maps cam(n-1) points into cam(n);\n"
      "# T_cam_imu maps {} points into the camera; t_imu = t_cam + timeshift_cam_imu.\n",
      version_string(), imu.empty() ? "IMU" : imu);
  for (size_t i = 0; i < cams.size(); ++i) {
    const Sensor& s = *cams[i];
    const CameraModel& c = s.camera;
    std::vector<double> coeffs = c.distortion_coeffs;
    if (c.distortion_model == DistortionModel::radtan && coeffs.size() == 5) {
      if (coeffs[4] != 0.0) {
        throw Error(fmt::format(
            "{}: Kalibr's radtan model has four coefficients (k1 k2 p1 p2) but k3 = {}; "
            "calibrate with four coefficients or export to opencv, ros or mrcal",
            s.name, coeffs[4]));
      }
      coeffs.resize(4);
    }
    out += fmt::format("cam{}:\n", i);
    if (i > 0) {
      out += "  T_cn_cnm1:\n" + yaml_matrix4_rows(T_a_b(rig, s.name, cams[i - 1]->name), "    ");
    }
    if (!imu.empty()) {
      out += "  T_cam_imu:\n" + yaml_matrix4_rows(T_a_b(rig, s.name, imu), "    ");
    }
    std::vector<std::string> overlaps;
    for (size_t j = 0; j < cams.size(); ++j) {
      if (j != i) overlaps.push_back(std::to_string(j));
    }
    out += fmt::format("  cam_overlaps: [{}]\n", fmt::join(overlaps, ", "));
    out += "  camera_model: pinhole\n";
    out += fmt::format("  distortion_coeffs: {}\n", yaml_list(coeffs));
    out += fmt::format("  distortion_model: {}\n", to_string(c.distortion_model));
    out += fmt::format("  intrinsics: {}\n", yaml_list({c.fx, c.fy, c.cx, c.cy}));
    out += fmt::format("  resolution: [{}, {}]\n", c.width, c.height);
    out += fmt::format("  rostopic: /{}/image_raw\n", s.name);
    if (!imu.empty()) {
      out += fmt::format("  timeshift_cam_imu: {}\n",
                         yaml_number(s.time_offset - sensor(rig, imu).time_offset));
    }
  }
  return out;
}

std::string opencv_yaml(const Rig& rig) {
  validate(rig);
  const std::vector<const Sensor*> cams = cameras(rig);
  if (cams.empty()) throw Error("the rig has no camera to export to OpenCV");
  cv::FileStorage fs(
      ".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs.writeComment(fmt::format(
      " Written by {}. Camera 1 = {}{}. R, T: p2 = R * p1 + T (metres).", version_string(),
      cams[0]->name, cams.size() > 1 ? fmt::format(", camera 2 = {}", cams[1]->name) : ""));
  for (size_t i = 0; i < std::min<size_t>(cams.size(), 2); ++i) {
    const CameraModel& c = cams[i]->camera;
    const std::string n = std::to_string(i + 1);
    fs << "camera" + n + "_name" << cams[i]->name;
    fs << "distortion_model" + n
       << (c.distortion_model == DistortionModel::radtan ? "radtan (cv::calibrateCamera)"
                                                         : "equidistant (cv::fisheye)");
    fs << "K" + n << to_cv(c.K());
    fs << "D" + n << distortion(c);
    fs << "image_size" + n << cv::Size(c.width, c.height);
  }
  if (const std::optional<StereoPair> pair = stereo_pair(rig)) {
    const Eigen::Matrix3d E = skew(pair->T_cam1_cam0.t) * pair->T_cam1_cam0.R;
    const Eigen::Matrix3d F =
        pair->cam1->camera.K().inverse().transpose() * E * pair->cam0->camera.K().inverse();
    fs << "R" << to_cv(pair->T_cam1_cam0.R) << "T" << to_cv(pair->T_cam1_cam0.t);
    fs << "E" << to_cv(E) << "F" << to_cv(F / F(2, 2));
    if (const std::optional<Rectification> r = rectification(*pair)) {
      fs << "R1" << r->R1 << "R2" << r->R2 << "P1" << r->P1 << "P2" << r->P2 << "Q" << r->Q;
    }
  }
  return fs.releaseAndGetString();
}

OpenCvSampleFiles opencv_sample_files(const Rig& rig) {
  validate(rig);
  const std::optional<StereoPair> pair = stereo_pair(rig);
  if (!pair) {
    throw Error(
        "opencv-sample is the layout of OpenCV's stereo sample: it needs two cameras (one "
        "camera: --to opencv or ros)");
  }
  const std::optional<Rectification> r = rectification(*pair, 1.0);
  if (!r) {
    throw Error(
        fmt::format("opencv-sample: {} and {} differ in image size or lens model, and the sample's "
                    "extrinsics.yml holds their common rectification",
                    pair->cam0->name, pair->cam1->name));
  }
  auto storage = [] {
    return cv::FileStorage(
        ".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  };
  cv::FileStorage in = storage(), ex = storage();
  in.writeComment(fmt::format(" Written by {}. M1 D1: {}, M2 D2: {} ({}).", version_string(),
                              pair->cam0->name, pair->cam1->name,
                              pair->cam0->camera.distortion_model == DistortionModel::radtan
                                  ? "cv::calibrateCamera's model"
                                  : "cv::fisheye's model"));
  in << "M1" << to_cv(pair->cam0->camera.K()) << "D1" << distortion(pair->cam0->camera);
  in << "M2" << to_cv(pair->cam1->camera.K()) << "D2" << distortion(pair->cam1->camera);
  ex.writeComment(fmt::format(
      " Written by {}. p2 = R * p1 + T, T in metres; rectification at alpha 1.", version_string()));
  ex << "R" << to_cv(pair->T_cam1_cam0.R) << "T" << to_cv(pair->T_cam1_cam0.t);
  ex << "R1" << r->R1 << "R2" << r->R2 << "P1" << r->P1 << "P2" << r->P2 << "Q" << r->Q;
  return {in.releaseAndGetString(), ex.releaseAndGetString()};
}

std::string ros_camera_info_yaml(const Rig& rig, std::string_view name) {
  validate(rig);
  const Sensor& s = camera(rig, name);
  const CameraModel& c = s.camera;
  cv::Mat R = cv::Mat::eye(3, 3, CV_64F);
  cv::Mat P = cv::Mat::zeros(3, 4, CV_64F);
  to_cv(c.K()).copyTo(P(cv::Rect(0, 0, 3, 3)));
  std::string how = "no stereo partner: R = I, P = [K | 0]";
  if (const std::optional<StereoPair> pair = stereo_pair(rig)) {
    if (const std::optional<Rectification> r = rectification(*pair)) {
      if (pair->cam0 == &s) R = r->R1, P = r->P1, how = "stereo rectified, left of the pair";
      if (pair->cam1 == &s) R = r->R2, P = r->P2, how = "stereo rectified, right of the pair";
    }
  }
  std::vector<double> d = c.distortion_coeffs;
  std::string model = "equidistant";
  if (c.distortion_model == DistortionModel::radtan) {
    model = "plumb_bob";
    d.resize(5, 0.0);  // plumb_bob is k1 k2 p1 p2 k3
  }
  auto block = [](std::string_view key, int rows, int cols, const std::vector<double>& data) {
    return fmt::format("{}:\n  rows: {}\n  cols: {}\n  data: {}\n", key, rows, cols,
                       yaml_list(data));
  };
  std::string out = fmt::format("# ROS camera_info written by {} ({}).\n", version_string(), how);
  out += fmt::format("image_width: {}\nimage_height: {}\ncamera_name: {}\n", c.width, c.height,
                     s.name);
  out += block("camera_matrix", 3, 3, {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1});
  out += fmt::format("distortion_model: {}\n", model);
  out += block("distortion_coefficients", 1, static_cast<int>(d.size()), d);
  out += block("rectification_matrix", 3, 3, row_major(R));
  out += block("projection_matrix", 3, 4, row_major(P));
  return out;
}

std::string mrcal_cameramodel(const Rig& rig, std::string_view name) {
  validate(rig);
  const Sensor& s = camera(rig, name);
  const CameraModel& c = s.camera;
  if (c.distortion_model != DistortionModel::radtan) {
    throw Error(fmt::format(
        "{}: mrcal 2.2 has no equidistant (Kannala-Brandt) lens model; export this camera to "
        "kalibr, opencv or ros instead",
        s.name));
  }
  const char* lensmodel =
      c.distortion_coeffs.size() == 4 ? "LENSMODEL_OPENCV4" : "LENSMODEL_OPENCV5";
  std::vector<double> intrinsics = {c.fx, c.fy, c.cx, c.cy};
  intrinsics.insert(intrinsics.end(), c.distortion_coeffs.begin(), c.distortion_coeffs.end());
  const SE3 T_cam_base = s.T_base_sensor.inverse();
  const Eigen::Vector3d r = rotation_vector(T_cam_base.R);
  const std::vector<double> rt = {r.x(),           r.y(), r.z(), T_cam_base.t.x(), T_cam_base.t.y(),
                                  T_cam_base.t.z()};
  const std::string text = fmt::format(
      "# mrcal camera model of '{}', written by {}.\n"
      "# extrinsics = rt_cam_ref, the reference frame being the rig's base frame ('{}').\n"
      "{{\n"
      "    'lensmodel':  '{}',\n"
      "    'intrinsics': {},\n"
      "    'imagersize': [{}, {}],\n"
      "    'extrinsics': {},\n"
      "}}\n",
      s.name, version_string(), rig.base_frame, lensmodel, yaml_list(intrinsics), c.width, c.height,
      yaml_list(rt));

  // Self-check with libmrcal's own reader: the file must load, with our lens model.
  io::check_with_libmrcal(text, lensmodel, s.name);
  return text;
}

std::vector<io::OutputFile> export_files(const Rig& rig, ExportFormat format,
                                         const std::filesystem::path& out,
                                         const ExportOptions& options) {
  switch (format) {
    case ExportFormat::rigcal:
      return {{out, rig_to_yaml(rig)}};
    case ExportFormat::vbr:
      return {{out, rig_to_vbr_yaml(rig)}};
    case ExportFormat::kalibr:
      return {{out, kalibr_camchain_yaml(rig, options)}};
    case ExportFormat::opencv:
      return {{out, opencv_yaml(rig)}};
    case ExportFormat::opencv_sample: {
      OpenCvSampleFiles f = opencv_sample_files(rig);
      return {{out / "intrinsics.yml", std::move(f.intrinsics)},
              {out / "extrinsics.yml", std::move(f.extrinsics)}};
    }
    case ExportFormat::ros:
    case ExportFormat::mrcal: {
      std::vector<io::OutputFile> files;
      for (const Sensor* cam : cameras(rig)) {
        if (format == ExportFormat::ros) {
          files.push_back({out / (cam->name + ".yaml"), ros_camera_info_yaml(rig, cam->name)});
        } else {
          files.push_back({out / (cam->name + ".cameramodel"), mrcal_cameramodel(rig, cam->name)});
        }
      }
      if (files.empty()) throw Error("the rig has no camera to export");
      return files;
    }
  }
  throw Error("unknown export format");
}

std::vector<std::string> vbr_drops(const Rig& rig) {
  std::vector<std::string> out;
  std::vector<std::string> offsets, drifts, attached;
  for (const Sensor& s : rig.sensors) {
    if (s.time_offset != 0.0)
      offsets.push_back(fmt::format("{} {:.3f} ms", s.name, 1e3 * s.time_offset));
    if (s.time_drift_ppm) drifts.push_back(fmt::format("{} {} ppm", s.name, *s.time_drift_ppm));
    if (!s.attached_to.empty()) attached.push_back(fmt::format("{} to {}", s.name, s.attached_to));
  }
  if (!offsets.empty()) {
    out.push_back(fmt::format(
        "clock offsets (the VBR format has none; its users take every stamp as on the base "
        "clock): {}",
        fmt::join(offsets, ", ")));
  }
  if (!drifts.empty()) out.push_back(fmt::format("clock drifts: {}", fmt::join(drifts, ", ")));
  if (!attached.empty())
    out.push_back(fmt::format("rigid attachments: {}", fmt::join(attached, ", ")));
  for (const auto& [key, text] : rig.extra_metadata) {
    if (key == "steps") out.push_back("the steps' provenance (rigcal.steps)");
  }
  return out;
}

}  // namespace rigcal::rig
