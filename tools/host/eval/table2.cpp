#include "smx/eval/table2.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "smx/algo/arena.hpp"
#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/lens.hpp"
#include "smx/eval/depth_eval.hpp"
#include "smx/eval/sim_frame.hpp"

namespace smx::eval {

namespace {

using Vec = Eigen::Vector3d;

std::array<double, 3> toArray(const Vec& v) {
  return {v.x(), v.y(), v.z()};
}

// Station i's direction from the sphere centre: a regular tetrahedron with station 0 towards −z
// (so camera 0 sits at the world origin looking +z, like cam0 of the example rigs) and stations
// 1..3 at 109.47° from it, 120° apart around the z axis (station 1 below, y down).
Vec stationDirection(int station) {
  if (station == 0) {
    return {0.0, 0.0, -1.0};
  }
  const double s = std::sqrt(8.0 / 9.0);
  const double phi = (90.0 + 120.0 * (station - 1)) * std::numbers::pi / 180.0;
  return {s * std::cos(phi), s * std::sin(phi), 1.0 / 3.0};
}

// The station's tangent frame (x, y), in which Table2Geometry::baselineAngleDeg is measured:
// x = up × d (up = −y, or +x for a station straight above or below), y = d × x.
std::pair<Vec, Vec> tangentFrame(const Vec& d) {
  const Vec up = std::abs(d.y()) < 0.9 ? Vec(0.0, -1.0, 0.0) : Vec(1.0, 0.0, 0.0);
  const Vec x = up.cross(d).normalized();
  return {x, d.cross(x)};
}

// Rows of R (device x, y, z in world coordinates) for a device at `eye` aimed at `aim`:
// with `along` (a world direction), the device x axis is `along` as seen at the principal point;
// without, the device is level (x horizontal).
std::array<Vec, 3> lookAt(const Vec& eye, const Vec& aim, std::optional<Vec> along) {
  const Vec z = (aim - eye).normalized();
  Vec x = Vec(0.0, 1.0, 0.0).cross(z).normalized();
  if (along) {
    x = (*along - z * along->dot(z)).normalized();
  }
  return {x, z.cross(x), z};
}

template <class Device>
void place(Device& device, const Vec& centre, const std::array<Vec, 3>& rows) {
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      device.R[3 * r + c] = rows[r][static_cast<Eigen::Index>(c)];
    }
    device.t[r] = -rows[r].dot(centre);
  }
}

// World point seen at camera pixel (x, y) at depth z (camera frame); nullopt where the lens model
// cannot be inverted.
std::optional<Vec> worldPoint(const algo::Camera& cam, int x, int y, double zM) {
  const auto local =
      algo::lens::devicePoint(cam, {static_cast<double>(x), static_cast<double>(y)}, zM);
  if (!local) {
    return std::nullopt;
  }
  const auto w = algo::lens::toWorld(cam, *local);
  return Vec(w[0], w[1], w[2]);
}

bool onSurface(float zTruth) {
  return std::isfinite(zTruth) && zTruth > 0.0F;
}

struct PaperValue {
  Table2Config config;
  double amount;
  double completeness;
};

// Table 2 of the paper (percent → fractions).
constexpr std::array<PaperValue, 8> kPaper = {{
    {{1, 1}, 0.28, 0.28},
    {{1, 2}, 0.54, 0.32},
    {{2, 1}, 0.54, 0.32},
    {{2, 2}, 1.02, 0.56},
    {{3, 1}, 0.79, 0.36},
    {{3, 2}, 1.44, 0.63},
    {{3, 3}, 1.98, 0.81},
    {{4, 4}, 2.84, 1.00},
}};

PaperValue paperValue(const Table2Config& c) {
  for (const auto& v : kPaper) {
    if (v.config.projectors == c.projectors && v.config.cameras == c.cameras) {
      return v;
    }
  }
  return {c, std::nan(""), std::nan("")};
}

// The projectors a camera decodes: those lighting its view of the sphere, the (at most
// kMaxProjectors) brightest by lit area, in rig order.
std::vector<int> chooseProjectors(const std::vector<int>& litPixels) {
  std::vector<int> order;
  for (std::size_t p = 0; p < litPixels.size(); ++p) {
    if (litPixels[p] > 0) {
      order.push_back(static_cast<int>(p));
    }
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return litPixels[static_cast<std::size_t>(a)] > litPixels[static_cast<std::size_t>(b)];
  });
  if (order.size() > static_cast<std::size_t>(algo::kMaxProjectors)) {
    order.resize(static_cast<std::size_t>(algo::kMaxProjectors));
  }
  std::sort(order.begin(), order.end());
  return order;
}

Table2Row measureConfig(const Table2Config& config, const Table2Options& options) {
  const auto start = std::chrono::steady_clock::now();
  const Table2Geometry& g = options.geometry;
  const algo::Rig rig = table2Rig(config.projectors, config.cameras, g);
  const sim::Scene scene = table2Scene(g);
  const auto c = table2Centre(g);
  const Vec centre(c[0], c[1], c[2]);
  SphereCoverage measured = SphereCoverage::forBinArea(g.sphereRadiusM, options.binAreaM2);
  SphereCoverage geometric = SphereCoverage::forBinArea(g.sphereRadiusM, options.binAreaM2);

  Table2Row row;
  row.projectors = config.projectors;
  row.cameras = config.cameras;
  const PaperValue paper = paperValue(config);
  row.paperAmount = paper.amount;
  row.paperCompleteness = paper.completeness;

  for (int camera = 0; camera < config.cameras; ++camera) {
    SimRequest request;
    request.camera = camera;
    request.seed = options.seed + static_cast<std::uint64_t>(camera);
    request.supersampling = options.supersampling;
    const SimFrame f = renderSimFrame(rig, scene, request);
    const algo::Camera& cam = rig.cameras[static_cast<std::size_t>(camera)];

    // Truth: which projectors light this camera's view of the sphere, and what the geometry
    // allows (seen by the camera and lit by any projector).
    std::vector<int> litPixels(rig.projectors.size(), 0);
    for (int y = 0; y < cam.height; ++y) {
      for (int x = 0; x < cam.width; ++x) {
        const float zTruth = f.depth.at(x, y);
        if (!onSurface(zTruth)) {
          continue;
        }
        bool anyLit = false;
        for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
          if (f.lit[p].at(x, y) != 0) {
            ++litPixels[p];
            anyLit = true;
          }
        }
        if (anyLit) {
          if (const auto w = worldPoint(cam, x, y, zTruth)) {
            geometric.add(toArray(*w - centre));
          }
        }
      }
    }

    const std::vector<int> chosen = chooseProjectors(litPixels);
    std::vector<int> dropped;
    for (std::size_t p = 0; p < litPixels.size(); ++p) {
      if (litPixels[p] > 0 &&
          std::find(chosen.begin(), chosen.end(), static_cast<int>(p)) == chosen.end()) {
        dropped.push_back(static_cast<int>(p));
      }
    }
    row.decoded.push_back(chosen);
    row.dropped.push_back(dropped);
    if (chosen.empty()) {
      continue;
    }

    // The pipeline's rig: this camera and the projectors it decodes (the image holds them all).
    algo::Rig subRig;
    subRig.cameras = {cam};
    for (const int p : chosen) {
      subRig.projectors.push_back(rig.projectors[static_cast<std::size_t>(p)]);
    }
    algo::PipelineOptions pipelineOptions;
    pipelineOptions.nominalDepthM = g.stationDistanceM;
    const auto setup = algo::prepareCameraPipeline(subRig, 0, pipelineOptions);
    if (!setup) {
      throw std::runtime_error("table 2: camera " + std::to_string(camera) + ": " + setup.error());
    }
    const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
    if (!bytes) {
      throw std::runtime_error(std::string("table 2: workspace: ") + bytes.error().message);
    }
    std::vector<std::byte> memory(*bytes);
    algo::Arena arena(memory);
    auto pipeline = algo::CameraPipeline::create(*setup, arena);
    if (!pipeline) {
      throw std::runtime_error(std::string("table 2: pipeline: ") + pipeline.error().message);
    }
    if (auto ok = pipeline->run(f.image.view()); !ok) {
      throw std::runtime_error(std::string("table 2: run: ") + ok.error().message);
    }

    for (std::size_t q = 0; q < chosen.size(); ++q) {
      const int p = chosen[q];
      Table2Pair pair;
      pair.camera = camera;
      pair.projector = p;
      pair.litPixels = litPixels[static_cast<std::size_t>(p)];
      const algo::ConstDepthPlane depth = pipeline->depth(static_cast<int>(q));
      for (int y = 0; y < depth.height(); ++y) {
        for (int x = 0; x < depth.width(); ++x) {
          const std::uint16_t units = depth(x, y);
          if (units == algo::kNoDepth) {
            continue;
          }
          ++pair.valid;
          const double zM = units * setup->depthUnitM;
          const float zTruth = f.depth.at(x, y);
          if (!onSurface(zTruth) || isGrossError(zM, zTruth)) {
            ++pair.gross;
            continue;
          }
          if (const auto w = worldPoint(cam, x, y, zM)) {
            measured.add(toArray(*w - centre));
          }
        }
      }
      row.validPixels += pair.valid;
      row.grossPixels += pair.gross;
      row.pairs.push_back(pair);
    }
  }
  row.completeness = measured.fraction();
  row.geometricCompleteness = geometric.fraction();
  row.grossRate = row.validPixels > 0 ? static_cast<double>(row.grossPixels) / row.validPixels : 0;
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

int inliers(const Table2Row& row) {
  int n = 0;
  for (const auto& p : row.pairs) {
    n += p.inliers();
  }
  return n;
}

}  // namespace

std::array<double, 3> table2Centre(const Table2Geometry& g) {
  return {0.0, 0.0, g.stationDistanceM};
}

algo::Rig table2Rig(int projectors, int cameras, const Table2Geometry& g) {
  if (projectors < 1 || projectors > kTable2Stations || cameras < 1 || cameras > kTable2Stations) {
    throw std::invalid_argument("table2Rig: 1..4 projectors and 1..4 cameras");
  }
  const auto c = table2Centre(g);
  const Vec centre(c[0], c[1], c[2]);
  algo::Rig rig;
  for (int i = 0; i < kTable2Stations; ++i) {
    const Vec d = stationDirection(i);
    const auto [tx, ty] = tangentFrame(d);
    const double a = g.baselineAngleDeg[static_cast<std::size_t>(i)] * std::numbers::pi / 180.0;
    const Vec baseline = tx * std::cos(a) + ty * std::sin(a);
    const Vec camCentre = centre + d * g.stationDistanceM;
    const Vec projCentre = camCentre + baseline * g.baselineM + d * g.setbackM;
    const std::string n = std::to_string(i);
    if (i < cameras) {
      algo::Camera cam;
      cam.id = "cam" + n;
      cam.width = 640;
      cam.height = 480;
      cam.K = {800.0, 0.0, 319.5, 0.0, 800.0, 239.5, 0.0, 0.0, 1.0};
      cam.dist = {-0.08, 0.05, 0.0, 0.0, 0.0};
      place(cam, camCentre, lookAt(camCentre, centre, std::nullopt));
      rig.cameras.push_back(cam);
    }
    if (i < projectors) {
      algo::Projector proj;
      proj.id = "proj" + n;
      proj.width = 1024;
      proj.height = 768;
      proj.K = {1400.0, 0.0, 511.5, 0.0, 1400.0, 383.5, 0.0, 0.0, 1.0};
      proj.dist = {};
      // Pattern axis (angle 0 = device x) along the baseline to this station's camera.
      place(proj, projCentre, lookAt(projCentre, centre, Vec(projCentre - camCentre)));
      proj.pattern = {0.0, g.stripePx, 0.0};
      rig.projectors.push_back(proj);
    }
  }
  return rig;
}

sim::Scene table2Scene(const Table2Geometry& g) {
  sim::Scene scene;
  sim::Object ball;
  ball.name = "ball";
  ball.shape = sim::Sphere{g.sphereRadiusM};
  const auto c = table2Centre(g);
  ball.pose.t = sim::Vec3(c[0], c[1], c[2]);
  ball.albedo.rgb = sim::Vec3(0.85, 0.85, 0.85);
  scene.objects.push_back(ball);
  scene.lighting.projectorPower = 0.4;
  return scene;
}

SphereCoverage::SphereCoverage(int cosBins, int phiBins)
    : cosBins_(std::max(cosBins, 1)),
      phiBins_(std::max(phiBins, 1)),
      hit_(static_cast<std::size_t>(cosBins_) * static_cast<std::size_t>(phiBins_), 0) {}

SphereCoverage SphereCoverage::forBinArea(double radiusM, double binAreaM2) {
  // n·m bins of 4πr²/(n·m); square at the equator when the band height 2r/n equals the sector
  // width 2πr/m, i.e. m = π·n.
  const double bins = 4.0 * std::numbers::pi * radiusM * radiusM / binAreaM2;
  const int n = std::max(1, static_cast<int>(std::lround(std::sqrt(bins / std::numbers::pi))));
  const int m = std::max(1, static_cast<int>(std::lround(std::numbers::pi * n)));
  return {n, m};
}

void SphereCoverage::add(const std::array<double, 3>& direction) {
  const double len = Vec(direction[0], direction[1], direction[2]).norm();
  if (!(len > 0.0) || !std::isfinite(len)) {
    return;
  }
  const double cosTheta = std::clamp(direction[1] / len, -1.0, 1.0);
  const double phi = std::atan2(direction[2], direction[0]) + std::numbers::pi;  // [0, 2π]
  const int band = std::clamp(static_cast<int>((cosTheta + 1.0) * 0.5 * cosBins_), 0, cosBins_ - 1);
  const int sector =
      std::clamp(static_cast<int>(phi / (2.0 * std::numbers::pi) * phiBins_), 0, phiBins_ - 1);
  hit_[static_cast<std::size_t>(band) * static_cast<std::size_t>(phiBins_) +
       static_cast<std::size_t>(sector)] = 1;
}

int SphereCoverage::covered() const {
  return static_cast<int>(std::count(hit_.begin(), hit_.end(), std::uint8_t{1}));
}

double SphereCoverage::fraction() const {
  return static_cast<double>(covered()) / bins();
}

const std::vector<Table2Config>& table2PaperConfigs() {
  static const std::vector<Table2Config> kConfigs = [] {
    std::vector<Table2Config> c;
    c.reserve(kPaper.size());
    for (const auto& v : kPaper) {
      c.push_back(v.config);
    }
    return c;
  }();
  return kConfigs;
}

std::vector<Table2Row> measureTable2(const Table2Options& options) {
  const Table2Row base = measureConfig({1, 1}, options);
  const int baseInliers = inliers(base);
  std::vector<Table2Row> rows;
  for (const auto& config : options.configs) {
    Table2Row row =
        (config.projectors == 1 && config.cameras == 1) ? base : measureConfig(config, options);
    row.amount = baseInliers > 0 ? static_cast<double>(inliers(row)) / baseInliers : 0.0;
    row.amountPaperUnit = row.amount * base.completeness;
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string formatTable2(const std::vector<Table2Row>& rows) {
  std::ostringstream out;
  std::array<char, 256> line{};
  std::snprintf(line.data(), line.size(), "%-5s %9s %22s %31s %8s %7s %6s  %s\n", "P C", "x 1P1C",
                "amount % meas (paper)", "completeness % meas/geom (paper)", "valid", "gross",
                "gross%", "decoded per camera (-dropped)");
  out << line.data();
  for (const auto& r : rows) {
    std::string decoded;
    for (std::size_t c = 0; c < r.decoded.size(); ++c) {
      decoded += (c != 0 ? " cam" : "cam") + std::to_string(c) + ":";
      for (const int p : r.decoded[c]) {
        decoded += "p" + std::to_string(p);
      }
      if (!r.dropped[c].empty()) {
        decoded += "(-";
        for (const int p : r.dropped[c]) {
          decoded += "p" + std::to_string(p);
        }
        decoded += ")";
      }
    }
    std::snprintf(line.data(), line.size(),
                  "%dP%dC  %9.2f %15.0f (%4.0f) %20.0f/%3.0f (%4.0f) %8d %7d %6.2f  %s\n",
                  r.projectors, r.cameras, r.amount, 100.0 * r.amountPaperUnit,
                  100.0 * r.paperAmount, 100.0 * r.completeness, 100.0 * r.geometricCompleteness,
                  100.0 * r.paperCompleteness, r.validPixels, r.grossPixels, 100.0 * r.grossRate,
                  decoded.c_str());
    out << line.data();
  }
  return out.str();
}

}  // namespace smx::eval
