#include "rigcal/session/calibrate.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "rigcal/core/error.h"
#include "rigcal/core/sha256.h"
#include "rigcal/core/text.h"
#include "rigcal/core/version.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/session.h"
#include "rigcal/report/json.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/session/provenance.h"
#include "rigcal/session/report_html.h"

namespace rigcal::session {
namespace fs = std::filesystem;
namespace {

// What the pipeline knows of a step before running it: where its inputs are, the rig entries it
// reads, its options as text, and how to run it.
struct Plan {
  std::string step;
  std::vector<std::string> depends_on;
  std::vector<std::pair<std::string, fs::path>> inputs;  // role, path
  std::vector<std::string> reads;                        // rig sensors
  std::string options;
  std::function<report::StepResult(const rig::Rig&, const report::Progress&)> run;
  std::string cannot_plan;                 // why it cannot run (a missing input), else ""
  std::shared_ptr<bool> reuse_detections;  // cameras: set when the detections cache may be used
};

// An entry "NAME.T_b" stands for that sensor's pose alone, "NAME" for its whole entry.
bool pose_only(const std::string& entry, std::string& name) {
  const bool pose = entry.size() > 4 && entry.compare(entry.size() - 4, 4, ".T_b") == 0;
  name = pose ? entry.substr(0, entry.size() - 4) : entry;
  return pose;
}

std::string fingerprint(const rig::Rig& rig, const std::vector<std::string>& entries) {
  std::string out;
  for (const std::string& entry : entries) {
    std::string name;
    if (pose_only(entry, name)) {
      const rig::Sensor* s = rig::find_sensor(rig, name);
      out +=
          s ? entry + ":\n" + rig::yaml_matrix4_rows(s->T_base_sensor, "") : entry + ": absent\n";
      continue;
    }
    const rig::Sensor* s = rig::find_sensor(rig, name);
    if (!s) {
      out += name + ": absent\n";
      continue;
    }
    rig::Rig one;
    one.sensors = {*s};
    one.sensors[0].attached_to.clear();
    one.base_frame = name;
    out += rig::rig_to_yaml(one);
    out += "attached_to: " + s->attached_to + "\n";
  }
  return out;
}

std::vector<std::string> camera_names(const rig::Rig& rig) {
  std::vector<std::string> out;
  for (const rig::Sensor* c : rig::cameras(rig)) out.push_back(c->name);
  return out;
}

nlohmann::json figures_json(const std::vector<report::Figure>& figures) {
  nlohmann::json j = nlohmann::json::array();
  for (const report::Figure& f : figures)
    j.push_back({{"name", f.name},
                 {"value", std::isfinite(f.value) ? nlohmann::json(f.value) : nlohmann::json()},
                 {"unit", f.unit}});
  return j;
}

std::vector<report::Figure> figures_from(const nlohmann::json& j) {
  std::vector<report::Figure> out;
  for (const nlohmann::json& f : j)
    out.push_back(
        {f.at("name"), f.at("value").is_null() ? NAN : f.at("value").get<double>(), f.at("unit")});
  return out;
}

nlohmann::json correlations_json(const std::vector<report::Correlation>& correlations) {
  nlohmann::json out = nlohmann::json::array();
  for (const report::Correlation& c : correlations)
    out.push_back({{"name", c.name}, {"names", c.names}, {"rho", c.rho}});
  return out;
}

std::vector<report::Correlation> correlations_from(const nlohmann::json& j) {
  std::vector<report::Correlation> out;
  for (const nlohmann::json& c : j) {
    out.push_back({c.at("name"), c.at("names").get<std::vector<std::string>>(),
                   c.at("rho").get<std::vector<double>>()});
  }
  return out;
}

// The cached result of a step: what StepRun shows, the rig it wrote and its inputs' hashes.
struct Cached {
  StepRun run;
  rig::Rig rig;
  std::vector<std::string> wrote;
  std::vector<HashedInput> inputs;
};

// What a step's run says, as the cache and OUT/reports/calibrate.json store it.
nlohmann::json run_json(const StepRun& run) {
  nlohmann::json j;
  j["step"] = run.step;
  j["status"] = run.status;
  j["reason"] = run.reason;
  j["remedy"] = run.remedy;
  j["summary"] = run.summary;
  j["notes"] = run.notes;
  j["warnings"] = run.warnings;
  j["sigmas"] = figures_json(run.sigmas);
  j["residuals"] = figures_json(run.residuals);
  j["correlations"] = correlations_json(run.correlations);
  j["seconds"] = run.seconds;
  return j;
}

nlohmann::json cache_json(const std::string& key, const StepRun& run, const rig::Rig& rig,
                          const std::vector<std::string>& wrote,
                          const std::vector<HashedInput>& inputs) {
  nlohmann::json j = run_json(run);
  j["key"] = key;
  j["tool_version"] = version_string();
  j["wrote"] = wrote;
  j["rig"] = rig::rig_to_yaml(rig);
  j["inputs"] = nlohmann::json::array();
  for (const HashedInput& in : inputs)
    j["inputs"].push_back({{"role", in.role},
                           {"path", in.path.string()},
                           {"sha256", in.sha256},
                           {"files", in.files}});
  return j;
}

std::optional<Cached> read_cache(const fs::path& file, const std::string& key) {
  if (!fs::exists(file)) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(io::read_text_file(file));
    if (j.at("key") != key) return std::nullopt;
    Cached c;
    c.run.step = j.at("step");
    c.run.status = j.at("status");
    c.run.reason = j.at("reason");
    c.run.remedy = j.at("remedy");
    c.run.summary = j.at("summary").get<std::vector<std::string>>();
    c.run.notes = j.at("notes").get<std::vector<std::string>>();
    c.run.warnings = j.at("warnings").get<std::vector<std::string>>();
    c.run.sigmas = figures_from(j.at("sigmas"));
    c.run.residuals = figures_from(j.at("residuals"));
    c.run.correlations = correlations_from(j.at("correlations"));
    c.run.cached = true;
    c.wrote = j.at("wrote").get<std::vector<std::string>>();
    c.rig = rig::parse_rig_yaml(j.at("rig").get<std::string>(), file.string());
    for (const nlohmann::json& in : j.at("inputs"))
      c.inputs.push_back({in.at("role"), in.at("path").get<std::string>(), in.at("sha256"),
                          in.at("files").get<size_t>()});
    return c;
  } catch (const std::exception&) {
    return std::nullopt;  // a cache of another version or damaged: run again
  }
}

// Copies what a step wrote from its rig into `rig`: whole entries (added where the rig lacks
// them) or, for "NAME.T_b", the pose alone.
void apply(rig::Rig& rig, const rig::Rig& step_rig, const std::vector<std::string>& wrote) {
  for (const std::string& entry : wrote) {
    std::string name;
    const bool pose = pose_only(entry, name);
    const rig::Sensor& from = rig::sensor(step_rig, name);
    rig::Sensor* to = rig::find_sensor(rig, name);
    if (!to) {
      rig.sensors.push_back(from);
    } else if (pose) {
      to->T_base_sensor = from.T_base_sensor;
    } else {
      *to = from;
    }
  }
}

// Writes the report folder whole: into a fresh sibling, then swapped in.
void write_report_folder(const fs::path& dir, const std::vector<io::OutputFile>& files) {
  const fs::path fresh = dir.string() + ".new";
  fs::remove_all(fresh);
  std::vector<io::OutputFile> placed;
  for (const io::OutputFile& f : files) placed.push_back({fresh / f.path, f.content});
  try {
    io::write_files_atomic(placed);
    fs::create_directories(fresh);
    fs::remove_all(dir);
    fs::rename(fresh, dir);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(fresh, ec);
    throw;
  }
}

std::string detections_key(const std::vector<HashedInput>& hashed, const CalibrateOptions& o) {
  Sha256 k;
  for (const HashedInput& h : hashed) k.update(h.role + " " + h.sha256 + "\n");
  k.update("bayer " + std::string(io::to_string(o.cameras.bayer)));
  return k.hex();
}

std::vector<Plan> make_plans(const CalibrateOptions& o, const io::Session& s,
                             const fs::path& target, const fs::path& out) {
  std::vector<Plan> plans;
  auto recording = [&](std::string_view purpose, Plan& p) -> fs::path {
    try {
      return io::recording_for(s, purpose);
    } catch (const Error& e) {
      p.cannot_plan = e.what();
      return {};
    }
  };
  auto need_target = [&](Plan& p) {
    if (target.empty() && p.cannot_plan.empty())
      p.cannot_plan = "no target: give --target T.yaml or name it in session.yaml (target: T.yaml)";
    if (!target.empty()) p.inputs.emplace_back("target", target);
  };
  {
    Plan p;
    p.step = "cameras";
    const fs::path rec = recording("cameras", p);
    need_target(p);
    for (const char* f : {"camera_left", "camera_right"}) {
      if (!rec.empty() && fs::is_directory(rec / f)) p.inputs.emplace_back(f, rec / f);
    }
    p.reads = {"cam_l", "cam_r"};
    p.options =
        fmt::format("model {} outlier_sigma {} bayer {} fit_at_rig {} board_warp {}",
                    o.cameras.model, o.cameras.outlier_sigma, io::to_string(o.cameras.bayer),
                    o.cameras.fit_at_rig, o.cameras.board_warp);
    // Named only when on: a session cached before the option existed stays cached.
    if (o.cameras.saddle_fit) p.options += " saddle_fit 1";
    p.reuse_detections = std::make_shared<bool>(false);
    p.run = [rec, target, out, opt = o.cameras, reuse = p.reuse_detections](
                const rig::Rig& rig, const report::Progress& pr) {
      camera::StepInputs in;
      in.target = target;
      in.images = io::read_session_images(rec);
      in.rig = rig;
      // Only from a run on these very images, target and Bayer pattern: corners.vnl names images
      // by path.
      if (*reuse) in.corners_cache = out / "reports" / "cameras" / "corners.vnl";
      return camera::calibrate_cameras(in, opt, pr);
    };
    plans.push_back(std::move(p));
  }
  {
    Plan p;
    p.step = "lidar_camera";
    p.depends_on = {"cameras"};
    const fs::path rec = recording("lidar_camera", p);
    need_target(p);
    const lidar_camera::StepOptions& lo = o.lidar_camera;
    if (!rec.empty()) {
      p.inputs.emplace_back("images",
                            rec / (lo.camera == "cam_l" ? "camera_left" : "camera_right"));
      p.inputs.emplace_back("scans", rec / "ouster_points");
    }
    p.options = fmt::format(
        "camera {} lidar {} bayer {} board {} {} roi {} corner_sigma {} max_dt {}", lo.camera,
        lo.lidar, io::to_string(lo.bayer), lo.board_width_m.value_or(0),
        lo.board_height_m.value_or(0),
        lo.roi ? fmt::format("{} {}", fmt::join(lo.roi->first, ","), fmt::join(lo.roi->second, ","))
               : "none",
        lo.corner_sigma_px, lo.max_dt_s);
    if (lo.fit_at_rig) {
      p.options += " fit_at_rig";
      const Eigen::Matrix4d T = lo.fit_at ? lo.fit_at->matrix() : Eigen::Matrix4d::Zero();
      for (int i = 0; i < 12; ++i) p.options += fmt::format(" {:.17g}", T(i / 4, i % 4));
    }
    p.run = [rec, target, lo](const rig::Rig& rig, const report::Progress& pr) {
      lidar_camera::StepInputs in = lidar_camera::pairs_from_recording(rec, rig, lo);
      in.target = target;
      in.rig_source = "the session's rig after the cameras step";
      return lidar_camera::calibrate_lidar_camera(in, lo, pr);
    };
    plans.push_back(std::move(p));
  }
  {
    Plan p;
    p.step = "time_sync";
    const fs::path rec = recording("motion", p);
    if (!rec.empty()) {
      p.inputs.emplace_back("reference", rec / "ouster_imu");
      p.inputs.emplace_back("other", rec / "imu");
    }
    p.reads = {"os_imu", "imu"};
    const time_sync::TimeSyncOptions& t = o.time_sync;
    p.options = fmt::format(
        "max_offset {} min_overlap {} window {} min_excitation {} three_axis {} coarse_hz {} "
        "fine_hz_max {} max_peak_ratio {} min_peak_ncc {}",
        t.max_offset_s, t.min_overlap, t.window_s, t.min_excitation_rad_s, t.three_axis,
        t.coarse_hz, t.fine_hz_max, t.max_peak_ratio, t.min_peak_ncc);
    p.run = [rec, t](const rig::Rig& rig, const report::Progress& pr) {
      time_sync::StepInputs in = time_sync::streams_of_recording(rec);
      in.rig = rig;
      return time_sync::estimate_clock(in, t, pr);
    };
    plans.push_back(std::move(p));
  }
  {
    Plan p;
    p.step = "hand_eye";
    const fs::path odometry = o.odometry.empty() ? s.odometry : o.odometry;
    const fs::path gnss = o.gnss.empty() ? s.gnss : o.gnss;
    // No odometry named: rigcal's own on the motion recording's scans.
    fs::path scans;
    if (odometry.empty()) {
      try {
        const fs::path rec = io::recording_for(s, "motion");
        if (fs::is_directory(rec / "ouster_points")) scans = rec / "ouster_points";
      } catch (const Error&) {
      }
    }
    if (odometry.empty() && scans.empty())
      p.cannot_plan =
          "no LiDAR odometry: the motion recording has no ouster_points/ for rigcal's own "
          "odometry; record the LiDAR during the motion, or give --odometry FILE.tum "
          "(T_odom_lidar) or name it in session.yaml (odometry: FILE)";
    else if (gnss.empty())
      p.cannot_plan =
          "no GNSS/INS trajectory: give --gnss FILE, put it in the motion recording as "
          "gnss/poses.tum or gnss/fixes.csv, or name it in session.yaml (gnss: FILE)";
    if (!odometry.empty()) p.inputs.emplace_back("lidar odometry", odometry);
    if (!scans.empty()) p.inputs.emplace_back("lidar scans", scans);
    if (!gnss.empty()) p.inputs.emplace_back("gnss", gnss);
    const hand_eye::StepOptions& h = o.hand_eye;
    p.reads = {h.sensor, h.lidar_sensor};
    std::string fixed;
    for (const auto& f : h.refine.fixed)
      fixed += fmt::format("[{} {} {}]={},{} ", f.direction.x(), f.direction.y(), f.direction.z(),
                           f.value_m, f.sigma_m);
    p.options = fmt::format(
        "sensor {} lidar {} attitude {} spacings {} stride {} min_rotation {} smoothing {} "
        "rotation_sigma {} translation_sigma {} max_sigma {} estimate_offset {} fixed {} "
        "duplicates {} max_gap {} huber {} estimate_scale {} odometry_preset {} sweep_motion {}",
        h.sensor, h.lidar_sensor, h.attitude, fmt::join(h.pairs.spacings_s, ","), h.pairs.stride_s,
        h.pairs.min_rotation_deg, h.pairs.gnss_half_window_s, h.refine.rotation_sigma_deg,
        h.refine.translation_sigma_m, h.max_sigma_m, h.estimate_offset, fixed,
        static_cast<int>(h.duplicates), h.pairs.max_gap_s, h.refine.huber, h.refine.estimate_scale,
        h.odometry_preset.empty() ? "rig" : h.odometry_preset, h.odometry_sweep_motion);
    if (h.fit_at_rig) p.options += " fit_at_rig";
    p.run = [odometry, scans, gnss, h](const rig::Rig& rig, const report::Progress& pr) {
      hand_eye::StepInputs in;
      in.lidar = odometry;
      in.lidar_scans = scans;
      in.gnss = gnss;
      in.rig = rig;
      in.rig_source = "the session's rig";
      return hand_eye::estimate_extrinsic(in, h, pr);
    };
    plans.push_back(std::move(p));
  }
  return plans;
}

}  // namespace

void check_step_name(std::string_view name) {
  for (const char* s : kSteps) {
    if (name == s) return;
  }
  throw Error(fmt::format("unknown step '{}': the steps are {}", name, fmt::join(kSteps, ", ")));
}

CalibrateResult calibrate(const CalibrateOptions& o, const Progress& progress) {
  if (!o.from.empty()) check_step_name(o.from);
  if (!o.only.empty()) check_step_name(o.only);
  if (!o.from.empty() && !o.only.empty()) throw Error("give --from or --only, not both");
  if (o.out.empty()) throw Error("--out: the output folder is needed");
  const io::FolderLock claim(o.out);
  const io::Session s = io::read_session(o.session, progress);
  const fs::path rig_file = o.rig.empty() ? s.rig : o.rig;
  if (rig_file.empty()) {
    throw Error(fmt::format(
        "no prior rig: give --rig PRIOR.yaml or name it in {}/session.yaml (rig: FILE); it names "
        "the sensors and holds what the steps do not estimate (data/sample_rig.yaml is an "
        "example)",
        o.session.string()));
  }
  const fs::path target = o.target.empty() ? s.target : o.target;
  CalibrateResult result;
  result.rig = rig::read_rig_file(rig_file);
  // Fitting the LiDAR-camera boards at the given rig: at its extrinsic as given, before the
  // cameras step moves the cameras.
  CalibrateOptions planned = o;
  lidar_camera::StepOptions& lo = planned.lidar_camera;
  if (lo.fit_at_rig && !lo.fit_at && rig::find_sensor(result.rig, lo.camera) &&
      rig::find_sensor(result.rig, lo.lidar))
    lo.fit_at = rig::T_a_b(result.rig, lo.camera, lo.lidar);
  // A GNSS/INS sensor's attached sensors are read (and written) by hand-eye too.
  std::vector<Plan> plans = make_plans(planned, s, target, o.out);
  for (Plan& p : plans) {
    if (p.step == "lidar_camera") {
      p.reads = camera_names(result.rig);
      p.reads.push_back(o.lidar_camera.lidar);
    }
    if (p.step == "hand_eye") {
      rig::Rig probe = result.rig;
      if (rig::find_sensor(probe, o.hand_eye.sensor)) {
        for (const std::string& n : rig::move_rigidly(
                 probe, o.hand_eye.sensor, rig::sensor(probe, o.hand_eye.sensor).T_base_sensor)) {
          if (n != o.hand_eye.sensor) p.reads.push_back(n + ".T_b");
        }
      }
    }
  }

  std::vector<StepRecord> records;
  std::map<std::string, std::string> status_of;
  bool internal = false;
  bool before_from = !o.from.empty();
  for (Plan& p : plans) {
    if (p.step == o.from) before_from = false;
    StepRun run;
    run.step = p.step;
    auto tell = [&](std::string_view what, size_t done, size_t total) {
      report::tell(progress, fmt::format("[{}] {}", p.step, what), done, total);
    };
    const fs::path cache_file = o.out / "cache" / (p.step + ".json");
    const fs::path report_dir = o.out / "reports" / p.step;
    std::string blocked;
    bool dependency_not_run = false;
    for (const std::string& d : p.depends_on) {
      if (status_of[d] != "ok") blocked = fmt::format("needs {}, which is {}", d, status_of[d]);
      dependency_not_run |= status_of[d] == "not run";
    }
    // The key: the files it reads, the rig entries it reads, its options, this version.
    std::vector<HashedInput> hashed;
    std::string key;
    if (p.cannot_plan.empty() && blocked.empty()) {
      try {
        for (const auto& [role, path] : p.inputs) {
          hashed.push_back(hash_input(role, path));
          hashed.back().path = io::source_path(s, hashed.back().path);  // a bag's, not /tmp's
          tell("hashing the inputs", hashed.size(), p.inputs.size());
        }
        Sha256 k;
        k.update(p.step + "\n" + version_string() + "\n" + p.options + "\n");
        k.update(fingerprint(result.rig, p.reads));
        for (const HashedInput& h : hashed) k.update(h.role + " " + h.sha256 + "\n");
        key = k.hex();
      } catch (const std::exception& e) {  // unreadable, or a folder behind a looping link
        p.cannot_plan = e.what();
      }
    }
    std::optional<Cached> cached;
    const bool forced = (!o.from.empty() && !before_from) || o.only == p.step;
    if (!key.empty() && !forced && fs::exists(report_dir / (p.step + ".json")))
      cached = read_cache(cache_file, key);
    if (before_from && !cached) {
      throw Error(fmt::format(
          "--from {}: the earlier step {} has no cached result for these inputs in {}{}", o.from,
          p.step, (o.out / "cache").string(),
          p.cannot_plan.empty() ? "; run without --from first"
                                : fmt::format(" (it cannot run: {})", p.cannot_plan)));
    }
    if (p.reuse_detections) {
      // The last run's detections are reused when they came from these images, this target and
      // this Bayer pattern.
      *p.reuse_detections = false;
      try {
        if (fs::exists(cache_file) && !key.empty()) {
          const nlohmann::json old = nlohmann::json::parse(io::read_text_file(cache_file));
          *p.reuse_detections = old.value("detections_key", "") == detections_key(hashed, o);
        }
      } catch (const std::exception&) {
      }
    }
    std::vector<std::string> wrote;
    rig::Rig step_rig;
    if (!o.only.empty() && o.only != p.step && !cached) {
      run.status = "not run";
      run.reason = fmt::format("--only {}", o.only);
    } else if (dependency_not_run) {
      run.status = "not run";
      run.reason = blocked;
    } else if (!p.cannot_plan.empty()) {
      run.status = "failed";
      run.reason = p.cannot_plan;
    } else if (!blocked.empty()) {
      run.status = "blocked";
      run.reason = blocked;
    } else if (cached) {
      run = cached->run;
      step_rig = cached->rig;
      wrote = cached->wrote;
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      try {
        report::StepResult r = p.run(result.rig, tell);
        run = step_run(r);
        run.step = p.step;
        run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        step_rig = r.rig;
        wrote = r.wrote;
        write_report_folder(report_dir, r.report_files);
        nlohmann::json cache = cache_json(key, run, step_rig, wrote, hashed);
        if (p.reuse_detections) cache["detections_key"] = detections_key(hashed, o);
        io::write_file_atomic(cache_file, report::json_text(cache));
      } catch (const std::exception& e) {
        // Bad input fails the step; anything else is a bug, said as one; the run goes on.
        const bool bad_input = dynamic_cast<const Error*>(&e) != nullptr;
        run.status = "failed";
        run.reason = bad_input ? e.what() : fmt::format("internal error: {}", e.what());
        internal |= !bad_input;
        std::error_code ec;
        fs::remove(cache_file, ec);
        fs::remove_all(report_dir, ec);
      }
    }
    if (run.status == "ok") {
      apply(result.rig, step_rig, wrote);
      records.push_back({p.step, run.status, version_string(), "", hashed, run.sigmas,
                         run.residuals, run.correlations});
    }
    status_of[p.step] = run.status;
    result.steps.push_back(std::move(run));
  }

  bool failed = false, undetermined = false, all_ok = true;
  for (const StepRun& r : result.steps) {
    failed |= r.status == "failed";
    undetermined |= r.status == "undetermined";
    all_ok &= r.status == "ok";
  }
  // A blocked step counts through the step that blocked it.
  result.exit_status = internal ? 1 : failed ? 2 : undetermined ? 3 : 0;
  if (all_ok) {
    auto& meta = result.rig.extra_metadata;
    meta.erase(std::remove_if(meta.begin(), meta.end(),
                              [](const auto& kv) { return kv.first == "steps"; }),
               meta.end());
    meta.emplace_back("steps", steps_yaml(records));
    result.calibration = o.out / "calib.yaml";
    io::write_file_atomic(result.calibration, rig::rig_to_yaml(result.rig));
    result.published = true;
  } else if (fs::exists(o.out / "calib.yaml")) {
    // An earlier run's calibration no longer matches these inputs: not left to be published.
    fs::remove(o.out / "calib.yaml");
    result.removed_stale = o.out / "calib.yaml";
  }
  // The run as a person reads it: OUT/reports/calibrate.json, rendered into OUT/report.html.
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["session"] = io::source_path(s, s.root).string();
  j["published"] = result.published;
  j["calibration"] = result.calibration.string();
  j["exit_status"] = result.exit_status;
  j["steps"] = nlohmann::json::array();
  for (const StepRun& run : result.steps) {
    nlohmann::json r = run_json(run);
    r["cached"] = run.cached;
    j["steps"].push_back(r);
  }
  io::write_file_atomic(o.out / "reports" / "calibrate.json", report::json_text(j));
  const io::OutputFile page = render_report(o.out);
  io::write_file_atomic(page.path, page.content);
  return result;
}

StepRun step_run(const report::StepResult& r) {
  StepRun run;
  run.step = r.step;
  run.status = std::string(report::to_string(r.status));
  run.reason = r.reason, run.remedy = r.remedy;
  run.summary = r.summary, run.notes = r.notes, run.warnings = r.warnings;
  run.sigmas = r.sigmas, run.residuals = r.residuals, run.correlations = r.correlations;
  return run;
}

io::OutputFile step_run_file(const report::StepResult& r, const fs::path& dir) {
  const StepRun run = step_run(r);
  nlohmann::json j;
  j["tool_version"] = version_string();
  j["run"] = run_json(run);
  return {dir / "run.json", report::json_text(j)};
}

CalibrateText calibrate_text(const CalibrateResult& r, const fs::path& out) {
  CalibrateText t;
  std::vector<std::string>& lines = t.lines;
  for (const StepRun& s : r.steps) {
    if (s.status == "not run") continue;
    lines.push_back(fmt::format("== {}: {}{}", s.step, s.status,
                                s.cached ? " (cached: inputs unchanged)" : ""));
    for (const std::string& line : s.summary) lines.push_back(line);
    for (const std::string& n : s.notes) lines.push_back("note: " + n);
    for (const std::string& w : s.warnings) lines.push_back("warning: " + w);
    if (s.status != "ok")
      lines.push_back(fmt::format("{}: {}", s.status, printable(s.reason, 2000)));
    if (!s.remedy.empty()) lines.push_back("what would settle it: " + s.remedy);
  }
  // The table: one row a step, its residual figures or the reason it did not end ok.
  lines.push_back("");
  lines.push_back(fmt::format("  {:<13} {:<13} {:>8}  {}", "step", "status", "time", "result"));
  for (const StepRun& s : r.steps) {
    std::string result;
    for (const report::Figure& f : s.residuals) {
      if (result.size() > 60) break;
      const bool whole = f.value == std::floor(f.value) && std::abs(f.value) < 1e9;
      result += fmt::format("{}{} {}{}", result.empty() ? "" : ", ", f.name,
                            whole ? fmt::format("{:.0f}", f.value) : fmt::format("{:.4g}", f.value),
                            f.unit.empty() || f.name.ends_with(f.unit) ? "" : " " + f.unit);
    }
    lines.push_back(fmt::format("  {:<13} {:<13} {:>8}  {}", s.step, s.status,
                                s.cached        ? "cached"
                                : s.seconds > 0 ? fmt::format("{:.2f} s", s.seconds)
                                                : "-",
                                s.status == "ok" ? result : printable(s.reason, 2000)));
  }
  lines.push_back("");
  if (r.published) {
    lines.push_back(fmt::format(
        "published {} (rigcal rig show prints its provenance); the report to read: {}/report.html",
        r.calibration.string(), out.string()));
    return t;
  }
  lines.push_back(fmt::format("the report to read: {}/report.html", out.string()));
  if (!r.removed_stale.empty()) {
    lines.push_back(fmt::format("removed {}: an earlier run's, it does not match these inputs",
                                r.removed_stale.string()));
  }
  std::vector<const StepRun*> open;  // failed first, then undetermined or blocked
  for (const bool failed : {true, false}) {
    for (const StepRun& s : r.steps) {
      if (s.status != "ok" && s.status != "not run" && (s.status == "failed") == failed)
        open.push_back(&s);
    }
  }
  if (open.empty()) {
    std::vector<std::string> not_run;
    for (const StepRun& s : r.steps)
      if (s.status == "not run") not_run.push_back(s.step);
    lines.push_back(fmt::format("nothing published: {} not run", fmt::join(not_run, ", ")));
    return t;
  }
  const StepRun& first = *open.front();
  std::string others;
  for (size_t k = 1; k < open.size(); ++k)
    others += fmt::format("{}{} {}", k == 1 ? "; also " : ", ", open[k]->step, open[k]->status);
  t.error_line = fmt::format("rigcal: {}: {}: {} (nothing published{})",
                             first.status == "failed" ? "error" : first.status, first.step,
                             printable(first.reason, 2000), others);
  return t;
}

}  // namespace rigcal::session
