#pragma once

#include <expected>
#include <filesystem>
#include <string>

#include "output_folder.hpp"
#include "smx/algo/boundary_map.hpp"
#include "smx/algo/demux.hpp"
#include "smx/algo/image_view.hpp"
#include "smx/sim/png_io.hpp"

// Debug renderings of orientation demultiplexing, like the paper's stripe-segmented images
// (Fig. 9(b, c), 11(c–e)): what a person looks at to see whether separation worked.
namespace smx::host {

// Black, with each boundary pixel in the colour after the boundary (the paper's grouping R, G, B),
// brighter with more confidence.
[[nodiscard]] sim::RgbImage renderBoundaries(algo::ConstBoundaryPlane boundaries);

// A separated, colour-normalised derivative (Q4.11 per channel) as grey 128 + gain · value per
// channel, clipped: rising channels bright, falling ones dark (paper Fig. 8, bottom).
[[nodiscard]] sim::RgbImage renderSeparated(
    const algo::ImageView<const std::int16_t> (&channels)[3]);

// The encoding direction as a hue (0° red, 120° green, 240° blue), where the projector has a
// boundary within the pixel's 3×3 neighbourhood brighter.
[[nodiscard]] sim::RgbImage renderDirections(algo::ConstDirectionPlane directions,
                                             algo::ConstBoundaryPlane boundaries);

// Writes the three renderings above of one projector into `dir` as <tag>.{boundaries,separated,
// direction}.png; the separated view is the last projector separated (Demultiplexer::separated).
[[nodiscard]] std::expected<void, std::string> writeDemuxDebug(OutputFolder& dir,
                                                               const std::string& tag,
                                                               const algo::Demultiplexer& demux,
                                                               int projector);

}  // namespace smx::host
