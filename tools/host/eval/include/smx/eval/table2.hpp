#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/sim/scene.hpp"

// Evaluation (stripemux eval): the paper's Table 2 (§5) measured instead of modelled. An object
// topologically like a sphere is scanned by 1–4 projectors and 1–4 cameras placed around it; the
// simulator renders every camera with all of the configuration's projectors on (their patterns
// superposed) and the real per-camera pipeline decodes it.
//
// Definitions (as in the paper, made measurable):
//   relative amount        Σ over decoded projector–camera pairs of the pair's inlier pixels
//                          (depth ≠ 0 and not a gross error against the truth, isGrossError),
//                          divided by that sum of the 1-projector-1-camera configuration;
//                          the paper's unit is instead one scan of the whole sphere (its 1P1C
//                          amount equals its 1P1C completeness, 28 %), so amountPaperUnit =
//                          amount × the measured 1P1C completeness is the value to compare;
//   relative completeness  the fraction of the sphere's surface on which some inlier lands:
//                          every inlier pixel (any pair, any camera) is back-projected to a world
//                          point, its direction from the sphere centre binned on an equal-area
//                          grid (SphereCoverage), completeness = covered bins / all bins;
//   geometric completeness the same from the truth: bins holding a surface point that a camera
//                          sees and at least one of the configuration's projectors lights. An
//                          upper bound on what any decoder could deliver in that layout.
//
// Layout (table2Rig): four stations at the vertices of a regular tetrahedron around the sphere
// (the fewest that see all of a sphere: every surface point is within 70.5° of a station); station
// i holds camera i and projector i. Configuration nPmC uses the projectors of stations 0..n−1 and
// the cameras of stations 0..m−1, so cross-station pairs (camera i, projector j ≠ i) triangulate
// across ~110° where the two stations' views of the sphere overlap. They see that overlap near
// both limbs, obliquely, and usually off their epipolar alignment: most deliver little or nothing
// (Table2Row::pairs says which); the own-station pairs carry the table.
//
// A camera pipeline decodes at most kMaxProjectors = 3 patterns. A camera that sees more (only in
// 4P4C: its own projector and the three others) decodes the three that light the most of its view
// of the sphere (truth lit planes); the dropped one is missing from Table2Row::decoded and its
// light stays in the image as an undecoded pattern.
namespace smx::eval {

inline constexpr int kTable2Stations = 4;

struct Table2Geometry {
  double sphereRadiusM = 0.15;
  double stationDistanceM = 0.9;  // camera centre to sphere centre
  double baselineM = 0.35;        // camera to projector within a station, across the view
  double setbackM = 0.10;         // projector behind its camera, along the station direction
  // Projector stripe width. Wider than the example rigs' 6 px: on the sphere most of a view is
  // oblique and foreshortens the stripes (8 px: 1P1C completeness 31 % instead of 28 %, gross
  // rate 0.2 % instead of 1 %). 198 stripes span 1584 px, more than the projector is wide, but the
  // sphere covers only the central ~480 px.
  double stripePx = 8.0;
  // Direction of each station's baseline (and so of its projector's pattern axis), in degrees in
  // the station's tangent frame (x = up × d, y = d × x for the station direction d from the
  // centre, up = −y). No choice serves every pair: a projector's axis can lie along at most one of
  // the epipolar directions to the other three cameras. These values came from a coordinate
  // search over 30° steps of the measured table (Σ amount/3 + 2·Σ completeness − Σ gross rate);
  // the last station's angle barely matters (±0.5 % of that score).
  std::array<double, kTable2Stations> baselineAngleDeg = {0.0, 0.0, 80.0, 30.0};
};

// Sphere centre in the world frame (camera 0's frame: camera 0 sits at the origin looking +z).
[[nodiscard]] std::array<double, 3> table2Centre(const Table2Geometry& g = {});

// The rig of configuration `projectors`P`cameras`C (1 ≤ each ≤ 4). Cameras 640×480, f 800 px with
// the example rigs' distortion; projectors 1024×768, f 1400 px; every device aimed at the sphere
// centre; projector i's pattern axis along its baseline to camera i. Throws std::invalid_argument
// on counts outside 1..4.
[[nodiscard]] algo::Rig table2Rig(int projectors, int cameras, const Table2Geometry& g = {});

// The sphere (albedo 0.85, projector power 0.4, as hal/sim/scenes/sphere.json) and nothing else.
[[nodiscard]] sim::Scene table2Scene(const Table2Geometry& g = {});

// Equal-area bins over the directions of the unit sphere: cosBins bands uniform in cos θ (θ from
// world +y) × phiBins sectors uniform in φ; every bin is 4π / (cosBins·phiBins) sr.
class SphereCoverage {
 public:
  SphereCoverage(int cosBins, int phiBins);
  // Bins of about binAreaM2 on a sphere of radiusM, near-square at the equator.
  [[nodiscard]] static SphereCoverage forBinArea(double radiusM, double binAreaM2);

  void add(const std::array<double, 3>& direction);  // any length > 0; others ignored
  [[nodiscard]] int bins() const { return cosBins_ * phiBins_; }
  [[nodiscard]] int covered() const;
  [[nodiscard]] double fraction() const;
  [[nodiscard]] int cosBins() const { return cosBins_; }
  [[nodiscard]] int phiBins() const { return phiBins_; }

 private:
  int cosBins_;
  int phiBins_;
  std::vector<std::uint8_t> hit_;
};

inline constexpr double kTable2BinAreaM2 = 1.5e-4;  // 1.5 cm²: ≥ 100 face-on camera pixels

struct Table2Pair {
  int camera = 0;
  int projector = 0;  // rig projector (station) index
  int litPixels = 0;  // camera pixels on the sphere this projector lights (truth)
  int valid = 0;      // depth ≠ 0
  int gross = 0;      // of them: gross errors or no surface at all
  [[nodiscard]] int inliers() const { return valid - gross; }
};

struct Table2Row {
  int projectors = 0;
  int cameras = 0;
  double amount = 0;                 // relative amount of 3D data (1 = the 1P1C value)
  double amountPaperUnit = 0;        // amount × measured 1P1C completeness (header comment)
  double completeness = 0;           // measured relative completeness, 0..1
  double geometricCompleteness = 0;  // upper bound from the truth, 0..1
  double paperAmount = 0;            // Table 2's modelled values, fractions
  double paperCompleteness = 0;
  int validPixels = 0;  // over all decoded pairs
  int grossPixels = 0;
  double grossRate = 0;
  std::vector<std::vector<int>> decoded;  // per camera: the projectors its pipeline decoded
  std::vector<std::vector<int>> dropped;  // per camera: projectors lit in its view, not decoded
  std::vector<Table2Pair> pairs;
  double seconds = 0;  // render + pipeline + scoring of the row
};

struct Table2Config {
  int projectors = 1;
  int cameras = 1;
};

// The paper's rows, in its order.
[[nodiscard]] const std::vector<Table2Config>& table2PaperConfigs();

struct Table2Options {
  Table2Geometry geometry;
  std::vector<Table2Config> configs = table2PaperConfigs();  // 1P1C is measured in any case
  double binAreaM2 = kTable2BinAreaM2;
  std::uint64_t seed = 1;
  int supersampling = 0;  // samples per pixel side; 0: the scene's own
};

// One row per requested configuration, in the requested order. Throws std::runtime_error when a
// render or a pipeline setup fails.
[[nodiscard]] std::vector<Table2Row> measureTable2(const Table2Options& options = {});

// The rows as a text table, measured next to modelled values (percent).
[[nodiscard]] std::string formatTable2(const std::vector<Table2Row>& rows);

}  // namespace smx::eval
