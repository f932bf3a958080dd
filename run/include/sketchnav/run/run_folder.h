#pragma once
// The run folder `sketchnav run --out DIR` writes (run.h runNavigation), and reading it back:
//   summary.json    the run's summary (what runNavigation returns), written whole or not at all
//   events.jsonl    one executive event per line (nav::NavEvent::toJson)
//   telemetry.csv   one row per control tick, the columns of kTelemetryColumns
//   trajectory.png  the map with the sketched path and the trajectory
// telemetry.csv's columns are listed once, here, for its writer and its reader: a column added
// to the list is written and read, and the reader finds columns by name, so a file written
// before a column was added still reads (the missing column's fields stay unset).
#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "sketchnav/hw/types.h"
#include "sketchnav/nav/executive.h"

namespace sketchnav::run {

/// telemetry.csv's columns, in file order (kTelemetryColumns names them).
enum class TelemetryColumn {
  T,           // [s] the run's clock since the executive started
  OdomX,       // [m] odometry frame: origin at the start pose, x along the initial heading
  OdomY,       // [m]
  OdomTheta,   // [rad]
  TrueX,       // [m] the simulator's ground truth, world frame; empty without a simulator
  TrueY,       // [m]
  TrueTheta,   // [rad]
  VCmd,        // [m/s] commanded
  WCmd,        // [rad/s] commanded
  ServoError,  // x_t - x_d when servoing; empty otherwise
  Mode,        // nav::toString(Mode)
  Turn,        // servo::toString(Turn)
  Section,     // 0-based section index
  Landmark,    // id of the attended landmark; empty when none
  FrontFreeM,  // [m] free corridor ahead (0 when the avoider did not run)
};
inline constexpr std::array<const char*, 15> kTelemetryColumns = {
    "t",     "odom_x",      "odom_y", "odom_theta", "true_x",  "true_y",   "true_theta",  "v_cmd",
    "w_cmd", "servo_error", "mode",   "turn",       "section", "landmark", "front_free_m"};

/// telemetry.csv's first line: the column names joined by ',' and a newline.
std::string telemetryCsvHeader();

/// One control tick as a telemetry.csv line (with its newline). `truth`: the simulator's pose
/// at this tick, or null (its columns left empty). Numbers as std::ostream writes them by
/// default (6 significant digits).
std::string telemetryCsvRow(const nav::TelemetryRow& row, const hw::Pose2D* truth);

/// Writes telemetry.csv. The header is flushed at open and every row is written whole and
/// flushed (one write()): a run killed at any moment leaves the file readable to its last whole
/// row. Not copyable; the file closes with the writer.
class TelemetryWriter {
 public:
  TelemetryWriter() = default;
  TelemetryWriter(const TelemetryWriter&) = delete;
  TelemetryWriter& operator=(const TelemetryWriter&) = delete;
  /// Creates (or truncates) `path` and writes the header; false when the file cannot be
  /// written.
  bool open(const std::string& path);
  bool isOpen() const { return out_.is_open(); }
  /// Appends one row (telemetryCsvRow); a no-op before a successful open().
  void write(const nav::TelemetryRow& row, const hw::Pose2D* truth);

 private:
  std::ofstream out_;
};

/// One telemetry.csv row, typed. A field whose cell is empty, unreadable or whose column is
/// absent stays as initialised here (NaN, "", -1, none).
struct TelemetryRecord {
  double t = NAN;                   // [s]
  hw::Pose2D odom{NAN, NAN, NAN};   // [m, m, rad] odometry frame
  std::optional<hw::Pose2D> truth;  // [m, m, rad] world frame; set when true_x and true_y are
                                    // (true_theta empty reads as 0)
  double v_cmd = NAN;               // [m/s]
  double w_cmd = NAN;               // [rad/s]
  double servo_error = NAN;         // NaN when not servoing
  std::string mode, turn;
  int section = -1;
  std::string landmark;
  double front_free_m = NAN;  // [m]
};

/// Reads a telemetry.csv: one record per line after the header, columns found by their names
/// in the header (unknown ones ignored). A missing or empty file reads as no records (a run
/// that crashed before its first tick); a truncated last line reads as far as it goes.
std::vector<TelemetryRecord> readTelemetryCsv(const std::string& path);

}  // namespace sketchnav::run
