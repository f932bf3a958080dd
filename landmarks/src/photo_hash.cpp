#include "sketchnav/landmarks/photo_hash.h"

#include <opencv2/img_hash.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bitset>

#include "sketchnav/landmarks/colour_layout.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::landmarks {

std::uint64_t perceptualHash(const cv::Mat& image) {
  CV_Assert(!image.empty());
  // The same shrinking as the model's thumbnails (colourThumbnail), so a photo and its
  // thumbnail hash alike.
  const cv::Mat in = colourThumbnail(image, kPhotoThumbnailSide);
  cv::Mat h;
  cv::img_hash::PHash::create()->compute(in, h);  // 1 x 8 CV_8U
  std::uint64_t v = 0;
  for (int i = 0; i < h.cols; ++i) v = (v << 8) | h.at<std::uint8_t>(0, i);
  return v;
}

int hashDistance(std::uint64_t a, std::uint64_t b) {
  return static_cast<int>(std::bitset<64>(a ^ b).count());
}

std::vector<std::vector<TrainingPhotoHit>> findTrainingPhotos(const LandmarkModel& model,
                                                              const std::vector<cv::Mat>& images,
                                                              int max_bits) {
  std::vector<std::pair<std::uint64_t, const DatabasePhoto*>> photos;
  for (const auto& p : model.photos())
    if (!p.thumbnail.empty()) photos.push_back({perceptualHash(p.thumbnail), &p});
  std::vector<std::vector<TrainingPhotoHit>> out;
  for (const auto& image : images) {
    const std::uint64_t h = perceptualHash(image);
    std::vector<TrainingPhotoHit> hits;
    for (const auto& [ph, p] : photos)
      if (const int d = hashDistance(h, ph); d <= max_bits) hits.push_back({p->path, d});
    std::sort(hits.begin(), hits.end(),
              [](const auto& a, const auto& b) { return a.distance < b.distance; });
    out.push_back(std::move(hits));
  }
  return out;
}

std::vector<TrainingPhotoHit> findTrainingPhotos(const LandmarkModel& model, const cv::Mat& image,
                                                 int max_bits) {
  return findTrainingPhotos(model, std::vector<cv::Mat>{image}, max_bits).front();
}

}  // namespace sketchnav::landmarks
