#include "scene_handheld.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "smx/config/json_paths.hpp"
#include "smx/config/json_text.hpp"

namespace smx::config::detail {
namespace {

using Json = nlohmann::json;

constexpr std::array<std::string_view, 11> kHandheldKeys = {
    "centre",    "axis",       "orbit_deg_per_frame", "bob_m", "bob_period_frames",
    "jitter_mm", "jitter_deg", "jitter_hz",           "fps",   "seed",
    "occlusion"};
constexpr std::array<std::string_view, 3> kOcclusionKeys = {"from_frame", "frames", "distance_m"};

constexpr int kMaxSeed = 2'147'483'647;
constexpr int kMaxFrame = 10'000'000;  // over a week at 15 fps

void vec3(FieldReader& r, const Json& obj, const std::string& path, std::string_view key,
          std::string_view what, Eigen::Vector3d& out) {
  if (const Json* v = r.find(obj, key); v != nullptr) {
    if (const auto a = r.numbers<3>(*v, member(path, key), what, Range::kAny)) {
      out = Eigen::Vector3d((*a)[0], (*a)[1], (*a)[2]);
    }
  }
}

// lo ≤ d ≤ hi, with the unit or meaning in `what`.
void checkBetween(FieldReader& r, double d, const std::string& path, double lo, double hi) {
  if (r.check(d, path, Range::kAny) && (d < lo || d > hi)) {
    r.fail(path, "must be from " + formatNumber(lo) + " to " + formatNumber(hi) + ", got " +
                     formatNumber(d));
  }
}

void readOcclusion(FieldReader& r, const Json& v, const std::string& parent,
                   sim::HandheldOcclusion& out) {
  const std::string path = member(parent, "occlusion");
  const Json* o = r.find(v, "occlusion");
  if (o == nullptr || !r.object(*o, path,
                                R"(a hand over the lenses {"from_frame", "frames", )"
                                R"("distance_m"})",
                                kOcclusionKeys)) {
    return;
  }
  if (r.find(*o, "frames") == nullptr) {
    r.fail(member(path, "frames"),
           "required field is missing; how many frames the hand covers "
           "the lenses, e.g. \"frames\": 15");
    return;
  }
  r.integer(*o, path, "from_frame", 0, kMaxFrame, "the first frame covered", out.fromFrame);
  r.integer(*o, path, "frames", 1, kMaxFrame, "frames covered", out.frames);
  r.number(*o, path, "distance_m", Range::kAny, out.distanceM);
}

}  // namespace

void readHandheld(FieldReader& r, const Json& doc, std::optional<sim::Handheld>& out) {
  const std::string path = "handheld";
  const Json* v = r.find(doc, path);
  if (v == nullptr || !r.object(*v, path, "the rig's hand-held trajectory", kHandheldKeys)) {
    return;
  }
  sim::Handheld h;
  vec3(r, *v, path, "centre", "x, y, z in metres, the world point the rig orbits", h.centre);
  vec3(r, *v, path, "axis", "x, y, z, the direction of the orbit axis", h.axis);
  r.number(*v, path, "orbit_deg_per_frame", Range::kAny, h.orbitDegPerFrame);
  r.number(*v, path, "bob_m", Range::kAny, h.bobM);
  r.number(*v, path, "bob_period_frames", Range::kAny, h.bobPeriodFrames);
  r.number(*v, path, "jitter_mm", Range::kAny, h.jitterMm);
  r.number(*v, path, "jitter_deg", Range::kAny, h.jitterDeg);
  r.number(*v, path, "jitter_hz", Range::kAny, h.jitterHz);
  r.number(*v, path, "fps", Range::kAny, h.fps);
  int seed = static_cast<int>(h.seed);
  r.integer(*v, path, "seed", 0, kMaxSeed, "the jitter's random seed", seed);
  h.seed = static_cast<std::uint32_t>(seed);
  readOcclusion(r, *v, path, h.occlusion);
  if (!r.ok()) {
    return;
  }
  checkHandheld(r, h);
  if (r.ok()) {
    h.axis /= h.axis.stableNorm();
    out = h;
  }
}

void checkHandheld(FieldReader& r, const sim::Handheld& h) {
  const std::string path = "handheld";
  r.checkEach(h.centre, member(path, "centre"), Range::kAny);
  r.checkEach(h.axis, member(path, "axis"), Range::kAny);
  if (r.ok() && !(h.axis.stableNorm() > 0)) {
    r.fail(member(path, "axis"),
           "must not be the zero vector; it is the direction of the orbit "
           "axis, e.g. [0, -1, 0] (up)");
  }
  // A quarter turn per frame is already more than any frame-to-frame registration follows.
  checkBetween(r, h.orbitDegPerFrame, member(path, "orbit_deg_per_frame"), -90.0, 90.0);
  checkBetween(r, h.bobM, member(path, "bob_m"), 0.0, 1.0);
  checkBetween(r, h.bobPeriodFrames, member(path, "bob_period_frames"), 2.0, kMaxFrame);
  checkBetween(r, h.jitterMm, member(path, "jitter_mm"), 0.0, 100.0);
  checkBetween(r, h.jitterDeg, member(path, "jitter_deg"), 0.0, 30.0);
  checkBetween(r, h.fps, member(path, "fps"), 1.0, 1000.0);
  if (r.check(h.jitterHz, member(path, "jitter_hz"), Range::kPositive) &&
      h.jitterHz > h.fps / 2.0) {
    r.fail(member(path, "jitter_hz"), "must be at most half of fps (" + formatNumber(h.fps / 2.0) +
                                          "): faster jitter aliases between frames; got " +
                                          formatNumber(h.jitterHz));
  }
  r.check(static_cast<int>(h.seed), member(path, "seed"), 0, kMaxSeed, "the jitter's random seed");
  const std::string at = member(path, "occlusion");
  const auto& o = h.occlusion;
  if (o.frames == 0) {
    return;  // no occlusion
  }
  r.check(o.fromFrame, member(at, "from_frame"), 0, kMaxFrame, "the first frame covered");
  r.check(o.frames, member(at, "frames"), 1, kMaxFrame, "frames covered");
  // In front of the lenses, nearer than any object a scan looks at.
  checkBetween(r, o.distanceM, member(at, "distance_m"), 0.01, 1.0);
}

}  // namespace smx::config::detail
