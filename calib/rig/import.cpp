// Other tools' calibration files into the rig model (import.h).
#include "rigcal/rig/import.h"

#include <fmt/format.h>
#include <mrcal/mrcal.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <regex>

#include "rigcal/core/error.h"
#include "rigcal/io/files.h"
#include "rigcal/io/yaml.h"
#include "rigcal/rig/checks.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::rig {
namespace {

[[noreturn]] void fail(std::string_view file, const YAML::Node& at, std::string_view key,
                       std::string_view what) {
  const int line = at ? io::yaml_line(at) : 0;
  throw Error(fmt::format("{}{}: {}{}", file, line > 0 ? fmt::format(":{}", line) : "",
                          key.empty() ? "" : fmt::format("key '{}': ", key), what));
}

// Lists of numbers under `key` of a map: `count` of them (0: any), flattening nested lists
// (Kalibr's 4 x 4 rows).
std::vector<double> numbers(const YAML::Node& map, std::string_view key, std::string_view file,
                            size_t count = 0) {
  const YAML::Node n = map[std::string(key)];
  if (!n) fail(file, map, key, "missing");
  std::vector<double> out;
  std::function<void(const YAML::Node&)> take = [&](const YAML::Node& x) {
    if (x.IsSequence()) {
      for (const YAML::Node& e : x) take(e);
      return;
    }
    try {
      out.push_back(x.as<double>());
    } catch (const YAML::Exception&) {
      fail(file, x, key, fmt::format("'{}' is not a number", x.Scalar()));
    }
  };
  take(n);
  if (count > 0 && out.size() != count)
    fail(file, n, key, fmt::format("{} numbers where {} are expected", out.size(), count));
  return out;
}

std::string text(const YAML::Node& map, std::string_view key, std::string_view file) {
  const YAML::Node n = map[std::string(key)];
  if (!n || !n.IsScalar()) fail(file, map, key, "missing, or not a single value");
  return n.Scalar();
}

SE3 se3_of(const std::vector<double>& rows, std::string_view file, const YAML::Node& at,
           std::string_view key) {
  SE3 T;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.R(r, c) = rows[size_t(4 * r + c)];
    T.t[r] = rows[size_t(4 * r + 3)];
  }
  if (const std::string bad = check_rotation(T.R); !bad.empty()) fail(file, at, key, bad);
  return T;
}

// Distortion coefficients of a model rigcal has: trailing coefficients of a larger OpenCV model
// (k4 k5 k6 ...) taken only when zero.
std::vector<double> radtan_coefficients(std::vector<double> d, std::string_view file,
                                        const YAML::Node& at, std::string_view key) {
  if (d.empty()) return {0, 0, 0, 0};
  if (d.size() > 5) {
    if (std::any_of(d.begin() + 5, d.end(), [](double x) { return x != 0.0; })) {
      fail(file, at, key,
           fmt::format("{} distortion coefficients with k4 and beyond not zero: OpenCV's rational "
                       "model, which rigcal does not have (radtan: k1 k2 p1 p2 [k3])",
                       d.size()));
    }
    d.resize(5);
  }
  if (d.size() != 4 && d.size() != 5)
    fail(file, at, key, fmt::format("{} distortion coefficients: radtan has 4 or 5", d.size()));
  return d;
}

std::string camera_name(size_t index, const std::string& from_file, const ImportOptions& o) {
  if (index < o.camera_names.size()) return o.camera_names[index];
  if (!from_file.empty() && std::regex_match(from_file, std::regex("[A-Za-z0-9_.-]+")))
    return from_file;
  return index == 0 ? "cam_l" : index == 1 ? "cam_r" : fmt::format("cam{}", index);
}

Sensor camera_sensor(std::string name, const SE3& T_base_cam) {
  Sensor s;
  s.name = std::move(name);
  s.type = SensorType::camera;
  s.T_base_sensor = T_base_cam;
  return s;
}

Rig finished(Rig rig, std::string_view file) {
  rig.base_frame = rig.sensors.at(0).name;
  if (const std::vector<Problem> p = find_problems(rig); !p.empty())
    throw Error(fmt::format("{}: {}: {}", file, p.front().key, p.front().what));
  return rig;
}

Rig kalibr(const YAML::Node& root, std::string_view file, const ImportOptions& o) {
  std::map<int, YAML::Node> cams;
  for (auto it = root.begin(); it != root.end(); ++it) {
    std::smatch m;
    const std::string key = it->first.Scalar();
    if (std::regex_match(key, m, std::regex("cam([0-9]+)"))) cams[std::stoi(m[1])] = it->second;
  }
  Rig rig;
  SE3 T_base_prev;
  double shift0 = 0;
  int expected = 0;
  for (const auto& [index, cam] : cams) {
    const std::string key = fmt::format("cam{}", index);
    if (index != expected) {
      fail(file, cam, key,
           fmt::format("cameras numbered from cam0 without gaps: cam{} is missing", expected));
    }
    ++expected;
    if (const std::string model = text(cam, "camera_model", file); model != "pinhole") {
      fail(file, cam, key + ".camera_model",
           fmt::format("'{}': rigcal has the pinhole model only (with radtan or equidistant "
                       "distortion)",
                       model));
    }
    SE3 T_base_cam;
    if (index > 0) {
      const SE3 T_cn_cnm1 =
          se3_of(numbers(cam, "T_cn_cnm1", file, 16), file, cam, key + ".T_cn_cnm1");
      T_base_cam = T_base_prev * T_cn_cnm1.inverse();
    }
    T_base_prev = T_base_cam;
    const std::string topic = cam["rostopic"] ? cam["rostopic"].Scalar() : "";
    Sensor s = camera_sensor(camera_name(size_t(index), "", o), T_base_cam);
    rig.notes.push_back(fmt::format("{}: Kalibr's {}{} read as {}", file, key,
                                    topic.empty() ? "" : fmt::format(" ({})", topic), s.name));
    const std::vector<double> k = numbers(cam, "intrinsics", file, 4);
    s.camera.fx = k[0], s.camera.fy = k[1], s.camera.cx = k[2], s.camera.cy = k[3];
    const std::vector<double> size = numbers(cam, "resolution", file, 2);
    s.camera.width = int(size[0]), s.camera.height = int(size[1]);
    const std::string model = text(cam, "distortion_model", file);
    std::vector<double> d =
        cam["distortion_coeffs"] ? numbers(cam, "distortion_coeffs", file) : std::vector<double>{};
    if (model == "radtan" || model == "none") {
      s.camera.distortion_model = DistortionModel::radtan;
      s.camera.distortion_coeffs = radtan_coefficients(d, file, cam, key + ".distortion_coeffs");
    } else if (model == "equidistant") {
      if (d.size() != 4)
        fail(file, cam, key + ".distortion_coeffs", "equidistant has 4 coefficients");
      s.camera.distortion_model = DistortionModel::equidistant;
      s.camera.distortion_coeffs = d;
    } else {
      fail(file, cam, key + ".distortion_model",
           fmt::format("'{}': rigcal has radtan and equidistant", model));
    }
    if (cam["T_cam_imu"]) {
      const SE3 T_cam_imu =
          se3_of(numbers(cam, "T_cam_imu", file, 16), file, cam, key + ".T_cam_imu");
      const double shift =
          cam["timeshift_cam_imu"] ? numbers(cam, "timeshift_cam_imu", file, 1)[0] : 0.0;
      if (index == 0) {
        shift0 = shift;
        Sensor imu;
        imu.name = "imu";
        imu.type = SensorType::imu;
        imu.T_base_sensor = T_base_cam * T_cam_imu;
        imu.time_offset = -shift;  // t_imu = t_cam + shift, the base clock being cam0's
        rig.notes.push_back(fmt::format(
            "{}: the IMU of T_cam_imu read as 'imu', its clock from cam0's timeshift_cam_imu",
            file));
        rig.sensors.push_back(s);
        rig.sensors.push_back(imu);
        continue;
      }
      s.time_offset = shift - shift0;
    }
    rig.sensors.push_back(s);
  }
  if (cams.empty()) fail(file, root, "", "no cam0: not a Kalibr camchain");
  // The IMU after the cameras.
  std::stable_partition(rig.sensors.begin(), rig.sensors.end(),
                        [](const Sensor& s) { return s.type == SensorType::camera; });
  return finished(std::move(rig), file);
}

// A ROS camera_info: camera_calibration_parsers' keys, or a CameraInfo message's fields.
Rig ros(const YAML::Node& root, std::string_view file, const ImportOptions& o) {
  const bool parser_form = bool(root["camera_matrix"]);
  const std::vector<double> K =
      parser_form ? numbers(root["camera_matrix"], "data", file, 9) : numbers(root, "K", file, 9);
  std::vector<double> D;
  if (parser_form && root["distortion_coefficients"])
    D = numbers(root["distortion_coefficients"], "data", file);
  if (!parser_form && root["D"]) D = numbers(root, "D", file);
  if (std::abs(K[1]) > 1e-9 * std::abs(K[0]))
    fail(file, root, parser_form ? "camera_matrix" : "K", "a skew term: rigcal's pinhole has none");
  Rig rig;
  const std::string name = root["camera_name"] ? root["camera_name"].Scalar() : "";
  Sensor s = camera_sensor(camera_name(0, name, o), SE3());
  s.camera.fx = K[0], s.camera.cx = K[2], s.camera.fy = K[4], s.camera.cy = K[5];
  s.camera.width = int(numbers(root, parser_form ? "image_width" : "width", file, 1)[0]);
  s.camera.height = int(numbers(root, parser_form ? "image_height" : "height", file, 1)[0]);
  const std::string model =
      root["distortion_model"] ? root["distortion_model"].Scalar() : "plumb_bob";
  if (model == "plumb_bob" || model == "rational_polynomial") {
    s.camera.distortion_model = DistortionModel::radtan;
    s.camera.distortion_coeffs = radtan_coefficients(D, file, root, "distortion_coefficients");
  } else if (model == "equidistant" || model == "fisheye") {
    if (D.size() != 4) fail(file, root, "D", "equidistant has 4 coefficients");
    s.camera.distortion_model = DistortionModel::equidistant;
    s.camera.distortion_coeffs = D;
  } else {
    fail(file, root, "distortion_model",
         fmt::format("'{}': rigcal reads plumb_bob, rational_polynomial (with k4-k6 zero), "
                     "equidistant and fisheye",
                     model));
  }
  rig.notes.push_back(fmt::format("{}: a ROS camera_info{}, read as {}", file,
                                  name.empty() ? "" : fmt::format(" of '{}'", name), s.name));
  rig.sensors.push_back(s);
  return finished(std::move(rig), file);
}

Rig opencv(std::string_view text_, std::string_view file, const ImportOptions& o) {
  cv::FileStorage fs;
  try {
    fs.open(std::string(text_), cv::FileStorage::READ | cv::FileStorage::MEMORY);
  } catch (const cv::Exception& e) {
    throw Error(fmt::format("{}: OpenCV could not read it: {}", file, e.msg));
  }
  auto matrix = [&](const std::string& key) -> cv::Mat {
    cv::Mat m;
    if (!fs[key].empty()) fs[key] >> m;
    if (!m.empty()) m.convertTo(m, CV_64F);
    return m;
  };
  auto need = [&](const cv::Mat& m, const std::string& key, int rows, int cols) {
    if (m.empty()) throw Error(fmt::format("{}: key '{}': missing", file, key));
    if ((rows > 0 && m.rows != rows) || (cols > 0 && m.cols != cols))
      throw Error(fmt::format("{}: key '{}': {} x {} where {} x {} is expected", file, key, m.rows,
                              m.cols, rows, cols));
  };
  Rig rig;
  const bool mono = !fs["camera_matrix"].empty();
  const int cameras = mono ? 1 : !fs["K2"].empty() || !fs["M2"].empty() ? 2 : 1;
  for (int i = 0; i < cameras; ++i) {
    const std::string n = std::to_string(i + 1);
    const std::string k_key = mono ? "camera_matrix" : !fs["K" + n].empty() ? "K" + n : "M" + n;
    const std::string d_key = mono ? "distortion_coefficients" : "D" + n;
    const cv::Mat K = matrix(k_key), D = matrix(d_key);
    need(K, k_key, 3, 3);
    if (std::abs(K.at<double>(0, 1)) > 1e-9 * std::abs(K.at<double>(0, 0)))
      throw Error(fmt::format("{}: key '{}': a skew term: rigcal's pinhole has none", file, k_key));
    std::string file_name;
    if (!fs["camera" + n + "_name"].empty()) fs["camera" + n + "_name"] >> file_name;
    Sensor s = camera_sensor(camera_name(size_t(i), file_name, o), SE3());
    s.camera.fx = K.at<double>(0, 0), s.camera.fy = K.at<double>(1, 1);
    s.camera.cx = K.at<double>(0, 2), s.camera.cy = K.at<double>(1, 2);
    int width = 0, height = 0;
    if (!fs["image_size" + n].empty()) {
      cv::Size size;
      fs["image_size" + n] >> size;
      width = size.width, height = size.height;
    } else if (!fs["image_width"].empty()) {
      fs["image_width"] >> width;
      fs["image_height"] >> height;
    }
    if (width <= 0 || height <= 0) {
      throw Error(
          fmt::format("{}: no image size (image_size{} or image_width and image_height): "
                      "rigcal needs it",
                      file, n));
    }
    s.camera.width = width, s.camera.height = height;
    std::vector<double> d;
    if (!D.empty()) d.assign(D.begin<double>(), D.end<double>());
    std::string model;
    if (!fs["distortion_model" + n].empty()) fs["distortion_model" + n] >> model;
    if (model.rfind("equidistant", 0) == 0 || model.rfind("fisheye", 0) == 0) {
      if (d.size() != 4)
        throw Error(fmt::format("{}: key '{}': equidistant has 4 coefficients", file, d_key));
      s.camera.distortion_model = DistortionModel::equidistant;
      s.camera.distortion_coeffs = d;
    } else {
      s.camera.distortion_model = DistortionModel::radtan;
      s.camera.distortion_coeffs = radtan_coefficients(d, file, YAML::Node(), d_key);
    }
    rig.sensors.push_back(s);
  }
  if (cameras == 2) {
    // p2 = R p1 + T: T_cam2_cam1.
    const cv::Mat R = matrix("R"), T = matrix("T");
    if (!R.empty() || !T.empty()) {
      need(R, "R", 3, 3);
      need(T, "T", 0, 0);
      if (T.total() != 3) throw Error(fmt::format("{}: key 'T': 3 numbers expected", file));
      SE3 T_2_1;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) T_2_1.R(r, c) = R.at<double>(r, c);
        T_2_1.t[r] = T.at<double>(r);
      }
      if (const std::string bad = check_rotation(T_2_1.R); !bad.empty())
        throw Error(fmt::format("{}: key 'R': {}", file, bad));
      rig.sensors[1].T_base_sensor = T_2_1.inverse();
    } else {
      rig.notes.push_back(
          fmt::format("{}: no R and T: the second camera's pose is not known "
                      "(identity)",
                      file));
    }
  }
  rig.notes.push_back(fmt::format("{}: an OpenCV FileStorage file, its cameras read as {}", file,
                                  rig.sensors.size() == 2
                                      ? rig.sensors[0].name + " and " + rig.sensors[1].name
                                      : rig.sensors[0].name));
  return finished(std::move(rig), file);
}

Rig mrcal(std::string_view text_, std::string_view file, const ImportOptions& o) {
  mrcal_cameramodel_t* model =
      mrcal_read_cameramodel_string(text_.data(), static_cast<int>(text_.size()));
  if (!model) throw Error(fmt::format("{}: libmrcal could not read this .cameramodel", file));
  const mrcal_lensmodel_type_t type = model->lensmodel.type;
  const std::string lens = mrcal_lensmodel_name_unconfigured(&model->lensmodel);
  const int n = mrcal_lensmodel_num_params(&model->lensmodel);
  std::vector<double> k(model->intrinsics, model->intrinsics + std::max(0, n));
  const unsigned w = model->imagersize[0], h = model->imagersize[1];
  mrcal_free_cameramodel(&model);
  Sensor s = camera_sensor(camera_name(0, "", o), SE3());
  if (type != MRCAL_LENSMODEL_PINHOLE && type != MRCAL_LENSMODEL_OPENCV4 &&
      type != MRCAL_LENSMODEL_OPENCV5 && type != MRCAL_LENSMODEL_OPENCV8) {
    throw Error(
        fmt::format("{}: lens model {}: rigcal reads LENSMODEL_PINHOLE and "
                    "LENSMODEL_OPENCV4/5/8 (8 with k4-k6 zero)",
                    file, lens));
  }
  s.camera.fx = k[0], s.camera.fy = k[1], s.camera.cx = k[2], s.camera.cy = k[3];
  s.camera.width = int(w), s.camera.height = int(h);
  s.camera.distortion_model = DistortionModel::radtan;
  s.camera.distortion_coeffs = radtan_coefficients(std::vector<double>(k.begin() + 4, k.end()),
                                                   file, YAML::Node(), "intrinsics");
  Rig rig;
  rig.notes.push_back(
      fmt::format("{}: an mrcal {} model read as {}; its extrinsics (relative to "
                  "mrcal's reference frame) not used: the camera is the base frame",
                  file, lens, s.name));
  rig.sensors.push_back(s);
  return finished(std::move(rig), file);
}

}  // namespace

std::string_view to_string(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::rigcal:
      return "rigcal";
    case CalibrationFormat::kalibr:
      return "kalibr";
    case CalibrationFormat::ros:
      return "ros";
    case CalibrationFormat::opencv:
      return "opencv";
    case CalibrationFormat::mrcal:
      return "mrcal";
  }
  return "?";
}

CalibrationFormat detect_calibration_format(std::string_view text) {
  // The first line that is not a comment or blank.
  size_t at = 0;
  std::string_view first;
  while (at < text.size()) {
    const size_t end = std::min(text.find('\n', at), text.size());
    std::string_view line = text.substr(at, end - at);
    at = end + 1;
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string_view::npos || line[start] == '#') continue;
    first = line.substr(start);
    break;
  }
  if (first.rfind("%YAML:1.0", 0) == 0 || first.rfind("<?xml", 0) == 0 ||
      first.rfind("<opencv_storage>", 0) == 0)
    return CalibrationFormat::opencv;
  if (first.rfind("{", 0) == 0 && text.find("lensmodel") != std::string_view::npos)
    return CalibrationFormat::mrcal;
  try {
    const YAML::Node root = io::load_yaml(text, "");
    if (root.IsMap()) {
      if (root["cam0"] && root["cam0"].IsMap() && root["cam0"]["intrinsics"])
        return CalibrationFormat::kalibr;
      if ((root["camera_matrix"] && root["image_width"]) ||
          (root["K"] && root["D"] && root["width"]))
        return CalibrationFormat::ros;
    }
  } catch (const std::exception&) {
    // Not YAML, or over the limits: rigcal's reader says what is wrong with the text.
  }
  return CalibrationFormat::rigcal;
}

Rig parse_calibration(std::string_view text, std::string_view file_name,
                      const ImportOptions& options) {
  const CalibrationFormat format = detect_calibration_format(text);
  switch (format) {
    case CalibrationFormat::rigcal:
      return parse_rig_yaml(text, file_name);
    case CalibrationFormat::opencv:
      return opencv(text, file_name, options);
    case CalibrationFormat::mrcal:
      return mrcal(text, file_name, options);
    case CalibrationFormat::kalibr:
    case CalibrationFormat::ros: {
      const YAML::Node root = io::load_yaml(text, file_name);
      io::refuse_duplicate_keys(root, file_name);
      return format == CalibrationFormat::kalibr ? kalibr(root, file_name, options)
                                                 : ros(root, file_name, options);
    }
  }
  throw Error("unknown calibration format");
}

Rig read_calibration_file(const std::filesystem::path& path, const ImportOptions& options) {
  return parse_calibration(io::read_text_file(path, io::kMaxYamlBytes), path.string(), options);
}

}  // namespace rigcal::rig
