#include "rigcal/hand_eye/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "rigcal/core/version.h"
#include "rigcal/report/json.h"
#include "rigcal/report/rotation.h"
#include "rigcal/report/svg_plot.h"

namespace rigcal::hand_eye {
std::vector<io::OutputFile> hand_eye_report_files(const std::filesystem::path& dir,
                                                  const HandEyeInputs& in,
                                                  const std::vector<MotionPair>& pairs,
                                                  const ClosedForm& cf, const Refined& r,
                                                  const Trajectory& lidar, const Trajectory& gnss) {
  std::vector<io::OutputFile> files;
  const Observability& ob = cf.observability;
  const SE3& X = r.T_gnss_lidar;
  const Eigen::Vector3d rpy = roll_pitch_yaw(X.R) * 180.0 / M_PI;
  const Eigen::Vector3d &sig_r = r.rotation_sigma_deg, &sig_t = r.translation_sigma_m;
  const std::vector<std::string>& notes = in.notes;
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["definition"] =
      "T_gnss_lidar: the LiDAR in the GNSS/INS frame; for each pair, A = T_L(t0)^-1 T_L(t1) and "
      "B = T_G(t0)^-1 T_G(t1) satisfy B X = X A";
  j["inputs"] = {{"lidar", in.lidar},
                 {"gnss", in.gnss},
                 {"rig", in.rig},
                 {"gnss_time_offset_s", in.gnss_time_offset_s},
                 {"spacings_s", in.spacings_s},
                 {"stride_s", in.stride_s},
                 {"min_rotation_deg", in.min_rotation_deg}};
  j["T_gnss_lidar"] = {{"t_m", report::vector_json(X.t)},
                       {"axis_angle", report::axis_angle_json(X.R)},
                       {"roll_pitch_yaw_deg", report::vector_json(rpy)},
                       {"t_sigma_m", report::vector_json(sig_t)},
                       {"rotation_sigma_deg", report::vector_json(sig_r)},
                       {"matrix", {X.matrix().row(0), X.matrix().row(1), X.matrix().row(2)}}};
  if (r.time_offset_sigma_s > 0) {  // estimated (--estimate-offset): refined with X
    j["clock_offset"] = {{"gnss_time_offset_s", in.gnss_time_offset_s},
                         {"sigma_s", r.time_offset_sigma_s},
                         {"correction_in_refinement_s", r.time_offset_correction_s}};
  }
  j["closed_form"] = {
      {"t_m", report::vector_json(cf.T_gnss_lidar.t)},
      {"roll_pitch_yaw_deg", report::vector_json(roll_pitch_yaw(cf.T_gnss_lidar.R) * 180 / M_PI)},
      {"axis_residual_rms_deg", cf.rotation_residual_rms_deg},
      {"pairs_left_out_by_consensus", cf.rejected}};
  nlohmann::json unobs = nlohmann::json::array();
  for (int i : ob.unobservable)
    unobs.push_back(report::vector_json(ob.translation_directions.col(i)));
  j["observability"] = {
      {"rotation_singular_values_rad", report::vector_json(ob.rotation_singular_values)},
      {"near_planar", ob.near_planar},
      {"near_planar_ratio", kNearPlanarRatio},
      {"dominant_rotation_axis", report::vector_json(ob.dominant_axis)},
      {"translation_singular_values", report::vector_json(ob.translation_singular_values)},
      {"translation_directions",
       {report::vector_json(ob.translation_directions.col(0)),
        report::vector_json(ob.translation_directions.col(1)),
        report::vector_json(ob.translation_directions.col(2))}},
      {"translation_sigma_m", report::vector_json(ob.translation_sigma_m)},
      {"unobservable_directions", unobs},
      {"max_sigma_m", in.max_sigma_m}};
  j["noise_scale"] = r.noise_scale;
  j["odometry_scale"] = {
      {"definition",
       "factor on every LiDAR odometry translation, estimated with the extrinsic (GNSS/INS "
       "distance over odometry distance)"},
      {"value", r.odometry_scale},
      {"sigma", r.odometry_scale_sigma}};
  nlohmann::json levels = nlohmann::json::array();
  for (const Refined::PairNoise& n : r.pair_noise) {
    levels.push_back({{"length_s", n.length_s},
                      {"pairs", n.pairs},
                      {"rotation_deg", n.rotation_deg},
                      {"translation_m", n.translation_m}});
  }
  j["pair_noise"] = {
      {"definition",
       "per pair length: RMS per component of the inlier pairs' residuals after a first solve "
       "with the given sigmas; the final solve weighs each pair with its length's levels"},
      {"levels", levels}};
  j["notes"] = notes;
  nlohmann::json pj = nlohmann::json::array();
  for (size_t k = 0; k < pairs.size(); ++k) {
    pj.push_back({{"t0_s", to_seconds_text(pairs[k].t0)},
                  {"t1_s", to_seconds_text(pairs[k].t1)},
                  {"rotation_deg", rotation_angle(pairs[k].B.R) * 180 / M_PI},
                  {"rotation_residual_deg", r.pair_rotation_residual_deg[k]},
                  {"translation_residual_m", r.pair_translation_residual_m[k]},
                  {"outlier", static_cast<bool>(r.outlier[k])}});
  }
  j["pairs"] = pj;
  files.push_back({dir / "hand_eye.json", report::json_text(j)});
  // Residuals over time.
  report::Plot p;
  p.title = "Per-pair residuals after the solve";
  p.x_label = "t0 (s since the first pair)";
  p.y_label = "translation residual (mm)";
  report::PlotSeries s{"translation", {}, {}, {}};
  for (size_t k = 0; k < pairs.size(); ++k) {
    s.x.push_back((pairs[k].t0 - pairs.front().t0).seconds());
    s.y.push_back(1e3 * r.pair_translation_residual_m[k]);
  }
  s.values.assign(s.x.size(), 0.0);
  p.series = {s};
  files.push_back({dir / "residuals.png", report::render_png(p)});
  // The GNSS/INS positions and the LiDAR odometry carried into the GNSS/INS frame through X,
  // aligned at the middle pair.
  const MotionPair& mid = pairs[pairs.size() / 2];
  report::Plot top;
  top.title = "Top view: GNSS/INS and LiDAR odometry through the extrinsic";
  top.x_label = "x (m)";
  top.y_label = "y (m)";
  top.equal_axes = true;
  report::PlotSeries gs{"GNSS/INS", {}, {}, {}}, ls{"LiDAR via X", {}, {}, {}};
  for (const SE3& T : gnss.T_world_body) gs.x.push_back(T.t.x()), gs.y.push_back(T.t.y());
  // T_enu_odom from the middle pair's start: T_enu_G(t0) X T_odom_L(t0)^-1.
  const auto find = [&](const Trajectory& tr, Time t) {
    const auto it = std::lower_bound(tr.stamps.begin(), tr.stamps.end(), t);
    return static_cast<size_t>(std::min<ptrdiff_t>(it - tr.stamps.begin(), tr.size() - 1));
  };
  const SE3 T_enu_odom =
      gnss.T_world_body[find(gnss, mid.t0 - Time::from_seconds(in.gnss_time_offset_s))] * X *
      lidar.T_world_body[find(lidar, mid.t0)].inverse();
  for (const SE3& T : lidar.T_world_body) {
    const SE3 G = T_enu_odom * T * X.inverse();
    ls.x.push_back(G.t.x()), ls.y.push_back(G.t.y());
  }
  top.series = {gs, ls};
  files.push_back({dir / "trajectories.png", report::render_png(top)});
  return files;
}

std::vector<std::string> fit_warnings(const Refined& r) {
  std::vector<std::string> out;
  const size_t n = r.outlier.size();
  const size_t outliers = static_cast<size_t>(std::count(r.outlier.begin(), r.outlier.end(), true));
  if (n > 0 && 10 * outliers > n) {
    out.push_back(fmt::format(
        "{} of the {} motion pairs ({:.0f} %) are outliers (beyond 3 robust sigmas of the fit): "
        "the trajectories disagree more often than their noise says. Look at the residuals "
        "along the recording: a stretch of bad odometry or tracking, jumps in the GNSS/INS "
        "poses, or clocks apart",
        outliers, n, 100.0 * double(outliers) / double(n)));
  }
  const double ds = r.odometry_scale - 1.0;
  if (r.odometry_scale_sigma > 0 && std::abs(ds) > 3 * r.odometry_scale_sigma &&
      std::abs(ds) > 0.01) {
    out.push_back(fmt::format(
        "the odometry's distances are {:.1f} % {} than the GNSS/INS's (scale {:.4f} +- {:.4f}, "
        "{:.1f} sigma from 1): the extrinsic was fitted with that scale, but a LiDAR odometry "
        "should need none; a tracked camera's scale (its target's size) or a degenerate "
        "stretch of the odometry is the usual cause",
        100.0 * std::abs(ds), ds > 0 ? "shorter" : "longer", r.odometry_scale,
        r.odometry_scale_sigma, std::abs(ds) / r.odometry_scale_sigma));
  }
  return out;
}

}  // namespace rigcal::hand_eye
