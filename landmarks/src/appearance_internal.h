#pragma once
// Dense aligned appearance comparison of verified candidates (recognition's sibling check).
#include <opencv2/core.hpp>

#include <vector>

#include "sketchnav/landmarks/matcher.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::landmarks::detail {

constexpr int kAppearanceGrid = 32;  // [px] the compared region is resampled to this square
constexpr int kAppearanceCells = 4;  // cells per side; the score is the mean over cells

/// How well each verified match's database photo explains the frame's pixels: the photo's
/// thumbnail (DatabasePhoto::thumbnail) is warped into the frame's colour thumbnail with the
/// match's homography, and compared with the frame over one common region — the union of the
/// first `region_matches` matches' inlier hulls, where all of those warped photos are valid (and,
/// for a later match, where its own warped photo is) — resampled to kAppearanceGrid²:
/// the mean over kAppearanceCells² cells of the normalised cross-correlation of L*, a*, b*
/// (mean of the three). Normalised per cell, so the light's level and contrast, and slow changes
/// of it across the package, do not count; a photo that matches only part of the region (the
/// artwork sibling products share) scores low on the rest. In [-1, 1]; NaN for every match when
/// the region matches cannot be compared (a match without homography or thumbnail, a grey
/// frame, a common region of fewer than ~16 thumbnail pixels), NaN for a later match alone when
/// it cannot.
std::vector<double> appearanceSimilarities(const LandmarkModel& model, const FrameFeatures& frame,
                                           const std::vector<const MatchResult*>& matches,
                                           size_t region_matches);

}  // namespace sketchnav::landmarks::detail
