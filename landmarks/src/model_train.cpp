// Training a landmark model from a folder of class folders.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>

#include "sketchnav/core/error.h"
#include "sketchnav/core/hash.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/landmarks/colour_layout.h"
#include "sketchnav/landmarks/landmark_set.h"
#include "sketchnav/landmarks/model.h"

namespace fs = std::filesystem;

namespace sketchnav::landmarks {

void ModelParams::validate() const {
  features.validate();
  require(vocabulary_size >= 2, "train.vocabulary_size", "must be >= 2");
  require(kmeans_sample >= 100, "train.kmeans_sample", "must be >= 100");
  require(kmeans_iterations >= 1, "train.kmeans_iterations", "must be >= 1");
  require(svm_c > 0, "train.svm_c", "must be > 0");
  require(frame_max_features >= 0, "train.frame_max_features", "must be >= 0");
  require(frame_max_image_side >= 64, "train.frame_max_image_side", "must be >= 64 px");
  require(seed >= 0, "train.seed", "must be >= 0");
  require(synth_views >= 0 && synth_views <= 4, "train.synth_views", "must be in [0, 4]");
  require(synth_tilt > 1 && synth_tilt <= 4, "train.synth_tilt", "must be in (1, 4]");
}

std::string landmarkSetFingerprint(const std::string& landmark_dir) {
  const LandmarkSet set = scanLandmarkSet(landmark_dir);
  std::string text;
  std::error_code ec;
  for (const auto& c : set.classes)
    for (const auto& p : c.photos)
      text += c.name + "|" + fs::relative(p, set.root).string() + "|" +
              std::to_string(fs::file_size(p, ec)) + "\n";
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx",
                static_cast<unsigned long long>(fnv1a(text.data(), text.size())));
  return buf;
}

namespace {

// ASIFT-like view synthesis: the photo seen obliquely, as an affine tilt (anti-aliased
// compression along one axis); the views' keypoints are mapped back into the photo's pixels so
// they verify against frames like the photo's own.
void addSynthesisedViews(const cv::Mat& img, const ModelParams& p, std::vector<cv::KeyPoint>& kps,
                         cv::Mat& sift_u8) {
  const double t = p.synth_tilt;
  const double sigma = 0.8 * std::sqrt(t * t - 1);  // Morel & Yu's anti-aliasing for a tilt t
  for (int v = 0; v < p.synth_views; ++v) {
    // Views 0, 1: compressed along x, along y; 2, 3: the same along the diagonals.
    const double a = (v % 2 == 0 ? 0.0 : 90.0) + (v >= 2 ? 45.0 : 0.0);
    const cv::Point2f c(0.5f * img.cols, 0.5f * img.rows);
    cv::Mat R = cv::getRotationMatrix2D(c, a, 1.0);  // rotate, compress x, rotate back
    cv::Mat rot;
    cv::warpAffine(img, rot, R, img.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    cv::Mat blurred, tilted;
    cv::GaussianBlur(rot, blurred, cv::Size(0, 0), sigma, 0.01);
    cv::resize(blurred, tilted, cv::Size(), 1.0 / t, 1.0, cv::INTER_LINEAR);
    std::vector<cv::KeyPoint> vk;
    cv::Mat vd;
    detectSift(tilted, p.features, vk, vd);
    if (vk.empty()) continue;
    // Back: un-compress x, then the inverse rotation.
    cv::Mat Ri;
    cv::invertAffineTransform(R, Ri);
    std::vector<cv::Point2f> pts;
    for (const auto& k : vk) pts.push_back({static_cast<float>(k.pt.x * t), k.pt.y});
    cv::transform(pts, pts, Ri);
    cv::Mat keep_rows;
    for (size_t i = 0; i < vk.size(); ++i) {
      if (pts[i].x < 0 || pts[i].y < 0 || pts[i].x >= img.cols || pts[i].y >= img.rows) continue;
      cv::KeyPoint k = vk[i];
      k.pt = pts[i];
      k.size = static_cast<float>(k.size * std::sqrt(t));  // geometric mean of the two scales
      kps.push_back(k);
      keep_rows.push_back(vd.row(static_cast<int>(i)));
    }
    if (!keep_rows.empty()) {
      if (sift_u8.empty())
        sift_u8 = keep_rows;
      else
        cv::vconcat(sift_u8, keep_rows, sift_u8);
    }
  }
}

}  // namespace

LandmarkModel trainModel(const std::string& landmark_dir, const ModelParams& params,
                         const TrainProgress& progress, const std::vector<std::string>& exclude) {
  params.validate();
  const LandmarkSet set = scanLandmarkSet(landmark_dir);
  LandmarkModel m;
  m.params_ = params;
  m.fingerprint_ = landmarkSetFingerprint(landmark_dir);

  struct Item {
    int cls;
    std::string path;
  };
  std::vector<Item> items;
  for (size_t c = 0; c < set.classes.size(); ++c) {
    if (std::find(exclude.begin(), exclude.end(), set.classes[c].name) != exclude.end()) continue;
    for (const auto& p : set.classes[c].photos) items.push_back({static_cast<int>(c), p});
  }

  // Features of every photo (the slow part: report progress).
  std::vector<DatabasePhoto> photos;
  std::vector<cv::Mat> colour_layouts;  // per kept photo, colour_layout.h
  const int total = static_cast<int>(items.size());
  int skipped = 0;
  for (int i = 0; i < total; ++i) {
    if (progress) progress("features", i, total);
    cv::Mat img;
    try {
      img = readImageFile(items[i].path, "photo");
    } catch (const InputError& e) {
      log::warn("landmarks", "skipping unreadable photo",
                {{"file", items[i].path}, {"why", e.what()}});
      ++skipped;
      continue;
    }
    DatabasePhoto ph;
    ph.class_id = items[i].cls;
    ph.path = fs::relative(items[i].path, set.root).string();
    ph.size = img.size();
    detectSift(img, params.features, ph.keypoints, ph.sift_u8);
    addSynthesisedViews(img, params, ph.keypoints, ph.sift_u8);
    ph.colours = keypointColours(img, ph.keypoints);
    ph.thumbnail = colourThumbnail(img, kPhotoThumbnailSide);
    if (ph.keypoints.size() < 5) {
      log::warn("landmarks", "skipping photo with too little texture",
                {{"file", items[i].path}, {"features", std::to_string(ph.keypoints.size())}});
      ++skipped;
      continue;
    }
    {
      std::vector<cv::Point2f> pts;
      pts.reserve(ph.keypoints.size());
      for (const auto& k : ph.keypoints) pts.push_back(k.pt);
      colour_layouts.push_back(
          colourLayoutDescriptor(colourThumbnail(img), img.size(), colourRegion(pts, img.size())));
    }
    photos.push_back(std::move(ph));
  }
  if (progress) progress("features", total, total);

  // Classes that kept at least one photo, renumbered.
  std::vector<int> remap(set.classes.size(), -1);
  for (const auto& ph : photos) remap[ph.class_id] = 0;
  for (size_t c = 0; c < set.classes.size(); ++c) {
    if (remap[c] < 0) {
      if (std::find(exclude.begin(), exclude.end(), set.classes[c].name) != exclude.end()) continue;
      log::warn("landmarks", "dropping class without readable photos",
                {{"class", set.classes[c].name}});
      continue;
    }
    remap[c] = static_cast<int>(m.classes_.size());
    m.classes_.push_back(set.classes[c].name);
  }
  if (m.classes_.empty())
    throw InputError(landmark_dir + ": no class folder with a readable, textured photo");
  for (auto& ph : photos) ph.class_id = remap[ph.class_id];

  // Vocabulary over the working descriptors of all photos.
  if (progress) progress("vocabulary", 0, 1);
  int n_desc = 0;
  for (const auto& ph : photos) n_desc += ph.sift_u8.rows;
  cv::Mat all(n_desc, 128, CV_32F);
  {
    int r = 0;
    for (auto& ph : photos) {
      ph.descriptors = workingDescriptors(ph.sift_u8, params.features.root_sift);
      ph.descriptors.copyTo(all.rowRange(r, r + ph.descriptors.rows));
      r += ph.descriptors.rows;
    }
  }
  VocabularyParams vp;
  vp.size = params.vocabulary_size;
  vp.sample = params.kmeans_sample;
  vp.iterations = params.kmeans_iterations;
  vp.seed = static_cast<unsigned>(params.seed);
  Vocabulary vocab = Vocabulary::train(all, vp);
  all.release();
  std::vector<std::vector<int>> words(photos.size());
  for (size_t i = 0; i < photos.size(); ++i) words[i] = vocab.assign(photos[i].descriptors);
  vocab.computeIdf(words);
  if (progress) progress("vocabulary", 1, 1);

  // Classifier over the photos' histograms.
  if (progress) progress("classifier", 0, 1);
  cv::Mat hists(static_cast<int>(photos.size()), vocab.size(), CV_32F);
  std::vector<int> labels(photos.size());
  for (size_t i = 0; i < photos.size(); ++i) {
    photos[i].words = words[i];
    bowHistogram(words[i], vocab.idf()).copyTo(hists.row(static_cast<int>(i)));
    labels[i] = photos[i].class_id;
  }
  m.classifier_ = LinearClassifier::train(hists, labels, static_cast<int>(m.classes_.size()),
                                          params.svm_c, static_cast<unsigned>(params.seed));
  // The same kind of classifier over the photos' colour layouts (same C: both inputs are unit
  // L2 vectors).
  cv::Mat colours(static_cast<int>(photos.size()), kColourLayoutDims, CV_32F);
  for (size_t i = 0; i < photos.size(); ++i)
    colour_layouts[i].copyTo(colours.row(static_cast<int>(i)));
  m.colour_classifier_ =
      LinearClassifier::train(colours, labels, static_cast<int>(m.classes_.size()), params.svm_c,
                              static_cast<unsigned>(params.seed));
  if (progress) progress("classifier", 1, 1);
  m.vocabulary_ = std::move(vocab);
  m.photos_ = std::move(photos);
  m.finalise();
  log::info("landmarks", "model trained",
            {{"classes", std::to_string(m.classes_.size())},
             {"photos", std::to_string(m.photos_.size())},
             {"skipped", std::to_string(skipped)},
             {"words", std::to_string(m.vocabulary_.size())},
             {"seed", std::to_string(params.seed)}});
  return m;
}

LandmarkModel loadOrTrainModel(const std::string& landmark_dir, const std::string& cache_file,
                               const ModelParams& params, const TrainProgress& progress) {
  std::error_code ec;
  if (fs::exists(cache_file, ec)) {
    try {
      LandmarkModel m = LandmarkModel::load(cache_file);
      if (m.sourceFingerprint() == landmarkSetFingerprint(landmark_dir) &&
          paramsToJson(m.params()) == paramsToJson(params))
        return m;
      log::info("landmarks", "cached model is stale, retraining", {{"file", cache_file}});
    } catch (const InputError& e) {
      log::warn("landmarks", "cached model unusable, retraining",
                {{"file", cache_file}, {"why", e.what()}});
    }
  }
  LandmarkModel m = trainModel(landmark_dir, params, progress);
  if (fs::path(cache_file).has_parent_path())
    fs::create_directories(fs::path(cache_file).parent_path(), ec);
  m.save(cache_file);
  return m;
}

}  // namespace sketchnav::landmarks
