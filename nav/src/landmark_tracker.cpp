#include "sketchnav/nav/landmark_tracker.h"

#include <algorithm>
#include <cmath>

#include "sketchnav/core/config.h"

namespace sketchnav::nav {

void LandmarkTrackerParams::validate() const {
  require(approach_m > 0 && approach_m <= max_approach_m, "nav.approach_m",
          "must be in (0, max_approach_m]");
  require(lost_after_s > 0, "nav.lost_after_s", "must be > 0");
  require(miss_slack_m >= 0, "nav.miss_slack_m", "must be >= 0");
  require(attend_bearing_deg > 0 && attend_bearing_deg <= 180, "nav.attend_bearing_deg",
          "must be in (0, 180]");
  require(attend_range_m > 0, "nav.attend_range_m", "must be > 0");
  require(max_missed_in_row >= 0, "nav.max_missed_in_row", "must be >= 0");
}

const char* toString(LandmarkState s) {
  switch (s) {
    case LandmarkState::Tracking:
      return "tracking";
    case LandmarkState::Passed:
      return "passed";
    case LandmarkState::Missed:
      return "missed";
    default:
      return "pending";
  }
}

LandmarkTracker::LandmarkTracker(const mapsketch::Route& route, LandmarkTrackerParams p)
    : route_(route), p_(p) {
  for (const auto& sec : route_.sections) tracks_.emplace_back(sec.landmarks.size());
}

const mapsketch::ExpectedLandmark& LandmarkTracker::landmark(int k, int i) const {
  return route_.sections[k].landmarks[i];
}

int LandmarkTracker::classCount(const std::string& cls) const {
  int n = 0;
  for (const auto& sec : route_.sections)
    for (const auto& l : sec.landmarks) n += l.class_name == cls;
  return n;
}

double LandmarkTracker::passDistance(int k, int i) const {
  const auto& sec = route_.sections[k];
  const auto& lm = sec.landmarks[i];
  double d = lm.range_m;
  if (lm.side == mapsketch::Side::Ahead && lm.along_m >= sec.length_m)
    d = (lm.position_m - sec.end_m).norm();
  return std::clamp(d, p_.approach_m, p_.max_approach_m);
}

bool LandmarkTracker::atLandmark(int k, int i, double range) const {
  return range > 0 && range <= passDistance(k, i) + 1.0;
}

LandmarkTracker::Miss LandmarkTracker::miss(int k, int i, bool counts) {
  auto& tr = tracks_[k][i];
  const auto& lm = landmark(k, i);
  tr.state = LandmarkState::Missed;
  if (counts) ++missed_in_row_;
  missed_ids_.push_back(lm.id);
  Miss m{event::LandmarkMissed{lm.id, lm.class_name, k, tr.frames_seen > 0}, std::nullopt};
  if (missed_in_row_ > p_.max_missed_in_row) {
    std::string ids;
    for (size_t j = missed_ids_.size() - missed_in_row_; j < missed_ids_.size(); ++j)
      ids += (ids.empty() ? "" : ", ") + missed_ids_[j];
    m.lost =
        "lost: " + std::to_string(missed_in_row_) + " landmarks in a row not found (" + ids + ")";
  }
  return m;
}

std::vector<LandmarkTracker::Miss> LandmarkTracker::pass(int k, int i) {
  tracks_[k][i].state = LandmarkState::Passed;
  // Passed out of order (the one after the attended landmark was seen first): every earlier
  // landmark still pending is behind the robot now.
  std::vector<Miss> out;
  for (int kk = 0; kk <= k; ++kk)
    for (int ii = 0; ii < (kk < k ? static_cast<int>(tracks_[kk].size()) : i); ++ii)
      if (tracks_[kk][ii].state == LandmarkState::Pending) {
        if (tracks_[kk][ii].frames_seen > 0)
          tracks_[kk][ii].state = LandmarkState::Passed;
        else
          out.push_back(miss(kk, ii, false));
      }
  missed_in_row_ = 0;
  return out;
}

bool LandmarkTracker::holdsSection(int k, double now, double within_s, int except_i) const {
  bool hold = false;
  for (size_t i = 0; i < tracks_[k].size(); ++i) {
    if (static_cast<int>(i) == except_i) continue;
    const auto& t = tracks_[k][i];
    hold |= t.state == LandmarkState::Tracking && now - t.last_seen <= within_s;
  }
  return hold;
}

std::vector<Expected> LandmarkTracker::expectations(const std::vector<AttendedLandmark>& att,
                                                    const hw::Pose2D& pose) const {
  std::vector<Expected> expect(att.size());
  for (size_t n = 0; n < att.size(); ++n) {
    const LandmarkTrack& t = tracks_[att[n].k][att[n].i];
    expect[n].class_name = landmark(att[n].k, att[n].i).class_name;
    expect[n].tracked = t.state == LandmarkState::Tracking;
    expect[n].where =
        expect[n].tracked
            ? expectedFromTrack(pose, t.last_origin, t.last_world_bearing, t.last_point_range)
            : att[n].pred;
    // A track followed by its bearing alone says nothing of the range: the sketch's
    // prediction still gates a measured one (else the first laser return along the bearing,
    // an obstacle in front, would be taken for the landmark).
    if (expect[n].tracked && expect[n].where.range <= 0) expect[n].where.range = att[n].pred.range;
  }
  return expect;
}

std::optional<LandmarkTracker::Association> LandmarkTracker::associate(
    const std::vector<AttendedLandmark>& att, size_t n, const std::vector<Expected>& expect,
    const std::vector<Candidate>& all, std::vector<bool>& used, const RouteAnchor& anchor,
    const SelectParams& select, const hw::Pose2D& pose, double now, double camera_x_m,
    bool far_bearings) {
  const AttendedLandmark& x = att[n];
  const auto& lm = landmark(x.k, x.i);
  // A detection already given to the landmark before (same class) is not this one, nor is a
  // tracked landmark's.
  std::vector<Candidate> cands;
  std::vector<size_t> idx;
  for (size_t c = 0; c < all.size(); ++c)
    if (!used[c] &&
        !anchor.atEarlierFix(lm.class_name, {pose.x, pose.y},
                             pose.theta + all[c].detection->bearing, all[c].range_m, fixRange()) &&
        !claimedByTracked(all[c], n, expect))
      cands.push_back(all[c]), idx.push_back(c);
  SelectParams sp = select;
  if (sp.unique_class_bearing_only && classCount(lm.class_name) == 1)
    sp.bearing_only_gate_deg = sp.bearing_gate_deg;
  const int ci =
      selectCandidate(cands, lm.class_name, expect[n].where.bearing, expect[n].where.range, sp);
  if (ci < 0) return std::nullopt;
  used[idx[ci]] = true;
  const auto& d = *cands[ci].detection;
  // Taken for its bearing alone when its measured range is another object's.
  const bool range_dropped = !rangeAgrees(cands[ci].range_m, expect[n].where.range, sp);
  const double range = range_dropped ? 0.0 : cands[ci].range_m;
  Association a;
  a.detection = &d;
  a.range_m = range;
  LandmarkTrack& t = tracks_[x.k][x.i];
  if (t.state != LandmarkState::Tracking)
    a.seen = event::LandmarkSeen{lm.id,
                                 lm.class_name,
                                 x.k,
                                 d.inliers,
                                 d.bearing * 180 / M_PI,
                                 range,
                                 x.pred.bearing * 180 / M_PI,
                                 x.pred.range,
                                 range_dropped,
                                 cands.size(),
                                 n == 0};
  t.state = LandmarkState::Tracking;
  ++t.frames_seen;
  t.max_inliers = std::max(t.max_inliers, d.inliers);
  t.last_seen = now;
  t.last_range = range;
  t.last_bearing = d.bearing;
  t.last_origin = {pose.x, pose.y};
  t.last_world_bearing = pose.theta + d.bearing;
  t.last_point_range = range;
  // Far ranges may be something else along the bearing; the bearing still helps.
  const bool far = range > fixRange();
  // Fixes rest on verified geometry: the bearings of recognised-only detections are noisier
  // by a few degrees, which a triangulation from nearly parallel rays turns into metres; they
  // still steer the servo and keep the track.
  if (!d.recognised_only && (!far || far_bearings)) {
    if (t.sightings.size() >= 80) t.sightings.erase(t.sightings.begin());
    Sighting sg{{pose.x, pose.y}, pose.theta + d.bearing, far ? 0.0 : range, far ? range : 0.0};
    sg.elevation = d.elevation;
    sg.camera_along_m = camera_x_m * std::cos(d.bearing);
    sg.photo = d.photo;
    if (range_dropped && cands[ci].range_m <= fixRange()) sg.gated_range_m = cands[ci].range_m;
    t.sightings.push_back(sg);
  }
  return a;
}

LandmarkTracker::Unseen LandmarkTracker::checkUnseen(int k, int i, double now) {
  LandmarkTrack& t = tracks_[k][i];
  if (t.state != LandmarkState::Tracking || now - t.last_seen <= p_.lost_after_s) return Unseen::No;
  // Out of view when already close (it slid out of the side of the image): passed.
  if (atLandmark(k, i, t.last_range)) return Unseen::AtIt;
  t.state = LandmarkState::Pending;
  return Unseen::LostToView;
}

std::optional<std::pair<int, int>> LandmarkTracker::finalLookCandidate(const SectionTracker& route,
                                                                       const hw::Pose2D& pose,
                                                                       double range_m,
                                                                       double& at_range_m) const {
  std::optional<std::pair<int, int>> out;
  double best = range_m;
  for (int kl = 0; kl < static_cast<int>(tracks_.size()); ++kl)
    for (size_t i = 0; i < tracks_[kl].size(); ++i) {
      const auto& t = tracks_[kl][i];
      if (t.frames_seen > 0 ||
          (t.state != LandmarkState::Pending && t.state != LandmarkState::Missed))
        continue;
      const double r =
          polarFrom(pose, route.toOdom(landmark(kl, static_cast<int>(i)).position_m)).range;
      if (r <= best) best = r, out = std::make_pair(kl, static_cast<int>(i));
    }
  at_range_m = best;
  return out;
}

}  // namespace sketchnav::nav
