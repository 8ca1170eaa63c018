#include "demux_frame.hpp"

#include <stdexcept>
#include <string>

#include "smx/algo/encoding_prediction.hpp"
#include "smx/eval/frame_eval.hpp"

namespace smx::test {

std::unique_ptr<DemuxedFrame> demultiplex(const eval::SimFrame& frame,
                                          const algo::DemuxParams& params, double nominalDepthM) {
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

eval::Mask regionLitBy(const eval::SimFrame& frame, int projector, int patterns) {
  eval::Mask m = eval::litRegion(
      frame, {.patterns = patterns, .exactly = true, .smooth = true, .projector = projector});
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      if (x < kImageMarginPx || y < kImageMarginPx || x >= m.width - kImageMarginPx ||
          y >= m.height - kImageMarginPx) {
        m.at(x, y) = 0;
      }
    }
  }
  return m;
}

}  // namespace smx::test
