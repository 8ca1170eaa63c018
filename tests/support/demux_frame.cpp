#include "demux_frame.hpp"

#include <stdexcept>
#include <string>

#include "smx/algo/encoding_prediction.hpp"

namespace smx::test {

std::unique_ptr<DemuxedFrame> demultiplex(const SimFrame& frame, const algo::DemuxParams& params,
                                          double nominalDepthM) {
  auto out = std::make_unique<DemuxedFrame>();
  const algo::DemuxLayout layout{frame.image.width, frame.image.height,
                                 static_cast<int>(frame.rig.projectors.size()), params};
  const auto bytes = algo::Demultiplexer::workspaceBytes(layout);
  if (!bytes) {
    throw std::runtime_error(std::string("demux layout: ") + bytes.error().message);
  }
  const auto predicted = algo::predictEncodingAngles(frame.rig, 0, layout, nominalDepthM);
  if (!predicted) {
    throw std::runtime_error("encoding prediction: " + predicted.error());
  }
  out->memory.resize(*bytes);
  out->arena = std::make_unique<algo::Arena>(out->memory);
  auto demux = algo::Demultiplexer::create(layout, *predicted, *out->arena);
  if (!demux) {
    throw std::runtime_error(std::string("demux create: ") + demux.error().message);
  }
  out->demux = std::make_unique<algo::Demultiplexer>(*demux);
  if (auto ok = out->demux->run(frame.image.view()); !ok) {
    throw std::runtime_error(std::string("demux run: ") + ok.error().message);
  }
  return out;
}

Mask regionLitBy(const SimFrame& frame, int projector, int patterns) {
  std::vector<algo::ImageView<const std::uint8_t>> lits;
  lits.reserve(frame.lit.size());
  for (const auto& lit : frame.lit) {
    lits.push_back(lit.view());
  }
  Mask region = smoothOnly(erode(litByExactly(lits, patterns), 3), frame.depth.view(), 0.02);
  const auto& mine = frame.lit.at(static_cast<std::size_t>(projector));
  for (int y = 0; y < region.height; ++y) {
    for (int x = 0; x < region.width; ++x) {
      region.at(x, y) = (region.at(x, y) != 0 && mine.at(x, y) != 0) ? 255 : 0;
    }
  }
  return region;
}

}  // namespace smx::test
