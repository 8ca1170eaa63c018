#include "smx/sim/pfm_io.hpp"

#include <bit>
#include <fstream>
#include <system_error>

namespace smx::sim {
namespace {

static_assert(std::endian::native == std::endian::little, "PFM writer assumes little endian");

template <class Pixel>
std::expected<void, std::string> writeRows(const std::filesystem::path& path, char kind,
                                           algo::ImageView<const Pixel> image) {
  std::ofstream out(path, std::ios::binary);
  if (!out) {
    return std::unexpected(path.string() + ": cannot open for writing");
  }
  out << 'P' << kind << '\n' << image.width() << ' ' << image.height() << "\n-1.0\n";
  for (int y = image.height() - 1; y >= 0; --y) {
    const auto row = image.row(y);
    out.write(reinterpret_cast<const char*>(row.data()),
              static_cast<std::streamsize>(row.size_bytes()));
  }
  out.close();
  if (!out) {
    return std::unexpected(path.string() + ": write failed");
  }
  return {};
}

}  // namespace

std::expected<void, std::string> writePfm(const std::filesystem::path& path,
                                          algo::ImageView<const float> image) {
  return writeRows(path, 'f', image);
}

std::expected<void, std::string> writePfm(const std::filesystem::path& path,
                                          algo::ImageView<const std::array<float, 3>> image) {
  return writeRows(path, 'F', image);
}

std::expected<FloatImage, std::string> readPfm(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return std::unexpected(path.string() + ": cannot open");
  }
  std::string magic;
  FloatImage img;
  double scale = 0.0;
  in >> magic >> img.width >> img.height >> scale;
  in.get();  // the single whitespace byte before the data
  if (!in || (magic != "Pf" && magic != "PF") || img.width <= 0 || img.height <= 0 ||
      scale == 0.0) {
    return std::unexpected(path.string() + ": not a PFM file (bad header)");
  }
  if (scale > 0.0) {
    return std::unexpected(path.string() + ": big-endian PFM is not supported");
  }
  img.channels = magic == "PF" ? 3 : 1;
  const auto rowValues =
      static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.channels);
  // The header's size must fit the file: a corrupt header must not allocate gigabytes.
  std::error_code ec;
  const auto fileBytes = std::filesystem::file_size(path, ec);
  const auto dataBytes = fileBytes - static_cast<std::uintmax_t>(in.tellg());
  if (ec || static_cast<std::uintmax_t>(in.tellg()) > fileBytes ||
      rowValues > dataBytes / sizeof(float) / static_cast<std::size_t>(img.height)) {
    return std::unexpected(path.string() + ": truncated: the header announces " +
                           std::to_string(img.width) + "x" + std::to_string(img.height) +
                           ", more than the file holds");
  }
  img.values.resize(rowValues * static_cast<std::size_t>(img.height));
  for (int y = img.height - 1; y >= 0; --y) {
    in.read(reinterpret_cast<char*>(img.values.data() + static_cast<std::size_t>(y) * rowValues),
            static_cast<std::streamsize>(rowValues * sizeof(float)));
  }
  if (!in) {
    return std::unexpected(path.string() + ": truncated PFM data");
  }
  return img;
}

}  // namespace smx::sim
