// The camera pipeline: the stages' objects and planes carved from one arena at create(), run in
// order per frame.
#include "smx/algo/camera_pipeline.hpp"

#include <algorithm>
#include <cstdint>
#include <span>

#include "smx/algo/depth_edges.hpp"
#include "smx/algo/depth_trust.hpp"
#include "smx/algo/range_merge.hpp"

namespace smx::algo {

namespace {

constexpr int kMaxBands = 16;  // of the merge: more than a board's cores

// The first failure among jobs' results, or success.
Result<void> firstError(std::span<const Result<void>> results) {
  for (const Result<void>& r : results) {
    if (!r) {
      return r;
    }
  }
  return {};
}

Result<void> validate(const CameraPipelineSetup& s) {
  if (s.layout.projectors < 1 || s.layout.projectors > kMaxProjectors) {
    return fail(Errc::kInvalidArgument, "pipeline: 1 to 3 projectors");
  }
  if (s.lanes < 1 || s.lanes > s.layout.projectors) {
    return fail(Errc::kInvalidArgument, "pipeline: 1 lane to one per projector");
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
  for (int l = 1; l < lanes_; ++l) {
    step(carveImage(carver, scratch_[static_cast<std::size_t>(l)], w, h));
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
  Result<void> ok = add(Demultiplexer::workspaceBytes(l, setup.lanes));
  for (int lane = 0; ok && lane < setup.lanes; ++lane) {
    ok = add(StripeDecoder::workspaceBytes(l.width, l.height, setup.decode));
  }
  // validate() checked one table per projector; a distorted projector's tables hold per-pixel
  // numerators, so each is sized by its own tables.
  for (int p = 0; ok && p < l.projectors; ++p) {
    ok = add(Triangulator::workspaceBytes(setup.triangulation[static_cast<std::size_t>(p)]));
  }
  CameraPipeline sized;
  sized.layout_ = l;
  sized.lanes_ = setup.lanes;
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
  c.lanes_ = setup.lanes;
  c.edgeJumpPermille_ = setup.edgeJumpPermille;
  c.trust_ = setup.trust;
  c.window_ = setup.window;
  auto demux = Demultiplexer::create(setup.layout, setup.predictedAngles, arena,
                                     DemuxSchedule::kAutomatic, setup.lanes);
  if (!demux) {
    return undo(demux.error());
  }
  c.demux_.emplace(*demux);
  for (int l = 0; l < setup.lanes; ++l) {
    auto decoder =
        StripeDecoder::create(setup.layout.width, setup.layout.height, setup.decode, arena);
    if (!decoder) {
      return undo(decoder.error());
    }
    c.decoders_[static_cast<std::size_t>(l)].emplace(*decoder);
  }
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
  for (std::optional<StripeDecoder>& decoder : decoders_) {
    if (decoder) {
      decoder->useReferenceKernels(on);
    }
  }
}

// The stages check that create() set their objects (it always does; a pipeline exists only
// after it), which also keeps every optional access visibly checked.
Result<void> CameraPipeline::demultiplex(ConstRgbView image, JobRunner& jobs) {
  if (!demux_) {
    return fail(Errc::kInvalidArgument, "pipeline: not created");
  }
  return demux_->run(image, jobs);
}

template <class PerProjector>
Result<void> CameraPipeline::onLanes(JobRunner& jobs, const PerProjector& perProjector) {
  std::array<Result<void>, kMaxProjectors> results{};
  auto lane = [&](int l) {
    for (int p = l; p < layout_.projectors; p += lanes_) {
      if (auto ok = perProjector(p, l); !ok) {
        results[static_cast<std::size_t>(l)] = ok;
        return;
      }
    }
  };
  jobs.forEach(lanes_, lane);
  return firstError(results);
}

Result<void> CameraPipeline::decodeProjector(int projector, StripeDecoder& decoder) {
  const auto i = static_cast<std::size_t>(projector);
  // NOLINTNEXTLINE(bugprone-unchecked-optional-access): decode() checked it
  const Demultiplexer& demux = *demux_;
  if (auto ok = decoder.run(demux.boundaries(projector), demux.directions(projector), stripes_[i]);
      !ok) {
    return ok;
  }
  const ImageView<const std::int16_t> from = decoder.levels();
  for (int y = 0; y < layout_.height; ++y) {
    const std::int16_t* src = from.rowPtr(y);
    std::int16_t* dst = levels_[i].rowPtr(y);
    for (int x = 0; x < layout_.width; ++x) {
      dst[x] = src[x];
    }
  }
  stats_[i] = decoder.stats();
  return {};
}

Result<void> CameraPipeline::decode(JobRunner& jobs) {
  if (!demux_) {
    return fail(Errc::kInvalidArgument, "pipeline: not created");
  }
  for (int l = 0; l < lanes_; ++l) {
    if (!decoders_[static_cast<std::size_t>(l)]) {
      return fail(Errc::kInvalidArgument, "pipeline: not created");
    }
  }
  return onLanes(jobs, [this](int p, int l) {
    // NOLINTNEXTLINE(bugprone-unchecked-optional-access): checked above
    return decodeProjector(p, *decoders_[static_cast<std::size_t>(l)]);
  });
}

Result<void> CameraPipeline::triangulateProjector(int projector, DepthPlane scratch) {
  const auto i = static_cast<std::size_t>(projector);
  const std::optional<Triangulator>& triangulator = triangulators_[i];
  if (!triangulator) {
    return fail(Errc::kInvalidArgument, "pipeline: not created");
  }
  // The unfiltered range image goes to the lane's scratch plane first. Untrusted depths go
  // before the edge filter, so that they cannot cut good neighbours.
  if (reference_) {
    if (auto ok = triangulator->run(stripes_[i], scratch); !ok) {
      return ok;
    }
    if (auto ok = trustDepth(*triangulator, stripes_[i], scratch, confidences_[i], trust_); !ok) {
      return ok;
    }
  } else if (auto ok =
                 triangulateTrusted(*triangulator, stripes_[i], scratch, confidences_[i], trust_);
             !ok) {
    return ok;
  }
  const auto edges = reference_ ? removeDepthEdgesReference : removeDepthEdges;
  return edges(scratch, depths_[i], edgeJumpPermille_);
}

Result<void> CameraPipeline::triangulate(JobRunner& jobs) {
  // Lane 0's scratch is the merged plane, free until merge().
  return onLanes(jobs, [this](int p, int l) {
    return triangulateProjector(p, l == 0 ? merged_ : scratch_[static_cast<std::size_t>(l)]);
  });
}

Result<void> CameraPipeline::merge(JobRunner& jobs) {
  std::array<ConstDepthPlane, kMaxProjectors> inputs{};
  std::array<ImageView<const std::uint8_t>, kMaxProjectors> confidences{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(layout_.projectors); ++i) {
    inputs[i] = depths_[i];
    confidences[i] = confidences_[i];
  }
  const auto n = static_cast<std::size_t>(layout_.projectors);
  const std::span<const ConstDepthPlane> ranges(inputs.data(), n);
  const std::span<const ImageView<const std::uint8_t>> rangeConfidences(confidences.data(), n);
  if (reference_) {
    auto merged = mergeRangesReference(ranges, rangeConfidences, merged_, mergedConfidence_,
                                       trust_.tolerance);
    if (merged && !window_.keepsAll()) {
      applyDepthWindow(merged_, mergedConfidence_, window_);
    }
    return merged;
  }
  const int h = layout_.height;
  const int count = std::min({jobs.width(), h, kMaxBands});
  std::array<Result<void>, kMaxBands> results{};
  auto band = [&](int b) {
    const int y0 = b * h / count;
    const int y1 = (b + 1) * h / count;
    Result<void>& result = results[static_cast<std::size_t>(b)];
    result = mergeRanges(ranges, rangeConfidences, merged_, mergedConfidence_, trust_.tolerance,
                         {y0, y1});
    if (result && !window_.keepsAll()) {
      applyDepthWindow(merged_.sub(0, y0, layout_.width, y1 - y0),
                       mergedConfidence_.sub(0, y0, layout_.width, y1 - y0), window_);
    }
  };
  jobs.forEach(count, band);
  return firstError(results);
}

Result<void> CameraPipeline::run(ConstRgbView image, JobRunner& jobs) {
  if (auto ok = demultiplex(image, jobs); !ok) {
    return ok;
  }
  if (auto ok = decode(jobs); !ok) {
    return ok;
  }
  if (auto ok = triangulate(jobs); !ok) {
    return ok;
  }
  return merge(jobs);
}

Result<void> CameraPipeline::demultiplex(ConstRgbView image) {
  SerialJobs serial;
  return demultiplex(image, serial);
}

Result<void> CameraPipeline::decode() {
  SerialJobs serial;
  return decode(serial);
}

Result<void> CameraPipeline::triangulate() {
  SerialJobs serial;
  return triangulate(serial);
}

Result<void> CameraPipeline::merge() {
  SerialJobs serial;
  return merge(serial);
}

Result<void> CameraPipeline::run(ConstRgbView image) {
  SerialJobs serial;
  return run(image, serial);
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
