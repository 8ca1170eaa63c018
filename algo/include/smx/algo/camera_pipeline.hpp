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
#include "smx/algo/depth_trust.hpp"
#include "smx/algo/depth_window.hpp"
#include "smx/algo/error.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/algo/jobs.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/algo/rig.hpp"
#include "smx/algo/stripe_decode.hpp"
#include "smx/algo/triangulation.hpp"

// One camera's frame through the whole pipeline (docs/decode.md): orientation demultiplexing →
// per projector multi-layer decoding → triangulation, the trust filter and the depth-edge filter →
// merging of the projectors' range images (consistency vote, then the paper's median-variant
// filter), with a confidence per merged depth. Per frame integer-only and
// allocation-free; all memory is carved from one arena at create().
//
// Within a frame, projectors' boundaries are detected, decoded and triangulated on up to `lanes`
// threads at once (a lane is one decoder's memory, one scratch depth plane and the boundary
// detector's strength planes) and the merge is cut into bands of rows:
// given a JobRunner, the stages hand it those parts. The planes are the same for any lanes and
// any runner (PipelineSchedule.LanesAndBands* compares them).
namespace smx::algo {

// Where the rig predicts the pattern directions when nothing says otherwise (a board, the CLI).
inline constexpr double kDefaultNominalDepthM = 0.9;

struct PipelineOptions {
  double nominalDepthM = kDefaultNominalDepthM;  // where the rig predicts the pattern directions
  double depthUnitM = kDefaultDepthUnitM;
  DemuxParams demux;
  DecodeParams decode;
  int edgeJumpPermille = 20;  // depth-edge filter of each pair's range image (0: off)
  // Per pair: which depths to trust (depth_trust.hpp); its tolerance's minUnits is set from
  // kGrossToleranceM and depthUnitM by prepareCameraPipeline.
  DepthTrustParams trust;
  // The owner's window on the merged depth (docs/config.md); the defaults keep everything.
  double minDepthM = 0.0;
  double maxDepthM = 1e9;
  int minConfidence = 1;  // 1…255
  int lanes = 1;          // projectors decoded at once (1…3), each lane with its own decoder
};

// Init time (double, allocates): the tables the pipeline needs, computed from the rig.
struct CameraPipelineSetup {
  DemuxLayout layout;
  DecodeParams decode;
  int edgeJumpPermille = 20;
  int lanes = 1;
  DepthTrustParams trust;
  double depthUnitM = kDefaultDepthUnitM;
  DepthWindow window;
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

  // The stages in order (run() calls all four); separate so that callers can time them. Those
  // given a JobRunner hand it their independent parts; without one they run on the caller.
  [[nodiscard]] Result<void> demultiplex(ConstRgbView image, JobRunner& jobs);
  [[nodiscard]] Result<void> decode(JobRunner& jobs);
  [[nodiscard]] Result<void> triangulate(JobRunner& jobs);
  [[nodiscard]] Result<void> merge(JobRunner& jobs);
  [[nodiscard]] Result<void> run(ConstRgbView image, JobRunner& jobs);
  [[nodiscard]] Result<void> demultiplex(ConstRgbView image);
  [[nodiscard]] Result<void> decode();
  [[nodiscard]] Result<void> triangulate();
  [[nodiscard]] Result<void> merge();
  [[nodiscard]] Result<void> run(ConstRgbView image);

  // Every stage after demultiplexing as its plain scalar definition instead of its schedule:
  // the same output bit for bit (PipelineSchedule.* compares them), for tests and benchmarks.
  void useReferenceKernels(bool on);

  [[nodiscard]] int projectors() const { return layout_.projectors; }
  [[nodiscard]] int lanes() const { return lanes_; }
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
  // Per-pixel confidence of depth(projector): 0 = no depth; 1…255 (depth_trust.hpp).
  [[nodiscard]] ImageView<const std::uint8_t> confidence(int projector) const;
  // Per-pixel confidence of merged(): 0 = no depth; 1…255 as documented in docs/decode.md.
  [[nodiscard]] ImageView<const std::uint8_t> confidence() const;

 private:
  CameraPipeline() = default;
  template <class Carver>
  [[nodiscard]] Result<void> carve(Carver& carver);
  [[nodiscard]] Result<void> decodeProjector(int projector, StripeDecoder& decoder);
  [[nodiscard]] Result<void> triangulateProjector(int projector, DepthPlane scratch);
  // Runs perProjector(p, lane) for every projector on the lanes, lane l taking l, l + lanes, …
  template <class PerProjector>
  [[nodiscard]] Result<void> onLanes(JobRunner& jobs, const PerProjector& perProjector);

  DemuxLayout layout_;
  int edgeJumpPermille_ = 0;
  DepthTrustParams trust_;
  DepthWindow window_;
  bool reference_ = false;
  int lanes_ = 1;
  std::optional<Demultiplexer> demux_;
  std::array<std::optional<StripeDecoder>, kMaxProjectors> decoders_;  // one per lane
  std::array<std::optional<Triangulator>, kMaxProjectors> triangulators_;
  std::array<StripePlane, kMaxProjectors> stripes_;
  std::array<ImageView<std::int16_t>, kMaxProjectors> levels_;
  std::array<DecodeStats, kMaxProjectors> stats_;
  std::array<DepthPlane, kMaxProjectors> depths_;
  std::array<ImageView<std::uint8_t>, kMaxProjectors> confidences_;
  DepthPlane merged_;                               // also lane 0's scratch before merge()
  std::array<DepthPlane, kMaxProjectors> scratch_;  // lane l's unfiltered range image (l ≥ 1)
  ImageView<std::uint8_t> mergedConfidence_;
};

}  // namespace smx::algo
