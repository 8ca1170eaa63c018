#pragma once

#include <cstdint>
#include <expected>
#include <memory>
#include <string>

#include "smx/view/live_feed.hpp"

// The live view's page server (docs/live-view.md): HTTP for the page and its scripts, a
// WebSocket for the feed, on a thread of its own. Only the newest frame of each camera goes to a
// page, one at a time: a camera's next is sent when the page says it has drawn its last. The page
// works offline: three.js comes from Debian's libjs-three on this machine, never a CDN.
namespace smx::view {

struct ServerOptions {
  std::string bind = "127.0.0.1";  // loopback unless told otherwise
  std::uint16_t port = 0;          // 0: any free port
  // Debian's libjs-three: three.min.js and examples/js/controls/OrbitControls.js are served.
  std::string threeDir = "/usr/share/javascript/three";
};

class ViewServer {
 public:
  // Listens and serves until destroyed. Errors: the address does not parse or cannot be bound.
  [[nodiscard]] static std::expected<std::unique_ptr<ViewServer>, std::string> start(
      LiveFeed& feed, const ServerOptions& options);
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;
  ~ViewServer();

  [[nodiscard]] std::uint16_t port() const;
  // http://ADDRESS:PORT/ as a browser on this machine opens it.
  [[nodiscard]] std::string url() const;
  // Whether three.js was found (else the page shows no 3D view and says why).
  [[nodiscard]] bool hasThreeJs() const;

  struct Impl;

 private:
  explicit ViewServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace smx::view
