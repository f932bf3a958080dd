#include "sketchnav/run/run_folder.h"

#include <sstream>

#include "sketchnav/nav/events.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::run {
namespace {

constexpr int kColumns = static_cast<int>(kTelemetryColumns.size());
static_assert(static_cast<int>(TelemetryColumn::FrontFreeM) == kColumns - 1,
              "every TelemetryColumn has a name in kTelemetryColumns");

// The cell of one column. The switch (no default) makes the compiler name a column added to
// the enum but not written here.
void writeCell(std::ostringstream& o, TelemetryColumn c, const nav::TelemetryRow& r,
               const hw::Pose2D* truth) {
  switch (c) {
    case TelemetryColumn::T:
      o << r.t;
      return;
    case TelemetryColumn::OdomX:
      o << r.odom.x;
      return;
    case TelemetryColumn::OdomY:
      o << r.odom.y;
      return;
    case TelemetryColumn::OdomTheta:
      o << r.odom.theta;
      return;
    case TelemetryColumn::TrueX:
      if (truth) o << truth->x;
      return;
    case TelemetryColumn::TrueY:
      if (truth) o << truth->y;
      return;
    case TelemetryColumn::TrueTheta:
      if (truth) o << truth->theta;
      return;
    case TelemetryColumn::VCmd:
      o << r.v_cmd;
      return;
    case TelemetryColumn::WCmd:
      o << r.w_cmd;
      return;
    case TelemetryColumn::ServoError:
      if (std::isfinite(r.servo_error)) o << r.servo_error;
      return;
    case TelemetryColumn::Mode:
      o << nav::toString(r.mode);
      return;
    case TelemetryColumn::Turn:
      o << servo::toString(r.turn);
      return;
    case TelemetryColumn::Section:
      o << r.section;
      return;
    case TelemetryColumn::Landmark:
      o << r.landmark;
      return;
    case TelemetryColumn::FrontFreeM:
      o << r.front_free_m;
      return;
  }
}

// The cells of a line; a trailing ',' ends with an empty cell.
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// NaN for an empty or unreadable cell (std::stod reads a leading number).
double number(const std::string& cell) {
  if (cell.empty()) return NAN;
  try {
    return std::stod(cell);
  } catch (...) {
    return NAN;
  }
}

// Sets one field of `r` from its cell; the truth's x, y, theta go to `truth` (NaN = empty)
// and become r.truth once the line is read.
void readCell(TelemetryRecord& r, hw::Pose2D& truth, TelemetryColumn c, const std::string& cell) {
  switch (c) {
    case TelemetryColumn::T:
      r.t = number(cell);
      return;
    case TelemetryColumn::OdomX:
      r.odom.x = number(cell);
      return;
    case TelemetryColumn::OdomY:
      r.odom.y = number(cell);
      return;
    case TelemetryColumn::OdomTheta:
      r.odom.theta = number(cell);
      return;
    case TelemetryColumn::TrueX:
      truth.x = number(cell);
      return;
    case TelemetryColumn::TrueY:
      truth.y = number(cell);
      return;
    case TelemetryColumn::TrueTheta:
      truth.theta = number(cell);
      return;
    case TelemetryColumn::VCmd:
      r.v_cmd = number(cell);
      return;
    case TelemetryColumn::WCmd:
      r.w_cmd = number(cell);
      return;
    case TelemetryColumn::ServoError:
      r.servo_error = number(cell);
      return;
    case TelemetryColumn::Mode:
      r.mode = cell;
      return;
    case TelemetryColumn::Turn:
      r.turn = cell;
      return;
    case TelemetryColumn::Section: {
      const double s = number(cell);
      if (std::isfinite(s)) r.section = static_cast<int>(s);
      return;
    }
    case TelemetryColumn::Landmark:
      r.landmark = cell;
      return;
    case TelemetryColumn::FrontFreeM:
      r.front_free_m = number(cell);
      return;
  }
}

}  // namespace

std::string telemetryCsvHeader() {
  std::string h;
  for (int i = 0; i < kColumns; ++i) h += (i ? "," : "") + std::string(kTelemetryColumns[i]);
  return h + "\n";
}

std::string telemetryCsvRow(const nav::TelemetryRow& row, const hw::Pose2D* truth) {
  std::ostringstream o;
  for (int i = 0; i < kColumns; ++i) {
    if (i) o << ',';
    writeCell(o, static_cast<TelemetryColumn>(i), row, truth);
  }
  o << '\n';
  return o.str();
}

bool TelemetryWriter::open(const std::string& path) {
  out_.open(path);
  if (!out_) return false;
  out_ << telemetryCsvHeader() << std::flush;
  return true;
}

void TelemetryWriter::write(const nav::TelemetryRow& row, const hw::Pose2D* truth) {
  if (out_.is_open()) out_ << telemetryCsvRow(row, truth) << std::flush;
}

std::vector<TelemetryRecord> readTelemetryCsv(const std::string& path) {
  std::vector<TelemetryRecord> out;
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return out;
  // The column of each cell of a line, or -1 for a column this reader does not know.
  std::vector<int> column_of;
  for (const auto& name : splitCsv(line)) {
    int c = -1;
    for (int i = 0; i < kColumns; ++i)
      if (name == kTelemetryColumns[i]) c = i;
    column_of.push_back(c);
  }
  while (std::getline(in, line)) {
    const auto cells = splitCsv(line);
    TelemetryRecord r;
    hw::Pose2D truth{NAN, NAN, NAN};
    for (size_t i = 0; i < cells.size() && i < column_of.size(); ++i)
      if (column_of[i] >= 0)
        readCell(r, truth, static_cast<TelemetryColumn>(column_of[i]), cells[i]);
    if (std::isfinite(truth.x) && std::isfinite(truth.y))
      r.truth = hw::Pose2D{truth.x, truth.y, std::isfinite(truth.theta) ? truth.theta : 0.0};
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace sketchnav::run
