#include "smx/sim/png_io.hpp"

#include <png.h>

#include <cstring>

namespace smx::sim {
namespace {

// png_image owns libpng state until finished or freed; free it on every exit path.
struct ImageGuard {
  png_image& image;
  ~ImageGuard() { png_image_free(&image); }
};

std::string describe(const std::filesystem::path& path, const png_image& image) {
  return path.string() + ": " + image.message;
}

// libpng wants rows whose stride is a whole number of pixels: pack (possibly padded) views first.
template <class Pixel>
std::expected<void, std::string> writePacked(const std::filesystem::path& path,
                                             algo::ImageView<const Pixel> image,
                                             png_uint_32 format) {
  std::vector<Pixel> packed(static_cast<std::size_t>(image.width()) *
                            static_cast<std::size_t>(image.height()));
  for (int y = 0; y < image.height(); ++y) {
    const auto row = image.row(y);
    std::memcpy(packed.data() + static_cast<std::size_t>(y) * row.size(), row.data(),
                row.size_bytes());
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width());
  png.height = static_cast<png_uint_32>(image.height());
  png.format = format;
  const ImageGuard guard{png};
  if (png_image_write_to_file(&png, path.c_str(), 0, packed.data(), 0, nullptr) == 0) {
    return std::unexpected(describe(path, png));
  }
  return {};
}

// Reads the pixels of a PNG whose header png_image_begin_read has read, in png.format, into an
// image with width, height and a pixel vector.
template <class Image>
std::expected<Image, std::string> finishRead(const std::filesystem::path& path, png_image& png) {
  Image out;
  out.width = static_cast<int>(png.width);
  out.height = static_cast<int>(png.height);
  out.pixels.resize(static_cast<std::size_t>(png.width) * png.height);
  if (png_image_finish_read(&png, nullptr, out.pixels.data(), 0, nullptr) == 0) {
    return std::unexpected(describe(path, png));
  }
  return out;
}

}  // namespace

std::expected<void, std::string> writePngRgb8(const std::filesystem::path& path,
                                              algo::ConstRgbView image) {
  return writePacked(path, image, PNG_FORMAT_RGB);
}

std::expected<void, std::string> writePngGray8(const std::filesystem::path& path,
                                               algo::ImageView<const std::uint8_t> image) {
  return writePacked(path, image, PNG_FORMAT_GRAY);
}

std::expected<void, std::string> writePngGray16(const std::filesystem::path& path,
                                                algo::ImageView<const std::uint16_t> image) {
  // PNG_FORMAT_LINEAR_Y: 16-bit samples written as given (big-endian in the file, gAMA 1.0).
  return writePacked(path, image, PNG_FORMAT_LINEAR_Y);
}

std::expected<Gray16Image, std::string> readPngGray16(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  const ImageGuard guard{png};
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
    return std::unexpected(describe(path, png));
  }
  if (png.format != PNG_FORMAT_LINEAR_Y) {
    return std::unexpected(path.string() + ": not a 16-bit grey PNG (" +
                           ((png.format & PNG_FORMAT_FLAG_COLOR) != 0 ? "colour" : "grey") +
                           ((png.format & PNG_FORMAT_FLAG_LINEAR) != 0 ? ", 16-bit" : ", 8-bit") +
                           ((png.format & PNG_FORMAT_FLAG_ALPHA) != 0 ? ", with alpha" : "") +
                           "); depth images are 16-bit grey");
  }
  return finishRead<Gray16Image>(path, png);
}

std::expected<RgbImage, std::string> readPngRgb8(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  const ImageGuard guard{png};
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
    return std::unexpected(describe(path, png));
  }
  png.format = PNG_FORMAT_RGB;
  return finishRead<RgbImage>(path, png);
}

}  // namespace smx::sim
