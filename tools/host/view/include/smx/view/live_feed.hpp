#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

// What the live view shows (docs/live-view.md), handed from the command's loop, which talks to
// the device, to the page server's thread. Only the newest frame of each camera is kept: a page
// that draws slowly skips frames instead of falling behind. Controls from the page queue here
// for the loop, which alone talks to the device.
namespace smx::view {

using Message = std::shared_ptr<const std::vector<std::byte>>;

struct FeedFrame {
  std::uint32_t seq = 0;
  Message message;
};

// A page's request, checked by the server: an action name and an optional argument.
struct Control {
  std::string action;  // "start", "stop", "preset", "config", "scan", "stop-scan"
  std::string value;   // the preset, KEY=VALUE, or scan mode; empty otherwise
};

// Frame to page: from the host receiving a frame to the page saying it has drawn it.
struct PageFigures {
  std::uint64_t framesPublished = 0;
  std::uint64_t framesDrawn = 0;
  double drawnPerSecond = 0.0;     // over the last two seconds
  double drawnPerSecondRun = 0.0;  // from the first draw to the last
  double latencyMeanMs = 0.0;
  double latencyP95Ms = 0.0;
  std::size_t latencySamples = 0;
};

class LiveFeed {
 public:
  static constexpr std::size_t kMaxCameras = 8;
  static constexpr std::size_t kMaxControls = 16;

  // --- the command's loop ---
  // The first text every page gets (device, rig, controls it offers).
  void setSession(const nlohmann::json& session);
  // Messages every page gets once after the session (the cameras' rays).
  void setStaticMessages(std::vector<std::vector<std::byte>> messages);
  // A camera's newest depth message (messages.hpp): its seq is set here. receivedNs: when the
  // host received the frame, CLOCK_MONOTONIC (the latency's start).
  void publishFrame(std::size_t camera, std::vector<std::byte> message, std::int64_t receivedNs);
  // Replaces the model shown (a scan's growing model); its seq is set here.
  void publishModel(std::vector<std::byte> message);
  // The status the pages show; "page" (PageFigures) is added to it by statusText().
  void setStatus(const nlohmann::json& status);
  // The controls queued so far, oldest first; the queue is then empty.
  [[nodiscard]] std::vector<Control> takeControls();
  [[nodiscard]] PageFigures figures() const;

  // --- the server ---
  [[nodiscard]] std::string sessionText() const;
  [[nodiscard]] std::vector<Message> staticMessages() const;
  // The frame to send after `sent` (each camera's last seq sent): the newest frame of the camera
  // that has a newer one and has waited longest; nullopt when none is newer.
  [[nodiscard]] std::optional<FeedFrame> nextFrame(const std::vector<std::uint32_t>& sent) const;
  [[nodiscard]] std::optional<FeedFrame> model() const;
  [[nodiscard]] std::string statusText() const;
  // A page has drawn frame `seq` at nowNs (CLOCK_MONOTONIC); unknown or old seqs are ignored.
  // Frames received before pageSinceNs (when that page connected) count as drawn but give no
  // latency: they waited for the page, not in the path to it.
  void drawn(std::uint32_t seq, std::int64_t nowNs, std::int64_t pageSinceNs = 0);
  // False when the queue is full (the page is told to wait).
  [[nodiscard]] bool pushControl(Control control);
  // Called (outside the lock) whenever something new is published.
  void setNotifier(std::function<void()> notify);

 private:
  void notify();

  mutable std::mutex mutex_;
  std::function<void()> notify_;
  std::string session_ = "{}";
  std::vector<Message> static_;
  std::vector<FeedFrame> newest_;  // by camera
  std::optional<FeedFrame> model_;
  nlohmann::json status_ = nlohmann::json::object();
  std::uint32_t seq_ = 0;
  std::deque<Control> controls_;
  // Receive times of recent seqs (seq % size), for the latency when the page says drawn.
  struct Received {
    std::uint32_t seq = 0;
    std::int64_t ns = 0;
    bool drawn = false;
  };
  std::vector<Received> received_ = std::vector<Received>(256);
  std::vector<double> latencyMs_;
  std::deque<std::int64_t> drawnNs_;  // the last few seconds of draws
  std::uint64_t published_ = 0;
  std::uint64_t drawnCount_ = 0;
  std::int64_t firstDrawnNs_ = 0;
  std::int64_t lastDrawnNs_ = 0;
};

// CLOCK_MONOTONIC in nanoseconds, the clock of ReceivedFrame::receivedNs.
[[nodiscard]] std::int64_t monotonicNs();

}  // namespace smx::view
