#include "smx/view/live_feed.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>

namespace smx::view {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr std::int64_t kDrawnWindowNs = 2 * kNsPerS;
constexpr std::size_t kMaxLatencySamples = 1'000'000;

void patchSeq(std::vector<std::byte>& message, std::uint32_t seq) {
  for (std::size_t i = 0; i < 4 && 8 + i < message.size(); ++i) {
    message[8 + i] = static_cast<std::byte>((seq >> (8 * i)) & 0xFFU);
  }
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) {
    return 0.0;
  }
  std::ranges::sort(v);
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

}  // namespace

std::int64_t monotonicNs() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNsPerS + now.tv_nsec;
}

void LiveFeed::setSession(const nlohmann::json& session) {
  {
    const std::lock_guard lock(mutex_);
    session_ = session.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  notify();
}

void LiveFeed::setStaticMessages(std::vector<std::vector<std::byte>> messages) {
  const std::lock_guard lock(mutex_);
  static_.clear();
  for (auto& m : messages) {
    static_.push_back(std::make_shared<const std::vector<std::byte>>(std::move(m)));
  }
}

void LiveFeed::publishFrame(std::size_t camera, std::vector<std::byte> message,
                            std::int64_t receivedNs) {
  if (camera >= kMaxCameras) {
    return;
  }
  {
    const std::lock_guard lock(mutex_);
    const std::uint32_t seq = ++seq_;
    patchSeq(message, seq);
    if (newest_.size() <= camera) {
      newest_.resize(camera + 1);
    }
    newest_[camera] = {seq, std::make_shared<const std::vector<std::byte>>(std::move(message))};
    received_[seq % received_.size()] = {seq, receivedNs, false};
    ++published_;
  }
  notify();
}

void LiveFeed::publishModel(std::vector<std::byte> message) {
  {
    const std::lock_guard lock(mutex_);
    const std::uint32_t seq = ++seq_;
    patchSeq(message, seq);
    model_ = FeedFrame{seq, std::make_shared<const std::vector<std::byte>>(std::move(message))};
  }
  notify();
}

void LiveFeed::setStatus(const nlohmann::json& status) {
  {
    const std::lock_guard lock(mutex_);
    status_ = status;
  }
  notify();
}

std::vector<Control> LiveFeed::takeControls() {
  const std::lock_guard lock(mutex_);
  std::vector<Control> out(std::make_move_iterator(controls_.begin()),
                           std::make_move_iterator(controls_.end()));
  controls_.clear();
  return out;
}

PageFigures LiveFeed::figures() const {
  const std::lock_guard lock(mutex_);
  PageFigures f;
  f.framesPublished = published_;
  f.framesDrawn = drawnCount_;
  const std::int64_t now = monotonicNs();
  const auto recent =
      std::ranges::count_if(drawnNs_, [now](std::int64_t t) { return now - t <= kDrawnWindowNs; });
  f.drawnPerSecond = static_cast<double>(recent) * 1e9 / static_cast<double>(kDrawnWindowNs);
  if (drawnCount_ >= 2 && lastDrawnNs_ > firstDrawnNs_) {
    f.drawnPerSecondRun = static_cast<double>(drawnCount_ - 1) * 1e9 /
                          static_cast<double>(lastDrawnNs_ - firstDrawnNs_);
  }
  double sum = 0.0;
  for (const double ms : latencyMs_) {
    sum += ms;
  }
  f.latencySamples = latencyMs_.size();
  f.latencyMeanMs = latencyMs_.empty() ? 0.0 : sum / static_cast<double>(latencyMs_.size());
  f.latencyP95Ms = percentile(latencyMs_, 0.95);
  return f;
}

std::string LiveFeed::sessionText() const {
  const std::lock_guard lock(mutex_);
  return session_;
}

std::vector<Message> LiveFeed::staticMessages() const {
  const std::lock_guard lock(mutex_);
  return static_;
}

std::optional<FeedFrame> LiveFeed::nextFrame(const std::vector<std::uint32_t>& sent) const {
  const std::lock_guard lock(mutex_);
  std::optional<FeedFrame> best;
  std::uint32_t bestSent = 0;
  for (std::size_t c = 0; c < newest_.size(); ++c) {
    const std::uint32_t last = c < sent.size() ? sent[c] : 0;
    const FeedFrame& f = newest_[c];
    if (f.message && f.seq > last && (!best || last < bestSent)) {
      best = f;
      bestSent = last;
    }
  }
  return best;
}

std::optional<FeedFrame> LiveFeed::model() const {
  const std::lock_guard lock(mutex_);
  return model_;
}

std::string LiveFeed::statusText() const {
  const PageFigures f = figures();
  nlohmann::json page{{"frames_published", f.framesPublished},
                      {"frames_drawn", f.framesDrawn},
                      {"drawn_per_s", f.drawnPerSecond},
                      {"latency_ms", {{"mean", f.latencyMeanMs}, {"p95", f.latencyP95Ms}}}};
  const std::lock_guard lock(mutex_);
  nlohmann::json out = status_;
  out["type"] = "status";
  out["page"] = std::move(page);
  return out.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void LiveFeed::drawn(std::uint32_t seq, std::int64_t nowNs, std::int64_t pageSinceNs) {
  const std::lock_guard lock(mutex_);
  Received& r = received_[seq % received_.size()];
  if (r.seq != seq || r.drawn || seq == 0) {
    return;
  }
  r.drawn = true;
  if (drawnCount_++ == 0) {
    firstDrawnNs_ = nowNs;
  }
  lastDrawnNs_ = nowNs;
  if (r.ns >= pageSinceNs && latencyMs_.size() < kMaxLatencySamples) {
    latencyMs_.push_back(static_cast<double>(nowNs - r.ns) / 1e6);
  }
  drawnNs_.push_back(nowNs);
  while (!drawnNs_.empty() && nowNs - drawnNs_.front() > kDrawnWindowNs) {
    drawnNs_.pop_front();
  }
}

bool LiveFeed::pushControl(Control control) {
  {
    const std::lock_guard lock(mutex_);
    if (controls_.size() >= kMaxControls) {
      return false;
    }
    controls_.push_back(std::move(control));
  }
  return true;
}

void LiveFeed::setNotifier(std::function<void()> notify) {
  const std::lock_guard lock(mutex_);
  notify_ = std::move(notify);
}

void LiveFeed::notify() {
  std::function<void()> n;
  {
    const std::lock_guard lock(mutex_);
    n = notify_;
  }
  if (n) {
    n();
  }
}

}  // namespace smx::view
