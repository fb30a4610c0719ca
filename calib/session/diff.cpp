// Two calibrations side by side (diff.h).
#include "rigcal/session/diff.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <regex>

#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/report/svg_plot.h"
#include "rigcal/session/provenance.h"
#include "rigcal/session/report_html.h"

namespace rigcal::session {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The significance of `difference` against the sigmas stored under `keys` (each scaled by
// `to_si` to the difference's units) in A and in B, with the correlations they stored among
// them: the chi-square d' (C_A + C_B)^-1 d over the components either gives a sigma of; none
// when neither stores any of them.
std::optional<Significance> significance(const std::vector<double>& difference,
                                         const std::vector<std::string>& keys,
                                         const std::vector<double>& to_si,
                                         const StoredUncertainty& a, const StoredUncertainty& b) {
  Significance s;
  s.sigma.assign(difference.size(), NAN);
  s.conditional_sigma.assign(difference.size(), NAN);
  // The covariance of components i and j stored by one calibration (0 where it has no sigma).
  const auto covariance = [&](const StoredUncertainty& u, size_t i, size_t j) {
    const auto si = u.sigma.find(keys[i]), sj = u.sigma.find(keys[j]);
    if (si == u.sigma.end() || sj == u.sigma.end()) return 0.0;
    return u.correlation(keys[i], keys[j]) * si->second * to_si[i] * sj->second * to_si[j];
  };
  // The components with a variance (a sigma of 0 stored, or none, says nothing).
  for (size_t i = 0; i < difference.size(); ++i) {
    const double v = covariance(a, i, i) + covariance(b, i, i);
    if (v > 0 && std::isfinite(v)) s.components.push_back(i);
  }
  if (s.components.empty()) return std::nullopt;
  const Eigen::Index m = static_cast<Eigen::Index>(s.components.size());
  Eigen::MatrixXd Ck(m, m);
  Eigen::VectorXd dk(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const size_t ci = s.components[size_t(i)];
    dk[i] = difference[ci];
    for (Eigen::Index j = 0; j < m; ++j) {
      const size_t cj = s.components[size_t(j)];
      Ck(i, j) = covariance(a, ci, cj) + covariance(b, ci, cj);
      if (i != j && Ck(i, j) != 0) s.correlated = true;
    }
  }
  // The whitening W (W' W = C^-1) from C's eigen-decomposition; directions with no variance to
  // speak of (stored correlations of +-1 within rounding) are given a floor of 1e-12 of the
  // largest.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ck);
  const double floor = 1e-12 * eig.eigenvalues().maxCoeff();
  const Eigen::VectorXd inv_sqrt = eig.eigenvalues().cwiseMax(floor).cwiseSqrt().cwiseInverse();
  s.whiten = inv_sqrt.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::MatrixXd information = s.whiten.transpose() * s.whiten;
  for (Eigen::Index i = 0; i < m; ++i) {
    s.sigma[s.components[size_t(i)]] = std::sqrt(Ck(i, i));
    s.conditional_sigma[s.components[size_t(i)]] = 1.0 / std::sqrt(information(i, i));
  }
  s.chi2 = (s.whiten * dk).squaredNorm();
  s.dof = static_cast<int>(m);
  s.p_value = chi2_upper_tail(s.chi2, s.dof);
  return s;
}

PoseDifference pose_difference(const SE3& T_a_b_in_a, const SE3& T_a_b_in_b, std::string a,
                               std::string b, const StoredUncertainty& sigmas_a,
                               const StoredUncertainty& sigmas_b) {
  PoseDifference d;
  d.a = std::move(a);
  d.b = std::move(b);
  d.rotation_rad = rotation_vector(T_a_b_in_b.R * T_a_b_in_a.R.transpose());
  d.translation_m = T_a_b_in_b.t - T_a_b_in_a.t;
  const std::string name = fmt::format("T_{}_{}", d.a, d.b);
  std::vector<std::string> keys;
  std::vector<double> values, to_si;
  for (int i = 0; i < 3; ++i) {
    keys.push_back(fmt::format("{}.rotation.{}_deg", name, "xyz"[i]));
    values.push_back(d.rotation_rad[i]);
    to_si.push_back(kDeg);
  }
  for (int i = 0; i < 3; ++i) {
    keys.push_back(fmt::format("{}.t.{}_m", name, "xyz"[i]));
    values.push_back(d.translation_m[i]);
    to_si.push_back(1.0);
  }
  d.significance = significance(values, keys, to_si, sigmas_a, sigmas_b);
  return d;
}

// The relations T_a_b whose sigmas a step stored, as (a, b) sensors of both rigs.
std::vector<std::pair<std::string, std::string>> stored_relations(
    const std::map<std::string, double>& sigmas, const rig::Rig& a, const rig::Rig& b) {
  static const std::regex key(R"(T_(.+)\.(t|rotation)\.[xyz]_(m|deg))");
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, value] : sigmas) {
    std::smatch m;
    if (!std::regex_match(name, m, key)) continue;
    const std::optional<std::pair<std::string, std::string>> ab = relation_sensors(m[1].str(), a);
    if (!ab || !rig::find_sensor(b, ab->first) || !rig::find_sensor(b, ab->second)) continue;
    if (std::find(out.begin(), out.end(), *ab) == out.end()) out.push_back(*ab);
  }
  return out;
}

}  // namespace

std::optional<std::pair<std::string, std::string>> relation_sensors(std::string_view frames,
                                                                    const rig::Rig& rig) {
  for (size_t cut = frames.find('_'); cut != std::string_view::npos;
       cut = frames.find('_', cut + 1)) {
    const std::string a(frames.substr(0, cut)), b(frames.substr(cut + 1));
    if (rig::find_sensor(rig, a) && rig::find_sensor(rig, b)) return std::pair{a, b};
  }
  return std::nullopt;
}

namespace {

Eigen::Vector3d ray(const Eigen::Vector2d& xn) { return Eigen::Vector3d(xn.x(), xn.y(), 1.0); }

// The normalized ray of a pixel by a lens, when the lens maps it back onto the pixel (inside the
// field where the model is one-to-one).
std::optional<Eigen::Vector3d> ray_of(const rig::CameraModel& lens, const Eigen::Vector2d& q) {
  const Eigen::Vector3d r = ray(camera::unproject(lens, q));
  const std::optional<Eigen::Vector2d> back = camera::project(lens, r);
  if (!back || !back->allFinite() || (*back - q).norm() > 1e-3) return std::nullopt;
  return r.normalized();
}

ProjectionDifference projection_difference(const rig::CameraModel& A, const rig::CameraModel& B,
                                           double step_px) {
  ProjectionDifference d;
  d.step_px = step_px;
  d.columns = int(std::floor((A.width - 1) / step_px)) + 1;
  d.rows = int(std::floor((A.height - 1) / step_px)) + 1;
  std::vector<std::optional<Eigen::Vector3d>> ray_a, ray_b;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int r = 0; r < d.rows; ++r) {
    for (int c = 0; c < d.columns; ++c) {
      const Eigen::Vector2d q(c * step_px, r * step_px);
      d.u.push_back(q.x());
      d.v.push_back(q.y());
      ray_a.push_back(ray_of(A, q));
      ray_b.push_back(ray_of(B, q));
      if (ray_a.back() && ray_b.back()) H += *ray_b.back() * ray_a.back()->transpose();
    }
  }
  // The rotation taking A's rays onto B's (Kabsch).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R_b_a = svd.matrixU() * S * svd.matrixV().transpose();
  d.fitted_rotation_deg = rotation_angle(R_b_a) / kDeg;
  std::vector<double> raw, fitted;
  for (size_t i = 0; i < ray_a.size(); ++i) {
    const Eigen::Vector2d q(d.u[i], d.v[i]);
    double e_raw = NAN, e_fit = NAN;
    if (ray_a[i]) {
      if (const auto p = camera::project(B, *ray_a[i])) e_raw = (*p - q).norm();
      if (const auto p = camera::project(B, R_b_a * *ray_a[i]); p && ray_b[i])
        e_fit = (*p - q).norm();
    }
    d.raw_px.push_back(e_raw);
    d.fitted_px.push_back(e_fit);
    if (std::isfinite(e_raw)) raw.push_back(e_raw);
    if (std::isfinite(e_fit)) fitted.push_back(e_fit);
  }
  d.raw_rms_px = rms(raw);
  d.fitted_rms_px = rms(fitted);
  d.raw_max_px = raw.empty() ? 0 : *std::max_element(raw.begin(), raw.end());
  d.fitted_max_px = fitted.empty() ? 0 : *std::max_element(fitted.begin(), fitted.end());
  return d;
}

CameraDifference camera_difference(const rig::Sensor& a, const rig::Sensor& b,
                                   const DiffConfig& config, const StoredUncertainty& sigmas_a,
                                   const StoredUncertainty& sigmas_b) {
  const rig::CameraModel &A = a.camera, &B = b.camera;
  CameraDifference d;
  d.camera = a.name;
  d.names = {"fx", "fy", "cx", "cy"};
  d.values = {B.fx - A.fx, B.fy - A.fy, B.cx - A.cx, B.cy - A.cy};
  std::vector<std::string> keys;
  for (const std::string& n : d.names) keys.push_back(fmt::format("{}.{}_px", a.name, n));
  d.significance = significance(d.values, keys, {1, 1, 1, 1}, sigmas_a, sigmas_b);
  if (A.distortion_model == B.distortion_model) {
    const size_t n = std::max(A.distortion_coeffs.size(), B.distortion_coeffs.size());
    for (size_t i = 0; i < n; ++i) {
      const double ka = i < A.distortion_coeffs.size() ? A.distortion_coeffs[i] : 0.0;
      const double kb = i < B.distortion_coeffs.size() ? B.distortion_coeffs[i] : 0.0;
      d.names.push_back(A.distortion_model == rig::DistortionModel::radtan
                            ? std::vector<std::string>{"k1", "k2", "p1", "p2", "k3"}.at(i)
                            : fmt::format("k{}", i + 1));
      d.values.push_back(kb - ka);
    }
  }
  if (A.width != B.width || A.height != B.height) {
    d.note = fmt::format("resolutions differ ({}x{} against {}x{}): no projection difference",
                         A.width, A.height, B.width, B.height);
  } else {
    d.projection = projection_difference(A, B, config.grid_step_px);
  }
  return d;
}

}  // namespace

RigDifference diff_rigs(const rig::Rig& a, const rig::Rig& b, const DiffConfig& config) {
  if (!(config.grid_step_px >= 1)) throw Error("diff: the projection grid's step must be >= 1 px");
  RigDifference out;
  // The frame the poses are compared in: A's base, else the first sensor of A that B has (an
  // import of cameras only has no LiDAR).
  out.base_frame = a.base_frame;
  if (!rig::find_sensor(b, a.base_frame)) {
    const auto common = std::find_if(a.sensors.begin(), a.sensors.end(), [&](const rig::Sensor& s) {
      return rig::find_sensor(b, s.name) != nullptr;
    });
    if (common == a.sensors.end()) {
      throw Error(
          "diff: the two calibrations have no sensor in common (by name): nothing to "
          "compare");
    }
    out.base_frame = common->name;
    out.notes.push_back(fmt::format(
        "the second calibration has no '{}' (the first's base frame): poses compared in '{}'",
        a.base_frame, out.base_frame));
  } else if (a.base_frame != b.base_frame) {
    out.notes.push_back(fmt::format(
        "the base frames differ ('{}' against '{}'): every pose compared in '{}', the first's",
        a.base_frame, b.base_frame, a.base_frame));
  }
  const StoredUncertainty sigmas_a = stored_uncertainty(a), sigmas_b = stored_uncertainty(b);
  for (const rig::Sensor& s : a.sensors)
    if (!rig::find_sensor(b, s.name)) out.only_in_a.push_back(s.name);
  for (const rig::Sensor& s : b.sensors)
    if (!rig::find_sensor(a, s.name)) out.only_in_b.push_back(s.name);
  for (const rig::Sensor& sa : a.sensors) {
    const rig::Sensor* sb = rig::find_sensor(b, sa.name);
    if (!sb) continue;
    if (sa.name != out.base_frame) {
      out.poses.push_back(pose_difference(rig::T_a_b(a, out.base_frame, sa.name),
                                          rig::T_a_b(b, out.base_frame, sa.name), out.base_frame,
                                          sa.name, sigmas_a, sigmas_b));
    }
    // Each clock against the reference sensor's (the base clocks of the two may differ).
    const rig::Sensor &ra = rig::sensor(a, out.base_frame), &rb = rig::sensor(b, out.base_frame);
    if (sa.name != out.base_frame) {
      ClockDifference c;
      c.sensor = sa.name;
      // A drifting clock's offset holds at its epoch: both compared at one instant (B's epoch
      // where B has a drift, else A's).
      const Time at = sb->time_drift_ppm ? sb->time_drift_epoch : sa.time_drift_epoch;
      const auto offset = [&](const rig::Sensor& s) {
        return s.time_offset + (s.time_drift_ppm
                                    ? *s.time_drift_ppm * 1e-6 * (at - s.time_drift_epoch).seconds()
                                    : 0.0);
      };
      c.offset_s = (offset(*sb) - offset(rb)) - (offset(sa) - offset(ra));
      auto drift = [](const rig::Sensor& s) { return s.time_drift_ppm.value_or(0.0); };
      if (sa.time_drift_ppm || sb->time_drift_ppm || ra.time_drift_ppm || rb.time_drift_ppm)
        c.drift_ppm = (drift(*sb) - drift(rb)) - (drift(sa) - drift(ra));
      // The offset (s) and, where either has one, the drift (ppm).
      std::vector<double> values{c.offset_s}, to_si{1.0};
      std::vector<std::string> keys{sa.name + ".time_offset_s"};
      if (c.drift_ppm) {
        values.push_back(*c.drift_ppm);
        keys.push_back(sa.name + ".time_drift_ppm");
        to_si.push_back(1.0);
      }
      c.significance = significance(values, keys, to_si, sigmas_a, sigmas_b);
      out.clocks.push_back(c);
    }
    if (sa.type == rig::SensorType::camera && sb->type == rig::SensorType::camera)
      out.cameras.push_back(camera_difference(sa, *sb, config, sigmas_a, sigmas_b));
  }
  // The relations the steps estimated (and stored sigmas of) between two sensors.
  std::map<std::string, double> all = sigmas_a.sigma;
  all.insert(sigmas_b.sigma.begin(), sigmas_b.sigma.end());
  for (const auto& [first, second] : stored_relations(all, a, b)) {
    if (first == out.base_frame) continue;  // compared above with its sigmas
    out.poses.push_back(pose_difference(rig::T_a_b(a, first, second), rig::T_a_b(b, first, second),
                                        first, second, sigmas_a, sigmas_b));
  }
  return out;
}

namespace {

nlohmann::json significance_json(const std::optional<Significance>& s, double scale) {
  if (!s) return nullptr;
  nlohmann::json sigma = nlohmann::json::array();
  for (double x : s->sigma) sigma.push_back(std::isfinite(x) ? nlohmann::json(x * scale) : nullptr);
  return {{"sigma", sigma},
          {"chi2", s->chi2},
          {"dof", s->dof},
          {"p_value", s->p_value},
          {"correlated", s->correlated}};
}

std::string significance_text(const std::optional<Significance>& s) {
  if (!s) return "no sigmas stored";
  return fmt::format("chi-square {:.2f} over {} components, p {:.3g}{}", s->chi2, s->dof,
                     s->p_value, s->p_value < 0.001 ? ": changed" : "");
}

}  // namespace

nlohmann::json diff_json(const RigDifference& d) {
  nlohmann::json poses = nlohmann::json::array(), clocks = nlohmann::json::array(),
                 cameras = nlohmann::json::array();
  for (const PoseDifference& p : d.poses) {
    // The sigmas in the units of the figures: rotation deg, translation mm.
    nlohmann::json sig = significance_json(p.significance, 1.0);
    if (!sig.is_null()) {
      for (size_t i = 0; i < 6; ++i)
        if (!sig["sigma"][i].is_null())
          sig["sigma"][i] = sig["sigma"][i].get<double>() * (i < 3 ? 1 / kDeg : 1e3);
    }
    poses.push_back(
        {{"relation", fmt::format("T_{}_{}", p.a, p.b)},
         {"rotation_deg",
          {p.rotation_rad.x() / kDeg, p.rotation_rad.y() / kDeg, p.rotation_rad.z() / kDeg}},
         {"rotation_angle_deg", p.rotation_rad.norm() / kDeg},
         {"translation_mm",
          {1e3 * p.translation_m.x(), 1e3 * p.translation_m.y(), 1e3 * p.translation_m.z()}},
         {"translation_norm_mm", 1e3 * p.translation_m.norm()},
         {"significance", sig}});
  }
  for (const ClockDifference& c : d.clocks) {
    clocks.push_back({{"sensor", c.sensor},
                      {"offset_ms", 1e3 * c.offset_s},
                      {"drift_ppm", c.drift_ppm ? nlohmann::json(*c.drift_ppm) : nullptr},
                      {"significance", [&] {
                         // The offset's sigma in ms, the drift's in ppm.
                         nlohmann::json j = significance_json(c.significance, 1.0);
                         if (!j.is_null() && !j["sigma"][0].is_null())
                           j["sigma"][0] = 1e3 * j["sigma"][0].get<double>();
                         return j;
                       }()}});
  }
  for (const CameraDifference& c : d.cameras) {
    nlohmann::json values;
    for (size_t i = 0; i < c.names.size(); ++i) values[c.names[i]] = c.values[i];
    nlohmann::json projection = nullptr;
    if (c.projection) {
      const ProjectionDifference& p = *c.projection;
      projection = {{"grid_step_px", p.step_px},
                    {"columns", p.columns},
                    {"rows", p.rows},
                    {"raw_rms_px", p.raw_rms_px},
                    {"raw_max_px", p.raw_max_px},
                    {"fitted_rms_px", p.fitted_rms_px},
                    {"fitted_max_px", p.fitted_max_px},
                    {"fitted_rotation_deg", p.fitted_rotation_deg}};
    }
    cameras.push_back({{"camera", c.camera},
                       {"intrinsics_b_minus_a", values},
                       {"significance", significance_json(c.significance, 1.0)},
                       {"projection", projection},
                       {"note", c.note}});
  }
  return {{"base_frame", d.base_frame},
          {"poses", poses},
          {"clocks", clocks},
          {"cameras", cameras},
          {"only_in_a", d.only_in_a},
          {"only_in_b", d.only_in_b},
          {"notes", d.notes},
          {"significance_note",
           "the difference against C_A + C_B, each calibration's covariance from the sigmas and "
           "the correlations its steps stored in rigcal.steps (sigma: each component's "
           "sqrt(sigma_A^2 + sigma_B^2); correlated: whether stored correlations entered; "
           "without them the diagonal alone; two calibrations from the same data are not "
           "independent, and p is then too large)"}};
}

std::vector<std::string> diff_lines(const RigDifference& d) {
  std::vector<std::string> out;
  out.push_back(fmt::format(
      "Poses, B against A (T_a_b: rotation Log(R_B R_A') about a's axes in deg, translation t_B - "
      "t_A in a, mm):"));
  // Figures that print as zero print without a sign.
  const auto clean = [](Eigen::Vector3d v, double resolution) {
    for (double& x : v) x = std::abs(x) < resolution / 2 ? 0.0 : x;
    return v;
  };
  for (const PoseDifference& p : d.poses) {
    const Eigen::Vector3d r = clean(p.rotation_rad / kDeg, 1e-4),
                          t = clean(1e3 * p.translation_m, 1e-2);
    out.push_back(fmt::format(
        "  {:<20} rotation {:8.4f} {:8.4f} {:8.4f} (angle {:.4f}); translation {:7.2f} {:7.2f} "
        "{:7.2f} (norm {:.2f}); {}",
        fmt::format("T_{}_{}", p.a, p.b), r.x(), r.y(), r.z(), r.norm(), t.x(), t.y(), t.z(),
        t.norm(), significance_text(p.significance)));
  }
  out.push_back("Clocks, B - A (ms; drift ppm):");
  for (const ClockDifference& c : d.clocks) {
    out.push_back(fmt::format("  {:<20} offset {:+.4f} ms{}; {}", c.sensor, 1e3 * c.offset_s,
                              c.drift_ppm ? fmt::format(", drift {:+.3f} ppm", *c.drift_ppm) : "",
                              significance_text(c.significance)));
  }
  for (const CameraDifference& c : d.cameras) {
    std::string values;
    for (size_t i = 0; i < c.names.size(); ++i)
      values += fmt::format("{}{} {:+.4g}", i ? ", " : "", c.names[i], c.values[i]);
    out.push_back(fmt::format("Camera {}, B - A (px; distortion unitless): {}; {}", c.camera,
                              values, significance_text(c.significance)));
    if (c.projection) {
      const ProjectionDifference& p = *c.projection;
      out.push_back(fmt::format(
          "  the same rays through both lenses, over the image (every {:g} px): {:.3f} px rms, "
          "max {:.3f}; with the best rotation of the camera taken out ({:.4f} deg): {:.3f} px rms, "
          "max {:.3f}",
          p.step_px, p.raw_rms_px, p.raw_max_px, p.fitted_rotation_deg, p.fitted_rms_px,
          p.fitted_max_px));
    } else {
      out.push_back("  " + c.note);
    }
  }
  if (!d.only_in_a.empty())
    out.push_back(fmt::format("Only in A: {}", fmt::join(d.only_in_a, ", ")));
  if (!d.only_in_b.empty())
    out.push_back(fmt::format("Only in B: {}", fmt::join(d.only_in_b, ", ")));
  for (const std::string& n : d.notes) out.push_back("Note: " + n);
  return out;
}

std::vector<std::pair<std::string, std::string>> projection_maps(const RigDifference& d) {
  std::vector<std::pair<std::string, std::string>> maps;
  for (const CameraDifference& c : d.cameras) {
    if (!c.projection) continue;
    const ProjectionDifference& p = *c.projection;
    report::Plot plot;
    plot.title = fmt::format(
        "{}: projection difference B - A, best camera rotation taken out ({:.3f} px rms)", c.camera,
        p.fitted_rms_px);
    plot.x_label = "u [px]";
    plot.y_label = "v [px]";
    plot.value_label = "|difference| [px]";
    plot.equal_axes = true;
    plot.y_down = true;
    report::PlotSeries points;
    for (size_t i = 0; i < p.u.size(); ++i) {
      if (!std::isfinite(p.fitted_px[i])) continue;
      points.x.push_back(p.u[i]);
      points.y.push_back(p.v[i]);
      points.values.push_back(p.fitted_px[i]);
    }
    plot.series.push_back(std::move(points));
    maps.emplace_back(fmt::format("projection_diff_{}.svg", c.camera), report::render_svg(plot));
  }
  return maps;
}

std::vector<io::OutputFile> diff_report_files(const RigDifference& d,
                                              const std::filesystem::path& dir) {
  const nlohmann::json j = diff_json(d);
  const std::vector<std::pair<std::string, std::string>> maps = projection_maps(d);
  std::vector<io::OutputFile> files{{dir / "diff.json", j.dump(2) + "\n"},
                                    {dir / "report.html", diff_html(j, maps)}};
  for (const auto& [name, svg] : maps) files.push_back({dir / name, svg});
  return files;
}

}  // namespace rigcal::session
