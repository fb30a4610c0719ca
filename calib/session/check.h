#pragma once
// Does a calibration still fit? (doc/check.md) The steps run again on a new session, from the
// stored calibration, and each quantity a step estimated with a sigma is compared with the stored
// one through both sigmas (diff.h: chi-square of the differences over the combined sigmas, and
// its probability if nothing changed). Each quantity gets a verdict:
//   consistent   the re-estimate agrees with the stored value within the two sigmas;
//   changed      it does not (p below CheckOptions::alarm_p): by how much, in px, mm, deg, ms;
//   cannot tell  the new data do not determine it (its step did not end ok, or the new sigma is
//                many times the stored one): what to record instead.
// The sensors every changed quantity involves are named as the suspects.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/session/calibrate.h"
#include "rigcal/session/diff.h"

namespace rigcal::session {

struct CheckOptions {
  // The new session, the folder for the re-estimate (its reports, cache and calib.yaml), and
  // each step's options; its `rig` is set to the stored calibration's file.
  CalibrateOptions calibrate;
  // A quantity is "changed" when P(chi-square >= its chi-square) is below this: one false alarm
  // in a thousand checks of an unchanged quantity, when the sigmas are honest.
  double alarm_p = 1e-3;
  // "cannot tell" when a component's new sigma is more than this many times the stored one: the
  // new data cannot see a change of the size the calibration resolves.
  double max_sigma_ratio = 5.0;
};

enum class VerdictKind { consistent, changed, cannot_tell };
std::string_view to_string(VerdictKind kind);

struct Verdict {
  std::string quantity;              // "T_cam_r_cam_l", "imu clock", "cam_r intrinsics"
  std::string step;                  // the step that estimates it
  std::vector<std::string> sensors;  // the sensors it involves
  VerdictKind kind = VerdictKind::consistent;
  std::string change;  // the difference in a person's units
  // The smallest change along one component this check would flag (at alarm_p, over the
  // quantity's components): sqrt(chi-square quantile) times the combined sigma.
  std::string detectable;
  double chi2 = 0, p_value = 1;
  int dof = 0;
  std::string reason;  // cannot tell: why, and what to record
};

// "This sensor moved, alone": the stored rig with that sensor (and what is attached to it) moved
// by the rotation and translation that best explain every judged relation of the re-estimate
// (least squares in their combined sigmas); what is left is its chi-square. The sensor that
// explains the changed poses best is the suspect.
struct Hypothesis {
  std::string sensor;
  double chi2 = 0, p_value = 1;  // over the judged relations' components
  int dof = 0;                   // those components less the 6 of the fitted move
};

// A residual level of the new data at the stored parameters (nothing re-estimated but the
// boards' poses), beside the stored calibration's own level and the re-estimate's on the new
// data: a lens bumped shows as reprojection errors above both. NaN where not available.
struct ResidualLevel {
  std::string step, what, unit;
  double at_stored = NAN, stored = NAN, reestimated = NAN;
};

struct CheckResult {
  std::filesystem::path calibration, session;  // what was checked against what
  double alarm_p = 1e-3;
  CalibrateResult estimate;  // the steps on the new session
  RigDifference difference;  // the stored calibration (A) against the re-estimate (B)
  std::vector<Verdict> verdicts;
  std::vector<ResidualLevel> residual_levels;
  // Where a relation changed: each sensor of the changed relations, moved alone, best first.
  std::vector<Hypothesis> hypotheses;
  // How much likelier the best hypothesis is than the next, exp((chi2_2 - chi2_1) / 2) (infinite
  // with one hypothesis): near 1 the data barely tell the two sensors apart (the stereo
  // extrinsic alone cannot say which camera turned).
  double likelihood_ratio = 0;
  // The sensors that changed: the best hypothesis's sensor for the poses, the sensors of changed
  // clocks and intrinsics.
  std::vector<std::string> suspects;
  // 0 nothing changed (quantities that cannot be told are listed), 3 something changed; 2 or 1
  // when the re-estimate's steps failed on bad input or an internal error.
  int exit_status = 0;
};

// `stored`: the calibration read from `stored_file` (which the re-estimate starts from). Throws
// rigcal::Error when the stored calibration has no step records with sigmas (nothing to compare
// against: `rigcal calibrate` writes them).
CheckResult check(const rig::Rig& stored, const std::filesystem::path& stored_file,
                  const CheckOptions& options, const Progress& progress = {});

// The verdicts as data (check.json), with the difference (diff_json) and the steps' statuses.
nlohmann::json check_json(const CheckResult& result);
// Lines for people: one a quantity, the suspects, the exit status's meaning.
std::vector<std::string> check_lines(const CheckResult& result);

// The report of a check in `dir`: check.json, diff.json, the projection maps, report.html.
std::vector<io::OutputFile> check_report_files(const CheckResult& result,
                                               const std::filesystem::path& dir);

}  // namespace rigcal::session
