#include "sketchnav/drivers/register.h"

#include <sstream>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/drivers/aravis_camera.h"
#include "sketchnav/drivers/dani_base.h"
#include "sketchnav/drivers/file_cameras.h"
#include "sketchnav/drivers/laser_sensors.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/hw/registry.h"

namespace sketchnav::drivers {
namespace {

// 0.2 rather than std::to_string's 0.200000, for messages.
std::string shortNumber(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

// The shared secret never travels in a URI (URIs are logged and stored in summaries): it is
// read from a file named by ?secret_file= or the config key base.dani.secret_file. Only a
// regular file of at most kMaxSecretFileBytes is read (a FIFO would block, /dev/zero would grow
// without end).
std::string readSecret(const std::string& path, const std::string& what) {
  if (path.empty()) return {};
  std::string s = readInputFile(path, what + ": secret file", kMaxSecretFileBytes);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  if (s.size() < 8) throw InputError(what + ": secret in '" + path + "' is shorter than 8 bytes");
  return s;
}

std::shared_ptr<DaniLink> daniLink(const Uri& uri, DeviceContext& ctx) {
  const std::string key = "dani://" + uri.authority;
  if (auto it = ctx.shared.find(key); it != ctx.shared.end())
    return std::any_cast<std::shared_ptr<DaniLink>>(it->second);
  DaniParams p;
  applyConfig(p, ctx.config, "base.dani");
  p.link_timeout_s = uri.paramDouble("link_timeout_s", p.link_timeout_s);
  p.connect_timeout_s = uri.paramDouble("connect_timeout_s", p.connect_timeout_s);
  p.resume_on_connect = uri.paramInt("resume", p.resume_on_connect ? 1 : 0) != 0;
  p.validate();
  std::string secret_file;
  if (ctx.config.has("base.dani.secret_file")) {
    ctx.config.markUsed("base.dani.secret_file");
    secret_file = ctx.config.at("base.dani.secret_file").get<std::string>();
  }
  secret_file = uri.param("secret_file", secret_file);
  const std::string host = uri.host();
  const int port = uri.port();
  auto link = std::make_shared<DaniLink>(
      host, port, p, ctx.clock, readSecret(secret_file, "base URI '" + uri.text + "'"), uri.text);
  if (!link->connect(p.connect_timeout_s))
    throw RuntimeError("base '" + uri.text + "': no answer from the base within " +
                       shortNumber(p.connect_timeout_s) +
                       " s (is it on, and is this laptop its allowed peer?)");
  ctx.shared[key] = link;
  return link;
}

}  // namespace

void registerDrivers() {
  Registry& r = Registry::instance();
  r.addCamera(
      "folder",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Camera> {
        if (uri.path.empty())
          throw InputError("camera URI '" + uri.text + "': expected folder:///absolute/path");
        FolderCameraParams p;
        applyConfig(p, ctx.config, "camera.folder");
        p.fps = uri.paramDouble("fps", p.fps);
        p.loop = uri.paramInt("loop", p.loop ? 1 : 0) != 0;
        p.hfov_deg = uri.paramDouble("hfov_deg", p.hfov_deg);
        p.validate();
        return std::make_unique<FolderCamera>(uri.path, p, uri.text);
      },
      {"fps", "loop", "hfov_deg"});
  r.addCamera("video",
              [](const Uri& uri, DeviceContext&) -> std::unique_ptr<Camera> {
                const std::string source = uri.path.empty() ? uri.authority : uri.path;
                if (source.empty())
                  throw InputError("camera URI '" + uri.text +
                                   "': expected video:///file or video://INDEX");
                return std::make_unique<VideoCamera>(source, uri.paramDouble("hfov_deg", 60.0),
                                                     uri.text);
              },
              {"hfov_deg"});
  // What daniLink() reads from a dani:// URI.
  const Registry::Parameters kDaniParameters = {"link_timeout_s", "connect_timeout_s", "resume",
                                                "secret_file"};
  r.addCamera("aravis",
              [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Camera> {
                AravisParams p;
                applyConfig(p, ctx.config, "camera.aravis");
                p.applyUri(uri);
                p.validate();
                return std::make_unique<AravisCamera>(uri.authority, p, ctx.clock, uri.text);
              },
              {"pixel_format", "width", "height", "fps", "exposure_us", "gain_db", "buffers",
               "packet_size", "resend", "hfov_deg", "lost_timeout_s", "reconnect_period_s"});
  r.addBase(
      "dani",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Base> {
        return std::make_unique<DaniBase>(daniLink(uri, ctx));
      },
      kDaniParameters);
  r.addCamera(
      "rawlog",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Camera> {
        if (uri.path.empty())
          throw InputError("camera URI '" + uri.text + "': expected rawlog:///path/file.rawlog");
        return std::make_unique<RawlogCamera>(
            uri.path, uri.param("label", ""), uri.text,
            uri.paramInt("realtime", 0) != 0
                ? (ctx.clock ? ctx.clock : std::make_shared<SteadyClock>())
                : nullptr);
      },
      {"label", "realtime"});
  r.addBase(
      "rawlog",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Base> {
        if (uri.path.empty())
          throw InputError("base URI '" + uri.text + "': expected rawlog:///path/file.rawlog");
        return std::make_unique<RawlogBase>(uri.path, ctx.clock, uri.param("label", "ODOMETRY"),
                                            uri.text);
      },
      {"label"});
  // laser://DRIVER?key=value: the query is the MRPT driver's own configuration section.
  r.addRange("laser",
             [](const Uri& uri, DeviceContext& ctx) { return createLaserFromUri(uri, ctx.clock); },
             {Registry::kAnyParameter});
  r.addRange("rawlog",
             [](const Uri& uri, DeviceContext& ctx) { return createLaserFromUri(uri, ctx.clock); },
             {"realtime", "loop", "label"});
  r.addRange(
      "dani",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<RangeSensor> {
        return std::make_unique<DaniSonar>(daniLink(uri, ctx));
      },
      kDaniParameters);
}

}  // namespace sketchnav::drivers
