# Finds every third-party dependency once, and fails at configure time with the Debian
# package that provides the missing one, so a user knows what to apt-get install.

macro(sketchnav_require found what debian_pkg)
  if(NOT ${found})
    message(FATAL_ERROR "sketchnav: ${what} not found. Install it with: "
                        "sudo apt-get install ${debian_pkg}  (or run ./bootstrap.sh)")
  endif()
endmacro()

find_package(Threads REQUIRED)

find_package(OpenCV QUIET COMPONENTS core imgproc imgcodecs videoio features2d calib3d flann ml
                                      ximgproc saliency img_hash)
sketchnav_require(OpenCV_FOUND "OpenCV 4 with contrib (ximgproc, saliency)"
                  "libopencv-dev libopencv-contrib-dev")

find_package(Eigen3 3.3 QUIET NO_MODULE)
sketchnav_require(Eigen3_FOUND "Eigen 3" "libeigen3-dev")

find_package(VISP QUIET COMPONENTS visp_core visp_vs visp_robot)
sketchnav_require(VISP_FOUND "ViSP (visp_core, visp_vs, visp_robot)" "libvisp-dev")

find_package(MRPT 2.0 QUIET COMPONENTS poses kinematics obs maps nav slam hwdrivers)
sketchnav_require(MRPT_FOUND "MRPT 2 (poses, kinematics, obs, maps, nav, slam, hwdrivers)" "libmrpt-dev")

find_package(nlohmann_json 3 QUIET)
sketchnav_require(nlohmann_json_FOUND "nlohmann-json" "nlohmann-json3-dev")

find_package(PkgConfig QUIET)
sketchnav_require(PKG_CONFIG_FOUND "pkg-config" "pkg-config")
pkg_check_modules(ARAVIS QUIET IMPORTED_TARGET aravis-0.8)
sketchnav_require(ARAVIS_FOUND "Aravis 0.8" "libaravis-dev libusb-1.0-0-dev")

find_package(ZLIB QUIET)
sketchnav_require(ZLIB_FOUND "zlib" "zlib1g-dev")
find_package(OpenSSL QUIET COMPONENTS Crypto)
sketchnav_require(OPENSSL_FOUND "OpenSSL (libcrypto)" "libssl-dev")

find_path(HTTPLIB_INCLUDE_DIR httplib.h)
if(HTTPLIB_INCLUDE_DIR)
  set(HTTPLIB_FOUND TRUE)
endif()
sketchnav_require(HTTPLIB_FOUND "cpp-httplib" "libcpp-httplib-dev")

if(SKETCHNAV_BUILD_TESTS)
  find_package(GTest QUIET)
  sketchnav_require(GTest_FOUND "GoogleTest" "libgtest-dev libgmock-dev")
endif()
if(SKETCHNAV_BUILD_BENCH)
  find_package(benchmark QUIET)
  sketchnav_require(benchmark_FOUND "Google Benchmark" "libbenchmark-dev")
endif()
