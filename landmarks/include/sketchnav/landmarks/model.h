#pragma once
// The landmark model (.slm): vocabulary, BoW classifier, colour-layout classifier and, per class,
// the keypoints, descriptors and keypoint colours of its database photos for matching. Built by
// trainModel() from a landmark set folder; saved as a versioned binary file (magic, format version,
// payload size, FNV-1a checksum) so a truncated file or a file of another version is refused with a
// clear error.
#include <opencv2/core.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/landmarks/bow.h"
#include "sketchnav/landmarks/rootsift.h"
#include "sketchnav/landmarks/vocabulary.h"

namespace sketchnav::landmarks {

/// Training settings ("landmarks.train.*").
struct ModelParams {
  FeatureParams features;  // database photos
  // Camera frames / query images (computeFrameFeatures(model, image)): fewer keypoints than the
  // database photos, because SIFT and the per-keypoint searches are the per-frame cost while
  // database keypoints are paid once, at training time.
  int frame_max_features = 500;    // keypoints kept per frame (strongest); 0 = all
  int frame_max_image_side = 400;  // [px] longer frame side above this is downscaled for SIFT
  // View synthesis (ASIFT-like): besides the photo itself, SIFT on `synth_views` affine-tilted
  // copies (compressed by synth_tilt along x, then along y, ...), keypoints mapped back to the
  // photo's pixels, up to features.max_features per view. More database keypoints for oblique
  // views of the package; 0 = off.
  int synth_views = 0;
  double synth_tilt = 2.0;
  int vocabulary_size = 1000;  // visual words; capped at training descriptors / 10
  int kmeans_sample = 60000;   // descriptors sampled for k-means
  int kmeans_iterations = 8;
  double svm_c = 1.0;  // linear SVM soft-margin constant
  int seed = 1;        // descriptor sampling, k-means seeding, CV folds

  template <class B>
  void bind(B& b) {
    b("max_features", features.max_features);
    b("max_image_side", features.max_image_side);
    b("contrast_threshold", features.contrast_threshold);
    b("root_sift", features.root_sift);
    b("frame_max_features", frame_max_features);
    b("frame_max_image_side", frame_max_image_side);
    b("synth_views", synth_views);
    b("synth_tilt", synth_tilt);
    b("vocabulary_size", vocabulary_size);
    b("kmeans_sample", kmeans_sample);
    b("kmeans_iterations", kmeans_iterations);
    b("svm_c", svm_c);
    b("seed", seed);
  }
  void validate() const;
  /// The feature settings for frames: `features` with the frame_* limits.
  FeatureParams frameFeatures() const {
    FeatureParams f = features;
    f.max_features = frame_max_features;
    f.max_image_side = frame_max_image_side;
    return f;
  }
};

/// One database photo: its features for matching and its BoW histogram for the shortlist.
struct DatabasePhoto {
  int class_id = -1;
  std::string path;  // relative to the landmark set root
  cv::Size size;     // photo size in pixels (keypoints are in these pixels)
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat sift_u8;      // N x 128 CV_8U raw SIFT (stored form)
  cv::Mat colours;      // N x 3 CV_8U colour around each keypoint (keypointColours())
  cv::Mat descriptors;  // N x 128 CV_32F working descriptors (RootSIFT or SIFT), built on load
  std::vector<int> words;
  cv::Mat histogram;  // 1 x K BoW histogram, built on load
  // The photo shrunk (INTER_AREA) to at most kPhotoThumbnailSide px on its longer side, BGR
  // CV_8UC3 (format 5): recognise() warps it into the frame to compare sibling candidates'
  // appearance densely (RecognitionParams::sibling_check). 12 KB per photo (64 px: the same val
  // result as 96 px in the prototype, /work/notes/s7).
  cv::Mat thumbnail;
};

/// [px] longer side of DatabasePhoto::thumbnail.
constexpr int kPhotoThumbnailSide = 64;

class LandmarkModel {
 public:
  // 5: a colour thumbnail per photo (DatabasePhoto::thumbnail). 4: the colour-layout
  // classifier (colourClassifier()). 3: keypoint colours (opponent
  // chromaticity) and frame_* params; 2 was a development format with another colour
  // definition. Older files are refused so no model without these parts is used by mistake.
  static constexpr std::uint32_t kFormatVersion = 5;

  LandmarkModel();
  ~LandmarkModel();
  LandmarkModel(LandmarkModel&&) noexcept;
  LandmarkModel& operator=(LandmarkModel&&) noexcept;

  const std::vector<std::string>& classes() const { return classes_; }
  int classId(const std::string& name) const;  // -1 when unknown
  const ModelParams& params() const { return params_; }
  const Vocabulary& vocabulary() const { return vocabulary_; }
  const LinearClassifier& classifier() const { return classifier_; }
  /// One-vs-rest linear classifier over the colour-layout descriptor (colour_layout.h) of each
  /// database photo's keypoint region, Platt-calibrated like classifier().
  const LinearClassifier& colourClassifier() const { return colour_classifier_; }
  const std::vector<DatabasePhoto>& photos() const { return photos_; }
  /// Indices into photos() of one class's database photos.
  const std::vector<int>& photosOfClass(int class_id) const { return by_class_[class_id]; }
  /// Fingerprint of the landmark set it was trained from (paths + sizes), for caches.
  const std::string& sourceFingerprint() const { return fingerprint_; }

  /// Exact kNN (k = 2, squared L2) of `query` descriptors in one database photo; a photo with
  /// one descriptor gives index -1 / FLT_MAX in the second column. Thread-safe.
  void knn2(int photo, const cv::Mat& query, cv::Mat& indices, cv::Mat& dists) const;
  /// kNN of `query` among the descriptors of all database photos (one FLANN kd-tree forest,
  /// built lazily on first use and cached; thread-safe). Result indices are global rows;
  /// globalOwner() maps them to (photo, keypoint).
  void knnAll(const cv::Mat& query, int k, int checks, cv::Mat& indices, cv::Mat& dists) const;
  std::pair<int, int> globalOwner(int row) const;
  /// Per database photo (indexed like photos(); 0 outside the class): how many `query` rows
  /// have their nearest descriptor among the class's photos in that photo (one approximate
  /// search in a per-class kd-tree, built lazily and cached; thread-safe). Orders a class's
  /// photos for matching: a camera frame's BoW histogram is mostly background.
  std::vector<int> classPhotoVotes(int class_id, const cv::Mat& query, int checks) const;
  /// The same search: per query row, the photo (index into photos()) holding its nearest
  /// descriptor among the class's photos, -1 when none.
  std::vector<int> classNearestPhoto(int class_id, const cv::Mat& query, int checks) const;
  /// Builds the database-wide and per-class search indexes now instead of on first use (seconds for
  /// 864 photos, a fraction of a second for 72), so the first camera frame is not slow. Idempotent;
  /// thread-safe.
  void buildIndexes() const;

  /// Writes the .slm file; throws RuntimeError when it cannot be written.
  void save(const std::string& path) const;
  /// Reads a .slm file; throws InputError naming the file when it is missing, not a model,
  /// of another format version, truncated or corrupt.
  static LandmarkModel load(const std::string& path);

 private:
  friend LandmarkModel trainModel(const std::string&, const ModelParams&,
                                  const std::function<void(const std::string&, int, int)>&,
                                  const std::vector<std::string>&);
  void finalise();  // builds working descriptors, histograms, per-class lists
  ModelParams params_;
  std::vector<std::string> classes_;
  Vocabulary vocabulary_;
  LinearClassifier classifier_;
  LinearClassifier colour_classifier_;
  std::vector<DatabasePhoto> photos_;
  std::vector<std::vector<int>> by_class_;
  std::string fingerprint_;
  struct Cache;
  std::unique_ptr<Cache> cache_;
};

/// Progress callback: (stage, done, total), e.g. ("features", 12, 72).
using TrainProgress = std::function<void(const std::string& stage, int done, int total)>;

/// Builds a model from a landmark set folder (landmark_set.h). Unreadable / corrupt photos
/// are skipped with a warning; classes left without photos are dropped with a warning.
/// Classes named in `exclude` are left out (used to measure rejection of unknown objects).
/// Throws InputError naming the folder when no class with a readable photo remains.
LandmarkModel trainModel(const std::string& landmark_dir, const ModelParams& params,
                         const TrainProgress& progress = {},
                         const std::vector<std::string>& exclude = {});

/// Fingerprint of a landmark set folder as stored in models trained from it.
std::string landmarkSetFingerprint(const std::string& landmark_dir);

/// For `sketchnav run`: loads `cache_file` when it exists, is readable and was trained from
/// the current content of `landmark_dir` with `params`; otherwise trains and writes it.
LandmarkModel loadOrTrainModel(const std::string& landmark_dir, const std::string& cache_file,
                               const ModelParams& params, const TrainProgress& progress = {});

}  // namespace sketchnav::landmarks
