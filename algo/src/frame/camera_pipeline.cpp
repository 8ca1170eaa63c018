// The camera pipeline: the stages' objects and planes carved from one arena at create(), run in
// order per frame.
#include "smx/algo/camera_pipeline.hpp"

#include <cstdint>

#include "smx/algo/depth_edges.hpp"
#include "smx/algo/depth_trust.hpp"
#include "smx/algo/range_merge.hpp"

namespace smx::algo {

namespace {

Result<void> validate(const CameraPipelineSetup& s) {
  if (s.layout.projectors < 1 || s.layout.projectors > kMaxProjectors) {
    return fail(Errc::kInvalidArgument, "pipeline: 1 to 3 projectors");
  }
  if (s.edgeJumpPermille < 0 || s.edgeJumpPermille > 1000) {
    return fail(Errc::kInvalidArgument, "pipeline: edgeJumpPermille 0 to 1000");
  }
  if (auto ok = validateDepthTrust(s.trust); !ok) {
    return ok;
  }
  if (s.triangulation.size() != static_cast<std::size_t>(s.layout.projectors)) {
    return fail(Errc::kSizeMismatch, "pipeline: one triangulation table per projector");
  }
  return {};
}

}  // namespace

template <class Carver>
Result<void> CameraPipeline::carve(Carver& carver) {
  const int w = layout_.width;
  const int h = layout_.height;
  Result<void> ok;
  const auto step = [&ok](Result<void> r) {
    if (ok && !r) {
      ok = r;
    }
  };
  for (int p = 0; p < layout_.projectors; ++p) {
    const auto i = static_cast<std::size_t>(p);
    step(carveImage(carver, stripes_[i], w, h));
    step(carveImage(carver, levels_[i], w, h));
    step(carveImage(carver, depths_[i], w, h));
    step(carveImage(carver, confidences_[i], w, h));
  }
  step(carveImage(carver, merged_, w, h));
  step(carveImage(carver, mergedConfidence_, w, h));
  return ok;
}

Result<std::size_t> CameraPipeline::workspaceBytes(const CameraPipelineSetup& setup) {
  if (auto ok = validate(setup); !ok) {
    return std::unexpected(ok.error());
  }
  const DemuxLayout& l = setup.layout;
  std::size_t total = 0;
  const auto add = [&total](const Result<std::size_t>& bytes) -> Result<void> {
    if (!bytes) {
      return std::unexpected(bytes.error());
    }
    total += *bytes;
    return {};
  };
  Result<void> ok = add(Demultiplexer::workspaceBytes(l));
  ok = ok ? add(StripeDecoder::workspaceBytes(l.width, l.height, setup.decode)) : ok;
  // validate() checked one table per projector; a distorted projector's tables hold per-pixel
  // numerators, so each is sized by its own tables.
  for (int p = 0; ok && p < l.projectors; ++p) {
    ok = add(Triangulator::workspaceBytes(setup.triangulation[static_cast<std::size_t>(p)]));
  }
  CameraPipeline sized;
  sized.layout_ = l;
  ArenaSizer sizer;
  ok = ok ? sized.carve(sizer) : ok;
  if (!ok) {
    return std::unexpected(ok.error());
  }
  return total + sizer.bytes();
}

Result<CameraPipeline> CameraPipeline::create(const CameraPipelineSetup& setup, Arena& arena) {
  if (auto ok = validate(setup); !ok) {
    return std::unexpected(ok.error());
  }
  const Arena::Marker start = arena.mark();
  const auto undo = [&](const Error& e) -> Result<CameraPipeline> {
    arena.rewind(start);
    return std::unexpected(e);
  };
  CameraPipeline c;
  c.layout_ = setup.layout;
  c.edgeJumpPermille_ = setup.edgeJumpPermille;
  c.trust_ = setup.trust;
  c.window_ = setup.window;
  auto demux = Demultiplexer::create(setup.layout, setup.predictedAngles, arena);
  if (!demux) {
    return undo(demux.error());
  }
  c.demux_.emplace(*demux);
  auto decoder =
      StripeDecoder::create(setup.layout.width, setup.layout.height, setup.decode, arena);
  if (!decoder) {
    return undo(decoder.error());
  }
  c.decoder_.emplace(*decoder);
  for (int p = 0; p < setup.layout.projectors; ++p) {
    const auto i = static_cast<std::size_t>(p);
    auto t = Triangulator::create(setup.triangulation[i], arena);
    if (!t) {
      return undo(t.error());
    }
    c.triangulators_[i].emplace(*t);
  }
  if (auto ok = c.carve(arena); !ok) {
    return undo(ok.error());
  }
  return c;
}

void CameraPipeline::useReferenceKernels(bool on) {
  reference_ = on;
  if (decoder_) {
    decoder_->useReferenceKernels(on);
  }
}

// The stages check that create() set their objects (it always does; a pipeline exists only
// after it), which also keeps every optional access visibly checked.
Result<void> CameraPipeline::demultiplex(ConstRgbView image) {
  if (!demux_) {
    return fail(Errc::kInvalidArgument, "pipeline: not created");
  }
  return demux_->run(image);
}

Result<void> CameraPipeline::decode() {
  if (!demux_ || !decoder_) {
    return fail(Errc::kInvalidArgument, "pipeline: not created");
  }
  for (int p = 0; p < layout_.projectors; ++p) {
    const auto i = static_cast<std::size_t>(p);
    if (auto ok = decoder_->run(demux_->boundaries(p), demux_->directions(p), stripes_[i]); !ok) {
      return ok;
    }
    const ImageView<const std::int16_t> from = decoder_->levels();
    for (int y = 0; y < layout_.height; ++y) {
      const std::int16_t* src = from.rowPtr(y);
      std::int16_t* dst = levels_[i].rowPtr(y);
      for (int x = 0; x < layout_.width; ++x) {
        dst[x] = src[x];
      }
    }
    stats_[i] = decoder_->stats();
  }
  return {};
}

Result<void> CameraPipeline::triangulate() {
  for (int p = 0; p < layout_.projectors; ++p) {
    const auto i = static_cast<std::size_t>(p);
    const std::optional<Triangulator>& triangulator = triangulators_[i];
    if (!triangulator) {
      return fail(Errc::kInvalidArgument, "pipeline: not created");
    }
    // The merged plane is free until merge(): the unfiltered range image goes there first.
    // Untrusted depths go before the edge filter, so that they cannot cut good neighbours.
    if (auto ok = triangulator->run(stripes_[i], merged_); !ok) {
      return ok;
    }
    if (auto ok = trustDepth(*triangulator, stripes_[i], merged_, confidences_[i], trust_); !ok) {
      return ok;
    }
    const auto edges = reference_ ? removeDepthEdgesReference : removeDepthEdges;
    if (auto ok = edges(merged_, depths_[i], edgeJumpPermille_); !ok) {
      return ok;
    }
  }
  return {};
}

Result<void> CameraPipeline::merge() {
  std::array<ConstDepthPlane, kMaxProjectors> inputs{};
  std::array<ImageView<const std::uint8_t>, kMaxProjectors> confidences{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(layout_.projectors); ++i) {
    inputs[i] = depths_[i];
    confidences[i] = confidences_[i];
  }
  const auto n = static_cast<std::size_t>(layout_.projectors);
  const std::span<const ConstDepthPlane> ranges(inputs.data(), n);
  const std::span<const ImageView<const std::uint8_t>> rangeConfidences(confidences.data(), n);
  auto merged = reference_ ? mergeRangesReference(ranges, rangeConfidences, merged_,
                                                  mergedConfidence_, trust_.tolerance)
                           : mergeRanges(ranges, rangeConfidences, merged_, mergedConfidence_,
                                         trust_.tolerance);
  if (merged && !window_.keepsAll()) {
    applyDepthWindow(merged_, mergedConfidence_, window_);
  }
  return merged;
}

Result<void> CameraPipeline::run(ConstRgbView image) {
  if (auto ok = demultiplex(image); !ok) {
    return ok;
  }
  if (auto ok = decode(); !ok) {
    return ok;
  }
  if (auto ok = triangulate(); !ok) {
    return ok;
  }
  return merge();
}

ConstStripePlane CameraPipeline::stripe(int projector) const {
  return stripes_[static_cast<std::size_t>(projector)];
}
ImageView<const std::int16_t> CameraPipeline::levels(int projector) const {
  return levels_[static_cast<std::size_t>(projector)];
}
const DecodeStats& CameraPipeline::decodeStats(int projector) const {
  return stats_[static_cast<std::size_t>(projector)];
}
ConstDepthPlane CameraPipeline::depth(int projector) const {
  return depths_[static_cast<std::size_t>(projector)];
}
ConstDepthPlane CameraPipeline::merged() const {
  return merged_;
}
ImageView<const std::uint8_t> CameraPipeline::confidence(int projector) const {
  return confidences_[static_cast<std::size_t>(projector)];
}
ImageView<const std::uint8_t> CameraPipeline::confidence() const {
  return mergedConfidence_;
}

}  // namespace smx::algo
