// rigcal check (calib/session/check.h) on simulated sessions, the short version of the long
// test's acceptance: an unchanged rig is consistent, a camera turned by 0.2 deg is flagged on
// that camera alone; a calibration without step records is refused.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "browser.h"
#include "check_sim.h"

namespace rigcal {
namespace {

TEST(CheckSim, AnUnchangedRigIsConsistentAndATurnedCameraIsFlaggedOnItself) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigcal_check_{}", ::getpid());
  fs::remove_all(dir);
  // Images integrated on 3 x 3 samples a pixel (the simulator's default is 5 x 5): the check's
  // verdicts, not the corners' last hundredth of a pixel, are what this test judges.
  const std::string config =
      "stereo:\n  views: 20\nlidar_camera:\n  pairs: 8\nimage:\n  supersample: 3\n";
  const std::vector<testing::RigChange> changes = testing::acceptance_changes();
  const testing::CheckOutcome same = testing::simulated_check(dir, 1, changes[0], config);
  ASSERT_EQ(same.status, 0) << same.out << same.err;
  ASSERT_EQ(same.report["verdicts"].size(), 7u) << same.report.dump(1);
  for (const nlohmann::json& v : same.report["verdicts"])
    EXPECT_EQ(v["verdict"], "consistent") << v;
  EXPECT_NE(same.out.find("Verdict: consistent"), std::string::npos) << same.out;
  // The new data at the stored calibration: the lenses' reprojection and the boards' fit as
  // good as the re-estimate's on the same data, give or take the stored parameters' own error.
  auto level = [](const testing::CheckOutcome& o, const std::string& what) {
    for (const nlohmann::json& l : o.report["residual_levels"])
      if (l["what"].get<std::string>().rfind(what, 0) == 0) return l;
    ADD_FAILURE() << "no residual level " << what << " in " << o.report["residual_levels"];
    return nlohmann::json();
  };
  const nlohmann::json same_rms = level(same, "corner reprojection RMS"),
                       same_boards = level(same, "boards' noise scale");
  ASSERT_TRUE(same_rms.is_object() && same_boards.is_object());
  EXPECT_LT(same_rms["at_stored"].get<double>(), 1.5 * same_rms["reestimated"].get<double>());
  EXPECT_GT(same_rms["stored"].get<double>(), 0.0);
  EXPECT_LT(same_boards["at_stored"].get<double>(), 2.0);
  // The new motion at the stored T_gnss_lidar and clock: as close as the re-estimate's.
  const nlohmann::json same_motion = level(same, "motion pairs' median rotation");
  ASSERT_TRUE(same_motion.is_object());
  EXPECT_LT(same_motion["at_stored"].get<double>(), 1.5 * same_motion["reestimated"].get<double>());
  std::printf(
      "[ figures ] unchanged, the new motion pairs' median rotation residual %.4f deg at the "
      "stored calibration, %.4f re-estimated (the calibration's own %.4f)\n",
      same_motion["at_stored"].get<double>(), same_motion["reestimated"].get<double>(),
      same_motion["stored"].is_number() ? same_motion["stored"].get<double>() : NAN);

  ASSERT_EQ(changes[1].sensor, "cam_r");
  const testing::CheckOutcome turned = testing::simulated_check(dir, 1, changes[1], config);
  EXPECT_EQ(turned.status, 3) << turned.out << turned.err;
  EXPECT_TRUE(testing::flagged_on(turned, "cam_r")) << turned.out;
  EXPECT_EQ(turned.report["suspects"], nlohmann::json::array({"cam_r"})) << turned.out;
  // Named with how much likelier than cam_l it is (only T_cam_r_lidar tells the two apart).
  EXPECT_GT(turned.report["likelihood_ratio"].get<double>(), 1.0);
  EXPECT_NE(turned.out.find("cam_r moving alone is"), std::string::npos) << turned.out;
  EXPECT_NE(turned.out.find("Changed: cam_r"), std::string::npos) << turned.out;
  // At the stored calibration the turned camera's corners miss by a large part of a pixel. Its
  // boards' planes miss the LiDAR's by the 0.2 deg too, but each pair's normal is only good to
  // a few tenths of a degree: their noise scale barely moves (1.06 against 0.86 unchanged,
  // seed 1); the re-estimate's comparison, with 8 pairs' sigma, is what sees it.
  const nlohmann::json turned_rms = level(turned, "corner reprojection RMS"),
                       turned_boards = level(turned, "boards' noise scale");
  ASSERT_TRUE(turned_rms.is_object() && turned_boards.is_object());
  EXPECT_GT(turned_rms["at_stored"].get<double>(), 3 * turned_rms["reestimated"].get<double>());
  EXPECT_GT(turned_boards["at_stored"].get<double>(), 0.0);
  std::printf(
      "[ figures ] at the stored calibration: reprojection RMS %.3f px unchanged, %.3f px cam_r "
      "turned (re-estimated %.3f, %.3f); boards' noise scale %.2f, %.2f\n",
      same_rms["at_stored"].get<double>(), turned_rms["at_stored"].get<double>(),
      same_rms["reestimated"].get<double>(), turned_rms["reestimated"].get<double>(),
      same_boards["at_stored"].get<double>(), turned_boards["at_stored"].get<double>());
  EXPECT_NE(turned.out.find("The new data at the stored calibration"), std::string::npos);
  // The difference's figures travel with the verdicts; the page a person reads holds each
  // quantity and names the sensor, and renders again from check.json the same.
  EXPECT_TRUE(fs::exists(dir / "next/check/diff.json"));
  const std::string page = testing::slurp(dir / "next/check/report.html");
  EXPECT_NE(page.find("Something changed: cam_r"), std::string::npos);
  for (const nlohmann::json& v : turned.report["verdicts"])
    EXPECT_NE(page.find(v["quantity"].get<std::string>()), std::string::npos) << v;
  EXPECT_NE(page.find("Which sensor moved"), std::string::npos);
  const testing::CliRun again =
      testing::rigcal_cli(fmt::format("report {}/next/check", dir.string()), dir);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(testing::slurp(dir / "next/check/report.html"), page);
  if (testing::have_chromium()) {
    const testing::BrowserLoad load =
        testing::load_in_browser(dir / "next/check/report.html", dir / "check.png");
    EXPECT_TRUE(load.ran) << load.log;
    EXPECT_EQ(testing::console_messages(load.log), "");
    for (const char* id :
         {"id=\"verdicts\"", "id=\"levels\"", "id=\"which\"", "id=\"steps\"", "id=\"poses\""})
      EXPECT_NE(load.dom.find(id), std::string::npos) << id;
    EXPECT_GT(load.screenshot_bytes, 20000u);
  }
  for (const nlohmann::json& h : turned.report["hypotheses"]) {
    std::printf("[ figures ] cam_r turned 0.2 deg, %s moved alone: chi-square %.1f over %d\n",
                h["sensor"].get<std::string>().c_str(), h["chi2"].get<double>(),
                h["dof"].get<int>());
  }

  // A calibration without step records (the bundled sample): nothing to compare, exit 2.
  const testing::CliRun bare =
      testing::rigcal_cli(fmt::format("check --rig {}/data/sample_rig.yaml --session {}/next/rec",
                                      RIGCAL_SOURCE_DIR, dir.string()),
                          dir);
  EXPECT_EQ(bare.status, 2);
  EXPECT_NE(bare.err.find("no step records with sigmas"), std::string::npos) << bare.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rigcal
