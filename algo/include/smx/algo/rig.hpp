#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

// The rig: cameras and projectors with their calibration, as described by rig.json
// (`stripemux-rig/1`, docs/rig-format.md). Plain data used at init time; the per-frame path only
// sees tables derived from it.
//
// Conventions (OpenCV): x right, y down, z forward; pixel (0,0) is the centre of the top-left
// pixel; extrinsics map world to device, x_dev = R·X + t, in metres.
namespace smx::algo {

struct DeviceModel {
  std::string id;
  int width = 0;
  int height = 0;
  std::array<double, 9> K{};     // row-major [fx 0 cx; 0 fy cy; 0 0 1]
  std::array<double, 5> dist{};  // k1 k2 p1 p2 k3
  std::array<double, 9> R{};     // row-major rotation, world -> device
  std::array<double, 3> t{};     // translation, world -> device, metres

  [[nodiscard]] double fx() const { return K[0]; }
  [[nodiscard]] double fy() const { return K[4]; }
  [[nodiscard]] double cx() const { return K[2]; }
  [[nodiscard]] double cy() const { return K[5]; }
};

// Stripe pattern placement in the projector image. The encoding axis (across the stripes) points
// along (cos a, sin a) in projector pixels (u right, v down), a = angleDeg; stripePx is the stripe
// width along the axis; the sequence is centred on ((width-1)/2, (height-1)/2) shifted by offsetPx
// along the axis. Stripe index grows along +axis.
struct StripePattern {
  double angleDeg = 0.0;
  double stripePx = 0.0;
  double offsetPx = 0.0;
};

struct Camera : DeviceModel {};

struct Projector : DeviceModel {
  StripePattern pattern;
};

// A turntable's axis of rotation in the world frame: a positive angle turns right-handed about
// `axis` (a unit vector) through `point`.
struct TurntableAxis {
  std::array<double, 3> axis{};
  std::array<double, 3> point{};
};

struct Rig {
  std::vector<Camera> cameras;
  std::vector<Projector> projectors;
  std::optional<TurntableAxis> turntable{};  // calibrated, or given by the board's maker
};

}  // namespace smx::algo
