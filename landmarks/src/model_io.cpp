// The LandmarkModel object and its .slm file format.
//
// File layout (little-endian, as written by this build):
//   magic "SKNVLMDL" (8 bytes) | u32 format version | u64 payload size | u64 FNV-1a(payload)
//   payload: params JSON, landmark set fingerprint, class names, vocabulary centres + IDF,
//            classifier weights + rho + Platt (a, b), colour-layout classifier weights + rho +
//            Platt (a, b) (since version 4), then per photo: class, path, size,
//            keypoints (x, y, size, angle, response, octave), raw SIFT (N x 128 u8),
//            keypoint colours (N x 3 u8, since version 3), words, colour thumbnail (H x 3W u8,
//            since version 5).
// Working descriptors (RootSIFT) and histograms are recomputed on load: they are derived.
#include <Eigen/Core>
#include <opencv2/flann.hpp>
// After flann.hpp, which it needs (cvflann::seed_random).
#include <opencv2/flann/random.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>

#include <unistd.h>

#include "sketchnav/core/error.h"
#include "sketchnav/core/hash.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/landmarks/colour_layout.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::landmarks {

namespace {
constexpr char kMagic[8] = {'S', 'K', 'N', 'V', 'L', 'M', 'D', 'L'};
constexpr int kSiftDims = 128;                        // SIFT descriptor length
constexpr std::uint64_t kMaxModelBytes = 4ull << 30;  // largest model file read [bytes]

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    buf_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void bytes(const void* p, size_t n) { buf_.append(static_cast<const char*>(p), n); }
  void str(const std::string& s) {
    put<std::uint64_t>(s.size());
    buf_.append(s);
  }
  void mat(const cv::Mat& m) {  // continuous 2-D, any type
    cv::Mat c = m.isContinuous() ? m : m.clone();
    put<std::int32_t>(c.rows);
    put<std::int32_t>(c.cols);
    put<std::int32_t>(c.type());
    bytes(c.data, c.total() * c.elemSize());
  }
  std::string& buffer() { return buf_; }

 private:
  std::string buf_;
};

class Reader {
 public:
  Reader(const char* p, size_t n, std::string file) : p_(p), end_(p + n), file_(std::move(file)) {}
  template <class T>
  T get() {
    T v;
    need(sizeof v);
    std::memcpy(&v, p_, sizeof v);
    p_ += sizeof v;
    return v;
  }
  std::string str() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(p_, n);
    p_ += n;
    return s;
  }
  /// A matrix field named `field` in errors. Its declared size is checked against the bytes
  /// left before anything is allocated (a corrupt header must not ask for gigabytes).
  cv::Mat mat(const std::string& field) {
    const int rows = get<std::int32_t>(), cols = get<std::int32_t>(), type = get<std::int32_t>();
    if (rows < 0 || cols < 0 || (type != CV_32F && type != CV_8U && type != CV_32S))
      corrupt(field + ": bad matrix header");
    const size_t esz = type == CV_8U ? 1 : 4;
    if (rows > 0 && cols > 0 &&
        static_cast<size_t>(cols) > remaining() / static_cast<size_t>(rows) / esz)
      corrupt(field + ": " + std::to_string(rows) + " x " + std::to_string(cols) +
              " matrix runs past the end of the payload");
    if (rows == 0 || cols == 0) return cv::Mat(rows, cols, type);
    cv::Mat m(rows, cols, type);
    const size_t n = m.total() * m.elemSize();
    need(n);
    std::memcpy(m.data, p_, n);
    p_ += n;
    return m;
  }
  bool atEnd() const { return p_ == end_; }
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  /// A count of items of at least `min_bytes` each that must fit in what is left.
  std::uint32_t count(const std::string& field, size_t min_bytes) {
    const auto n = get<std::uint32_t>();
    if (static_cast<size_t>(n) > remaining() / min_bytes)
      corrupt(field + ": count " + std::to_string(n) + " runs past the end of the payload");
    return n;
  }
  [[noreturn]] void corrupt(const std::string& why) const {
    throw InputError(file_ + ": corrupt landmark model (" + why +
                     "); retrain with "
                     "`sketchnav train`");
  }

 private:
  void need(size_t n) const {
    if (static_cast<size_t>(end_ - p_) < n) corrupt("field runs past the end of the payload");
  }
  const char* p_;
  const char* end_;
  std::string file_;
};
/// The elements of a continuous matrix of type `type` with exactly `n` elements, else a
/// corrupt-model error naming `field`. Never iterates an empty or mistyped matrix.
template <class T>
std::vector<T> elements(const Reader& r, const cv::Mat& m, int type, size_t n,
                        const std::string& field) {
  if (m.total() != n || (n > 0 && m.type() != type))
    r.corrupt(field + ": expected " + std::to_string(n) + " values, got " +
              std::to_string(m.total()));
  if (n == 0) return {};
  const T* p = m.ptr<T>(0);
  return std::vector<T>(p, p + n);
}

bool finite(float v) {
  return std::isfinite(v);
}
}  // namespace

struct LandmarkModel::Cache {
  std::mutex mutex;
  std::once_flag global_once;
  cv::Mat global_descriptors;                     // all photos' descriptors, stacked
  std::vector<std::pair<int, int>> global_owner;  // row -> (photo, keypoint)
  std::unique_ptr<cv::flann::Index> global_index;
  // Per class: its photos' descriptors stacked, row -> photo, and a kd-tree (built lazily).
  struct PerClass {
    std::once_flag once;
    cv::Mat descriptors;
    std::vector<int> photo;
    std::unique_ptr<cv::flann::Index> index;
  };
  std::unique_ptr<PerClass[]> per_class;
};

LandmarkModel::LandmarkModel() : cache_(std::make_unique<Cache>()) {}
LandmarkModel::~LandmarkModel() = default;
LandmarkModel::LandmarkModel(LandmarkModel&&) noexcept = default;
LandmarkModel& LandmarkModel::operator=(LandmarkModel&&) noexcept = default;

int LandmarkModel::classId(const std::string& name) const {
  for (size_t i = 0; i < classes_.size(); ++i)
    if (classes_[i] == name) return static_cast<int>(i);
  return -1;
}

void LandmarkModel::finalise() {
  by_class_.assign(classes_.size(), {});
  for (size_t i = 0; i < photos_.size(); ++i) {
    auto& ph = photos_[i];
    if (ph.descriptors.empty() || ph.descriptors.rows != ph.sift_u8.rows)
      ph.descriptors = workingDescriptors(ph.sift_u8, params_.features.root_sift);
    ph.histogram = bowHistogram(ph.words, vocabulary_.idf());
    by_class_[ph.class_id].push_back(static_cast<int>(i));
  }
  cache_ = std::make_unique<Cache>();
  cache_->per_class = std::make_unique<Cache::PerClass[]>(classes_.size());
}

void LandmarkModel::knn2(int photo, const cv::Mat& query, cv::Mat& indices, cv::Mat& dists) const {
  // Exact brute force: for one photo's ~500 descriptors a full distance table beats a FLANN
  // kd-tree search (2.4 vs 4.5 ms per photo with cv::batchDistance) and never misses. The
  // table is one matrix product, |q - t|^2 = |q|^2 + |t|^2 - 2 q.t, which Eigen's GEMM kernel
  // computes in 1.5 ms (400 x 600 descriptors, one core, the distribution's SSE2 baseline);
  // the neighbours are the same up to float rounding on exact ties.
  const cv::Mat& train = photos_[photo].descriptors;
  indices.create(query.rows, 2, CV_32S);
  dists.create(query.rows, 2, CV_32F);
  indices.setTo(-1);
  dists.setTo(std::numeric_limits<float>::max());
  if (query.empty() || train.rows < 1) return;
  // Working descriptors on both sides (cv::batchDistance refused anything else too).
  CV_Assert(query.type() == CV_32F && train.type() == CV_32F && query.cols == train.cols);
  using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using View = Eigen::Map<const RowMajor, 0, Eigen::OuterStride<>>;
  const View T(train.ptr<float>(), train.rows, train.cols,
               Eigen::OuterStride<>(static_cast<Eigen::Index>(train.step1())));
  const Eigen::VectorXf tn = T.rowwise().squaredNorm();
  // Query rows in blocks: the product block stays in cache and its buffer is reused.
  constexpr int kBlock = 64;
  thread_local std::vector<float> buffer;
  buffer.resize(static_cast<size_t>(kBlock) * train.rows);
  for (int r0 = 0; r0 < query.rows; r0 += kBlock) {
    const int rows = std::min(kBlock, query.rows - r0);
    const View Q(query.ptr<float>(r0), rows, query.cols,
                 Eigen::OuterStride<>(static_cast<Eigen::Index>(query.step1())));
    Eigen::Map<RowMajor> G(buffer.data(), rows, train.rows);
    G.noalias() = Q * T.transpose();
    for (int i = 0; i < rows; ++i) {
      const float qn = Q.row(i).squaredNorm();
      const float* g = &G(i, 0);
      float b1 = std::numeric_limits<float>::max(), b2 = b1;
      int j1 = -1, j2 = -1;
      for (int j = 0; j < train.rows; ++j) {
        const float v = tn[j] - 2 * g[j];
        if (v < b2) {
          if (v < b1) {
            b2 = b1, j2 = j1, b1 = v, j1 = j;
          } else {
            b2 = v, j2 = j;
          }
        }
      }
      int* id = indices.ptr<int>(r0 + i);
      float* ds = dists.ptr<float>(r0 + i);
      id[0] = j1, ds[0] = std::max(0.0f, qn + b1);
      if (j2 >= 0) id[1] = j2, ds[1] = std::max(0.0f, qn + b2);
    }
  }
}

void LandmarkModel::knnAll(const cv::Mat& query, int k, int checks, cv::Mat& indices,
                           cv::Mat& dists) const {
  std::call_once(cache_->global_once, [this] {
    int n = 0;
    for (const auto& ph : photos_) n += ph.descriptors.rows;
    cache_->global_descriptors.create(n, 128, CV_32F);
    cache_->global_owner.resize(n);
    int r = 0;
    for (size_t p = 0; p < photos_.size(); ++p) {
      const cv::Mat& d = photos_[p].descriptors;
      d.copyTo(cache_->global_descriptors.rowRange(r, r + d.rows));
      for (int i = 0; i < d.rows; ++i) cache_->global_owner[r + i] = {static_cast<int>(p), i};
      r += d.rows;
    }
    cvflann::seed_random(4242);  // reproducible trees
    cache_->global_index = std::make_unique<cv::flann::Index>(cache_->global_descriptors,
                                                              cv::flann::KDTreeIndexParams(4));
  });
  k = std::min(k, cache_->global_descriptors.rows);
  cache_->global_index->knnSearch(query, indices, dists, k, cv::flann::SearchParams(checks));
}

std::vector<int> LandmarkModel::classPhotoVotes(int class_id, const cv::Mat& query,
                                                int checks) const {
  std::vector<int> votes(photos_.size(), 0);
  for (int p : classNearestPhoto(class_id, query, checks))
    if (p >= 0) ++votes[p];
  return votes;
}

std::vector<int> LandmarkModel::classNearestPhoto(int class_id, const cv::Mat& query,
                                                  int checks) const {
  std::vector<int> out(query.rows, -1);
  if (class_id < 0 || class_id >= static_cast<int>(classes_.size()) || query.empty()) return out;
  if (!cache_->per_class) return out;  // created by finalise()
  Cache::PerClass& pc = cache_->per_class[class_id];
  std::call_once(pc.once, [&] {
    int n = 0;
    for (int p : by_class_[class_id]) n += photos_[p].descriptors.rows;
    pc.descriptors.create(n, 128, CV_32F);
    pc.photo.resize(n);
    int r = 0;
    for (int p : by_class_[class_id]) {
      const cv::Mat& d = photos_[p].descriptors;
      d.copyTo(pc.descriptors.rowRange(r, r + d.rows));
      std::fill(pc.photo.begin() + r, pc.photo.begin() + r + d.rows, p);
      r += d.rows;
    }
    if (n > 0) {
      cvflann::seed_random(4243);  // reproducible trees
      pc.index =
          std::make_unique<cv::flann::Index>(pc.descriptors, cv::flann::KDTreeIndexParams(2));
    }
  });
  if (!pc.index) return out;
  cv::Mat idx, dist;
  pc.index->knnSearch(query, idx, dist, 1, cv::flann::SearchParams(checks));
  for (int i = 0; i < idx.rows; ++i) {
    const int r = idx.at<int>(i, 0);
    if (r >= 0 && r < static_cast<int>(pc.photo.size())) out[i] = pc.photo[r];
  }
  return out;
}

void LandmarkModel::buildIndexes() const {
  cv::Mat idx, dist;
  if (photos_.empty()) return;
  const cv::Mat probe =
      photos_[0].descriptors.rowRange(0, std::min(1, photos_[0].descriptors.rows));
  if (probe.empty()) return;
  knnAll(probe, 2, 1, idx, dist);
  for (size_t c = 0; c < classes_.size(); ++c) classPhotoVotes(static_cast<int>(c), probe, 1);
}

std::pair<int, int> LandmarkModel::globalOwner(int row) const {
  return cache_->global_owner[row];
}

void LandmarkModel::save(const std::string& path) const {
  // The rename below would replace a device node or FIFO (`-o /dev/full` as root did).
  requireOutputFile(path, "landmark model");
  Writer w;
  w.str(paramsToJson(params_).dump());
  w.str(fingerprint_);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(classes_.size()));
  for (const auto& c : classes_) w.str(c);
  w.mat(vocabulary_.centres());
  w.mat(cv::Mat(vocabulary_.idf(), true).reshape(1, 1));
  w.mat(classifier_.weights);
  w.mat(cv::Mat(classifier_.rho, true).reshape(1, 1));
  w.put<float>(classifier_.platt_a);
  w.put<float>(classifier_.platt_b);
  w.mat(colour_classifier_.weights);
  w.mat(cv::Mat(colour_classifier_.rho, true).reshape(1, 1));
  w.put<float>(colour_classifier_.platt_a);
  w.put<float>(colour_classifier_.platt_b);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(photos_.size()));
  for (const auto& ph : photos_) {
    w.put<std::int32_t>(ph.class_id);
    w.str(ph.path);
    w.put<std::int32_t>(ph.size.width);
    w.put<std::int32_t>(ph.size.height);
    w.put<std::uint32_t>(static_cast<std::uint32_t>(ph.keypoints.size()));
    for (const auto& k : ph.keypoints) {
      w.put<float>(k.pt.x);
      w.put<float>(k.pt.y);
      w.put<float>(k.size);
      w.put<float>(k.angle);
      w.put<float>(k.response);
      w.put<std::int32_t>(k.octave);
    }
    w.mat(ph.sift_u8.empty() ? cv::Mat(0, 128, CV_8U) : ph.sift_u8);
    w.mat(ph.colours.empty() ? cv::Mat(0, 3, CV_8U) : ph.colours);
    w.mat(cv::Mat(ph.words, true).reshape(1, 1));
    w.mat(ph.thumbnail.empty() ? cv::Mat(0, 0, CV_8U) : ph.thumbnail.reshape(1));
  }
  const std::string& payload = w.buffer();
  // Written beside the target and renamed into place, so a reader (another process sharing the
  // model cache, or a crash mid-write) never sees a half-written model.
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) throw RuntimeError(path + ": cannot write landmark model");
  const std::uint32_t version = kFormatVersion;
  const std::uint64_t size = payload.size(), sum = fnv1a(payload.data(), payload.size());
  out.write(kMagic, sizeof kMagic);
  out.write(reinterpret_cast<const char*>(&version), sizeof version);
  out.write(reinterpret_cast<const char*>(&size), sizeof size);
  out.write(reinterpret_cast<const char*>(&sum), sizeof sum);
  out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  out.close();
  std::error_code ec;
  if (!out) {
    std::filesystem::remove(tmp, ec);
    throw RuntimeError(path + ": writing the landmark model failed (disk full?)");
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw RuntimeError(path + ": cannot move the landmark model into place: " + ec.message());
  }
}

LandmarkModel LandmarkModel::load(const std::string& path) {
  // A directory, FIFO or device is refused before it is opened; the size is bounded before
  // the file is read whole.
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(path + ": landmark model not found or unreadable");
  const std::string data = readInputFile(path, "landmark model", kMaxModelBytes);
  constexpr size_t kHeader = 8 + 4 + 8 + 8;
  if (data.size() < 8 || std::memcmp(data.data(), kMagic, 8) != 0)
    throw InputError(path + ": not a sketchnav landmark model (.slm)");
  if (data.size() < kHeader)
    throw InputError(path + ": truncated landmark model (header incomplete)");
  std::uint32_t version;
  std::uint64_t size, sum;
  std::memcpy(&version, data.data() + 8, 4);
  std::memcpy(&size, data.data() + 12, 8);
  std::memcpy(&sum, data.data() + 20, 8);
  if (version != kFormatVersion)
    throw InputError(path + ": landmark model format version " + std::to_string(version) +
                     ", this build reads version " + std::to_string(kFormatVersion) +
                     "; retrain with `sketchnav train`");
  if (data.size() - kHeader != size)
    throw InputError(path + ": truncated landmark model (payload " +
                     std::to_string(data.size() - kHeader) + " of " + std::to_string(size) +
                     " bytes)");
  const char* payload = data.data() + kHeader;
  if (fnv1a(payload, size) != sum)
    throw InputError(path + ": corrupt landmark model (checksum mismatch)");

  // The checksum catches accidents, not a crafted file: every size below is checked before use.
  Reader r(payload, size, path);
  LandmarkModel m;
  {
    const std::string params = r.str();
    Json pj;
    try {
      pj = parseJsonText(params, "parameter block");
    } catch (const InputError& e) {
      r.corrupt(e.what());
    }
    if (!pj.is_object()) r.corrupt("parameter block: not a JSON object");
    try {
      applyConfig(m.params_, Config::fromJson(pj, path), "");
    } catch (const InputError& e) {
      throw InputError(path + ": landmark model parameter block: " + clipForMessage(e.what(), 200));
    } catch (const Json::exception& e) {
      r.corrupt(std::string("parameter block: ") + clipForMessage(e.what(), 120));
    }
  }
  m.fingerprint_ = r.str();
  const auto n_classes = r.count("class count", 8);
  if (n_classes < 1) r.corrupt("class count: 0");
  for (std::uint32_t i = 0; i < n_classes; ++i) m.classes_.push_back(r.str());
  cv::Mat centres = r.mat("vocabulary centres"), idf = r.mat("vocabulary idf");
  if (centres.type() != CV_32F || centres.rows < 1 || centres.cols != kSiftDims)
    r.corrupt("vocabulary centres: expected K x " + std::to_string(kSiftDims) + " floats, K >= 1");
  const std::vector<float> idf_v =
      elements<float>(r, idf, CV_32F, static_cast<size_t>(centres.rows), "vocabulary idf");
  for (float v : idf_v)
    if (!finite(v)) r.corrupt("vocabulary idf: not finite");
  m.vocabulary_ = Vocabulary::fromCentres(centres, idf_v);
  m.classifier_.weights = r.mat("classifier weights");
  cv::Mat rho = r.mat("classifier rho");
  m.classifier_.platt_a = r.get<float>();
  m.classifier_.platt_b = r.get<float>();
  if (m.classifier_.weights.type() != CV_32F ||
      m.classifier_.weights.rows != static_cast<int>(n_classes) ||
      m.classifier_.weights.cols != centres.rows)
    r.corrupt("classifier weights: expected " + std::to_string(n_classes) + " x " +
              std::to_string(centres.rows) + " floats");
  m.classifier_.rho = elements<float>(r, rho, CV_32F, n_classes, "classifier rho");
  if (!finite(m.classifier_.platt_a) || !finite(m.classifier_.platt_b))
    r.corrupt("classifier Platt scaling: not finite");
  m.colour_classifier_.weights = r.mat("colour classifier weights");
  cv::Mat colour_rho = r.mat("colour classifier rho");
  if (m.colour_classifier_.weights.type() != CV_32F ||
      m.colour_classifier_.weights.rows != static_cast<int>(n_classes) ||
      m.colour_classifier_.weights.cols != kColourLayoutDims)
    r.corrupt("colour classifier weights: expected " + std::to_string(n_classes) + " x " +
              std::to_string(kColourLayoutDims) + " floats");
  m.colour_classifier_.rho =
      elements<float>(r, colour_rho, CV_32F, n_classes, "colour classifier rho");
  m.colour_classifier_.platt_a = r.get<float>();
  m.colour_classifier_.platt_b = r.get<float>();
  if (!finite(m.colour_classifier_.platt_a) || !finite(m.colour_classifier_.platt_b))
    r.corrupt("colour classifier Platt scaling: not finite");
  // A photo record is at least class + path length + size + keypoint count + 4 matrix headers.
  constexpr size_t kMinPhotoBytes = 4 + 8 + 8 + 4 + 4 * 12;
  constexpr size_t kKeypointBytes = 6 * 4;
  const auto n_photos = r.count("photo count", kMinPhotoBytes);
  m.photos_.resize(n_photos);
  for (std::uint32_t i = 0; i < n_photos; ++i) {
    auto& ph = m.photos_[i];
    const std::string f = "photo " + std::to_string(i);
    ph.class_id = r.get<std::int32_t>();
    if (ph.class_id < 0 || ph.class_id >= static_cast<int>(n_classes))
      r.corrupt(f + " class: " + std::to_string(ph.class_id) + " is not a class index");
    ph.path = r.str();
    ph.size.width = r.get<std::int32_t>();
    ph.size.height = r.get<std::int32_t>();
    if (ph.size.width < 0 || ph.size.height < 0) r.corrupt(f + " size: negative");
    const auto nk = r.count(f + " keypoint count", kKeypointBytes);
    ph.keypoints.resize(nk);
    for (auto& k : ph.keypoints) {
      k.pt.x = r.get<float>();
      k.pt.y = r.get<float>();
      k.size = r.get<float>();
      k.angle = r.get<float>();
      k.response = r.get<float>();
      k.octave = r.get<std::int32_t>();
      if (!finite(k.pt.x) || !finite(k.pt.y) || !finite(k.size) || !finite(k.angle) ||
          !finite(k.response))
        r.corrupt(f + " keypoints: not finite");
    }
    ph.sift_u8 = r.mat(f + " descriptors");
    ph.colours = r.mat(f + " keypoint colours");
    cv::Mat words = r.mat(f + " words");
    if (nk > 0 && (ph.sift_u8.type() != CV_8U || ph.sift_u8.rows != static_cast<int>(nk) ||
                   ph.sift_u8.cols != kSiftDims))
      r.corrupt(f + " descriptors: expected " + std::to_string(nk) + " x " +
                std::to_string(kSiftDims) + " bytes");
    if (nk > 0 && (ph.colours.type() != CV_8U || ph.colours.rows != static_cast<int>(nk) ||
                   ph.colours.cols != 3))
      r.corrupt(f + " keypoint colours: expected " + std::to_string(nk) + " x 3 bytes");
    if (nk == 0) {
      ph.sift_u8 = cv::Mat(0, kSiftDims, CV_8U);
      ph.colours = cv::Mat(0, 3, CV_8U);
    }
    ph.words = elements<int>(r, words, CV_32S, nk, f + " words");
    for (int wd : ph.words)
      if (wd < 0 || wd >= centres.rows) r.corrupt(f + " words: index out of the vocabulary");
    cv::Mat thumb = r.mat(f + " thumbnail");
    if ((!thumb.empty() && thumb.type() != CV_8U) || thumb.cols % 3 != 0 ||
        thumb.rows > kPhotoThumbnailSide || thumb.cols > 3 * kPhotoThumbnailSide)
      r.corrupt(f + " thumbnail");
    if (!thumb.empty()) ph.thumbnail = thumb.reshape(3);
  }
  if (!r.atEnd()) r.corrupt("trailing bytes");
  m.finalise();
  return m;
}

}  // namespace sketchnav::landmarks
