// A tiny program built against the *installed* sketchnav package: proves the exported
// targets, headers and transitive dependencies are complete.
#include <sketchnav/core/uri.h>
#include <sketchnav/drivers/register.h>
#include <sketchnav/hw/registry.h>

#include <iostream>

int main() {
  sketchnav::drivers::registerDrivers();
  const auto schemes = sketchnav::hw::Registry::instance().cameraSchemes();
  const auto uri = sketchnav::Uri::parse("dani://127.0.0.1:5000");
  const bool ok = !schemes.empty() && uri.port() == 5000;
  std::cout << (ok ? "consumer ok" : "consumer FAILED") << "\n";
  return ok ? 0 : 1;
}
