#pragma once
// Perceptual hashes of images against a landmark model's database photos: does an image (a
// simulator texture, a test photo) show one of the photos the model was trained on? A run that
// renders a training photo tests the model on its own training data, so the simulator warns.
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace sketchnav::landmarks {

class LandmarkModel;

/// 64-bit DCT perceptual hash (OpenCV img_hash::PHash) of a BGR or grey image, computed on the
/// image first shrunk to the model thumbnails' size (kPhotoThumbnailSide, INTER_AREA), so an
/// image and the thumbnail of the same photo go through the same steps.
std::uint64_t perceptualHash(const cv::Mat& image);

/// Bits in which two hashes differ (0-64).
int hashDistance(std::uint64_t a, std::uint64_t b);

/// [bits] default Hamming radius for "near-duplicate": copies that are re-encoded, resized or
/// brightened lie within it, and crops of up to ~2 % per side; distinct photos (even of the same
/// product) almost all lie beyond it (distances measured on the grocery photos in
/// doc/simulator.md).
constexpr int kNearDuplicateBits = 10;

struct TrainingPhotoHit {
  std::string photo;  // the database photo's path, relative to the landmark set root
  int distance = 0;   // [bits]
};

/// The model's database photos within `max_bits` of `image`'s perceptual hash, nearest first.
std::vector<TrainingPhotoHit> findTrainingPhotos(const LandmarkModel& model, const cv::Mat& image,
                                                 int max_bits = kNearDuplicateBits);
/// The same for several images (the model's photos hashed once): one list per image.
std::vector<std::vector<TrainingPhotoHit>> findTrainingPhotos(const LandmarkModel& model,
                                                              const std::vector<cv::Mat>& images,
                                                              int max_bits = kNearDuplicateBits);

}  // namespace sketchnav::landmarks
