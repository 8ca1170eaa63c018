#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include "smx/algo/arena.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/rig.hpp"
#include "smx/algo/stripe_decode.hpp"
#include "smx/algo/triangulation.hpp"

// One camera's frame through the whole pipeline (docs/decode.md): orientation demultiplexing →
// per projector multi-layer decoding → triangulation and the depth-edge filter → merging of the
// projectors' range images (the paper's median-variant filter). Per frame integer-only and
// allocation-free; all memory is carved from one arena at create().
namespace smx::algo {

// Where the rig predicts the pattern directions when nothing says otherwise (a board, the CLI).
inline constexpr double kDefaultNominalDepthM = 0.9;

struct PipelineOptions {
  double nominalDepthM = kDefaultNominalDepthM;  // where the rig predicts the pattern directions
  double depthUnitM = kDefaultDepthUnitM;
  DemuxParams demux;
  DecodeParams decode;
  int edgeJumpPermille = 20;  // depth-edge filter of each pair's range image (0: off)
};

// Init time (double, allocates): the tables the pipeline needs, computed from the rig.
struct CameraPipelineSetup {
  DemuxLayout layout;
  DecodeParams decode;
  int edgeJumpPermille = 20;
  double depthUnitM = kDefaultDepthUnitM;
  std::vector<std::uint16_t> predictedAngles;      // Demultiplexer::create's
  std::vector<TriangulationTables> triangulation;  // per projector
};
[[nodiscard]] std::expected<CameraPipelineSetup, std::string> prepareCameraPipeline(
    const Rig& rig, int camera, const PipelineOptions& options = {});

class CameraPipeline {
 public:
  [[nodiscard]] static Result<std::size_t> workspaceBytes(const CameraPipelineSetup& setup);
  [[nodiscard]] static Result<CameraPipeline> create(const CameraPipelineSetup& setup,
                                                     Arena& arena);

  // The stages in order (run() calls all four); separate so that callers can time them.
  [[nodiscard]] Result<void> demultiplex(ConstRgbView image);
  [[nodiscard]] Result<void> decode();
  [[nodiscard]] Result<void> triangulate();
  [[nodiscard]] Result<void> merge();
  [[nodiscard]] Result<void> run(ConstRgbView image);

  [[nodiscard]] int projectors() const { return layout_.projectors; }
  // create() sets every stage object: a CameraPipeline exists only after it.
  // NOLINTNEXTLINE(bugprone-unchecked-optional-access)
  [[nodiscard]] const Demultiplexer& demux() const { return *demux_; }
  // NOLINTNEXTLINE(bugprone-unchecked-optional-access)
  [[nodiscard]] Demultiplexer& demux() { return *demux_; }
  [[nodiscard]] ConstStripePlane stripe(int projector) const;
  [[nodiscard]] ImageView<const std::int16_t> levels(int projector) const;
  [[nodiscard]] const DecodeStats& decodeStats(int projector) const;
  [[nodiscard]] ConstDepthPlane depth(int projector) const;  // that projector's range image
  [[nodiscard]] ConstDepthPlane merged() const;              // all projectors, merged

 private:
  CameraPipeline() = default;
  template <class Carver>
  [[nodiscard]] Result<void> carve(Carver& carver);

  DemuxLayout layout_;
  int edgeJumpPermille_ = 0;
  std::optional<Demultiplexer> demux_;
  std::optional<StripeDecoder> decoder_;
  std::array<std::optional<Triangulator>, kMaxProjectors> triangulators_;
  std::array<StripePlane, kMaxProjectors> stripes_;
  std::array<ImageView<std::int16_t>, kMaxProjectors> levels_;
  std::array<DecodeStats, kMaxProjectors> stats_;
  std::array<DepthPlane, kMaxProjectors> depths_;
  DepthPlane merged_;
};

}  // namespace smx::algo
