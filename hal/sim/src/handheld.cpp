#include "smx/sim/handheld.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>

namespace smx::sim {
namespace {

struct Sinusoid {
  double amplitude = 0.0;
  double radPerFrame = 0.0;
  double phase = 0.0;
};

// Six axes (translation x, y, z in metres; rotation vector x, y, z in radians).
using JitterTerms = std::array<std::array<Sinusoid, kHandheldJitterTerms>, 6>;

// A uniform double in [0, 1) from mt19937_64's 64 bits: the same on every standard library
// (std::uniform_real_distribution is not).
double unit(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11U) * 0x1.0p-53;
}

JitterTerms jitterTerms(const Handheld& h) {
  std::mt19937_64 rng(h.seed);
  JitterTerms terms{};
  constexpr double kTerms = kHandheldJitterTerms;
  // Equal amplitudes: per axis mean square K·a²/2, over three axes 3·K·a²/2 = rms².
  const double perAxis = std::sqrt(2.0 / (3.0 * kTerms));
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t axis = 0; axis < terms.size(); ++axis) {
    const double rms = axis < 3 ? h.jitterMm * 1e-3 : h.jitterDeg * deg;
    for (std::size_t k = 0; k < terms[axis].size(); ++k) {
      // One frequency per band ((k + u) / K of jitterHz, u in [0.25, 1)): no two terms beat
      // slowly, so the RMS over a loop stays close to the long-time one.
      const double hz = h.jitterHz * (static_cast<double>(k) + 0.25 + 0.75 * unit(rng)) / kTerms;
      terms[axis][k] = {rms * perAxis, 2.0 * std::numbers::pi * hz / h.fps,
                        2.0 * std::numbers::pi * unit(rng)};
    }
  }
  return terms;
}

}  // namespace

Eigen::Isometry3d handheldJitter(const Handheld& handheld, double frameTime) {
  const JitterTerms terms = jitterTerms(handheld);
  std::array<double, 6> v{};
  for (std::size_t axis = 0; axis < terms.size(); ++axis) {
    for (const Sinusoid& s : terms[axis]) {
      v[axis] += s.amplitude * std::sin(s.radPerFrame * frameTime + s.phase);
    }
  }
  const Eigen::Vector3d rotation(v[3], v[4], v[5]);
  Eigen::Isometry3d jitter = Eigen::Isometry3d::Identity();
  const double angle = rotation.norm();
  if (angle > 0.0) {
    jitter.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  }
  jitter.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return jitter;
}

Eigen::Isometry3d handheldRigPose(const Handheld& handheld, double frameTime) {
  const Eigen::Vector3d axis = handheld.axis.normalized();
  const double angle = frameTime * handheld.orbitDegPerFrame * std::numbers::pi / 180.0;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  const double bob =
      handheld.bobM * std::sin(2.0 * std::numbers::pi * frameTime / handheld.bobPeriodFrames);
  Eigen::Isometry3d smooth = Eigen::Isometry3d::Identity();
  smooth.linear() = turn;
  // A turn about the axis through the centre: X ↦ turn·(X − c) + c, then the bob along the axis.
  smooth.translation() = handheld.centre - turn * handheld.centre + bob * axis;
  if (handheld.jitterMm == 0.0 && handheld.jitterDeg == 0.0) {
    return smooth;
  }
  return smooth * handheldJitter(handheld, frameTime);
}

bool handheldOccluded(const Handheld& handheld, double frameTime) {
  const auto& o = handheld.occlusion;
  const double frame = std::floor(frameTime + 0.5);
  return o.frames > 0 && frame >= o.fromFrame &&
         frame < static_cast<double>(o.fromFrame) + static_cast<double>(o.frames);
}

}  // namespace smx::sim
