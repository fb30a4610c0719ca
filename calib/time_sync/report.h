#pragma once
// The time-offset report (doc/time-offset.md): time_sync.json and quick-look PNGs of the
// correlation around the peak, the aligned signals and the windowed offsets.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rigcal/io/files.h"
#include "rigcal/time_sync/time_sync.h"

namespace rigcal::time_sync {

struct TimeSyncInputs {
  std::string reference, other;                // paths as given
  std::string reference_format, other_format;  // as read
  std::string sensor, reference_sensor;        // rig sensors, where given
  double reference_time_offset_s = 0.0;        // the reference sensor's time_offset in the rig
  std::vector<std::string> notes;              // what the readers assumed or did
};

nlohmann::json time_sync_json(const TimeSyncResult& result, const TimeSyncOptions& options,
                              const TimeSyncInputs& inputs);

// time_sync.json, correlation.png, aligned.png and (when windows were estimated) windows.png.
std::vector<io::OutputFile> time_sync_report_files(
    const std::filesystem::path& dir, const TimeSyncResult& result, const TimeSyncOptions& options,
    const TimeSyncInputs& inputs, const AngularRates& reference, const AngularRates& other);

}  // namespace rigcal::time_sync
