#pragma once
// Global colour-layout descriptor of an image region: what SIFT does not see. Sibling products
// (the Arla milks, the Bravo juices) print the same artwork on differently coloured cartons, so
// their keypoints vote and verify alike; the carton's colours and where they are tell them
// apart. Used as one more piece of evidence in recognise() (recognition.h), through a linear
// one-vs-rest classifier over it stored in the model (LandmarkModel::colourClassifier()).
//
// Descriptor: HSV histogram, 16 hue × 4 saturation bins (value ignored), of the whole region
// and of each cell of a 2×2 grid over it (5 × 64 = 320 values); each of the five histograms is
// normalised to sum 1 and square-rooted (the Hellinger map, as RootSIFT: unit L2 per part), and
// the whole is scaled by 1/√5, so the descriptor has unit L2 norm. The region is first resized
// to kColourLayoutSide² pixels so its size does not matter. Hue and saturation do not change
// when the light is scaled (R, G, B multiplied by one factor; up to 8-bit rounding and
// clipping), so neither does the descriptor. Value was left out because it does not help:
// a linear SVM over train/ scores 0.46–0.49 top-1 on grocery val without it, 0.37–0.44 with
// 4 value bins (Python prototype, 32–192 px squares).
//
// Region: the bounding box of the window's keypoints (robust: the kColourLayoutTrim fraction of
// keypoints is left out on each side), for database photos and query windows alike, so both
// are described over "the textured part of the image" — on a database photo or a val photo
// nearly the whole photo, on a photo letterboxed into a camera frame the photo without the
// border, on a window or a fovea crop its textured part. Why not the candidate's verified
// homography region: the colour evidence matters most where verification failed (the false
// rejections have 0–10 inliers, no usable homography), and a per-candidate region would make
// the class scores incomparable (each computed on other pixels). Why not the box of the
// keypoints that voted for a candidate: sibling classes get few, scattered voters (the votes
// pass a ratio test between classes), and database photos have no votes to train on the same
// region. In a camera frame where the landmark is small, the whole frame's keypoint box is
// mostly background: the colour evidence is then as weak as the BoW histogram's, and the
// objectness windows or the fovea crop (nav) are what localise the landmark. Measured with
// the colour rescue (recognition.h): photos letterboxed into 640×480 frames gain as much as
// the photos themselves (top-1 0.58 -> 0.66 vs 0.65 -> 0.72), 10 objectness windows 0.65 ->
// 0.75.
//
// Cost: ~0.23 ms per 640×480 frame for the thumbnail (in computeFrameFeatures), ~0.02 ms per
// window for region, descriptor and classifier (one OpenCV thread).
#include <opencv2/core.hpp>

#include <vector>

namespace sketchnav::landmarks {

constexpr int kColourLayoutHueBins = 16, kColourLayoutSatBins = 4, kColourLayoutValBins = 1;
constexpr int kColourLayoutBins =
    kColourLayoutHueBins * kColourLayoutSatBins * kColourLayoutValBins;
constexpr int kColourLayoutDims = 5 * kColourLayoutBins;  // whole region + 2x2 grid
constexpr int kColourLayoutSide = 64;       // [px] the region is resized to this square
constexpr int kColourThumbnailSide = 160;   // [px] longer side of the stored frame thumbnail
constexpr double kColourLayoutTrim = 0.02;  // keypoints left out per side of the region box

/// The image shrunk (INTER_AREA) so its longer side is at most `max_side`, BGR CV_8UC3 (grey
/// and BGRA inputs converted); empty for an empty image. Kept per frame in FrameFeatures so
/// recognise() can describe any window's colours without the frame (and, at
/// kPhotoThumbnailSide, per database photo for the sibling check).
cv::Mat colourThumbnail(const cv::Mat& image, int max_side = kColourThumbnailSide);

/// The region box of `keypoints` (image pixels): the bounding box after trimming
/// kColourLayoutTrim of the points on each side of each axis, clipped to the image. With fewer
/// than 8 keypoints, `fallback` (clipped to the image; empty = the whole image).
cv::Rect colourRegion(const std::vector<cv::Point2f>& keypoints, cv::Size image_size,
                      const cv::Rect& fallback = {});

/// Descriptor (1 x kColourLayoutDims CV_32F, unit L2 norm) of `region` (pixels of the original
/// image, of size `image_size`) read from its thumbnail (colourThumbnail()). An empty or
/// degenerate region -> the whole image. An empty thumbnail -> an all-zero row (no colour).
cv::Mat colourLayoutDescriptor(const cv::Mat& thumbnail, cv::Size image_size, cv::Rect region);

}  // namespace sketchnav::landmarks
