// Per-frame cost of the objectness union on a 640x480 frame like the navigation camera's:
// a plain room wall with photo-like landmarks. One thread, as in the navigation loop.
#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <random>

#include "sketchnav/landmarks/objectness.h"

namespace {
using namespace sketchnav::landmarks;

cv::Mat frame() {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> c(0, 255);
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(185, 190, 200));
  cv::Mat noise(img.size(), CV_8UC3);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(4));
  img += noise;
  cv::rectangle(img, cv::Rect(0, 330, 640, 150), cv::Scalar(90, 110, 130), cv::FILLED);  // floor
  for (const cv::Rect& b :
       {cv::Rect(80, 200, 40, 50), cv::Rect(300, 150, 120, 90), cv::Rect(520, 260, 60, 60)}) {
    cv::Mat p = img(b);
    for (int k = 0; k < 20; ++k)
      cv::circle(p, {c(rng) % b.width, c(rng) % b.height}, 2 + c(rng) % 10,
                 cv::Scalar(c(rng), c(rng), c(rng)), cv::FILLED);
  }
  return img;
}

void BM_ProposeUnion(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat img = frame();
  ObjectnessParams p;
  p.use_ccs = state.range(0) & 1;
  p.use_scs = state.range(0) & 2;
  const Objectness o(p);
  for (auto _ : state) benchmark::DoNotOptimize(o.propose(img, static_cast<int>(state.range(1))));
}
// range(0): 1 = CCS only, 2 = SCS only, 3 = union; range(1): window budget.
BENCHMARK(BM_ProposeUnion)
    ->Args({3, 100})
    ->Args({3, 1000})
    ->Args({1, 100})
    ->Args({2, 100})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
