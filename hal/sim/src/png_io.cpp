#include "smx/sim/png_io.hpp"

#include <png.h>

#include <cstring>
#include <fstream>
#include <system_error>

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

std::string sizeText(std::uint64_t width, std::uint64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The header's claim against the limit, before anything is allocated for the pixels. The maxima
// hold for an expected size too: it comes from a file as well (a rig allows 65535 a side).
std::expected<void, std::string> checkSize(std::string_view name, std::uint64_t width,
                                           std::uint64_t height, const PngSizeLimit& limit) {
  const std::string prefix = std::string(name) + ": image is " + sizeText(width, height);
  if (limit.width > 0 && limit.height > 0 &&
      (width != static_cast<std::uint64_t>(limit.width) ||
       height != static_cast<std::uint64_t>(limit.height))) {
    return std::unexpected(prefix + ", " + std::string(limit.owner) + " is " +
                           sizeText(static_cast<std::uint64_t>(limit.width),
                                    static_cast<std::uint64_t>(limit.height)));
  }
  const auto maxSide = static_cast<std::uint64_t>(limit.maxSide);
  if (width > maxSide || height > maxSide || width * height > limit.maxPixels) {
    return std::unexpected(prefix + "; images are read up to " + std::to_string(maxSide) +
                           " pixels a side and " + std::to_string(limit.maxPixels) + " in all");
  }
  return {};
}

std::uint64_t bigEndian32(std::span<const std::byte> bytes) {
  std::uint64_t value = 0;
  for (const std::byte b : bytes.first(4)) {
    value = value << 8U | std::to_integer<std::uint64_t>(b);
  }
  return value;
}

// Each chunk's length against the bytes the file has left. libpng allocates what an ancillary
// chunk (sPLT, zTXt) claims before it reads the data, so a chunk of 45 bytes could cost 2 GB,
// also when the file ends inside the chunk's CRC. Bytes that are not a PNG, or that end before a
// chunk's length and type, are left to libpng to name.
std::expected<void, std::string> checkChunkLengths(std::span<const std::byte> bytes,
                                                   std::string_view name) {
  constexpr std::size_t kSignature = 8;
  constexpr std::size_t kLengthAndType = 8;
  constexpr std::size_t kChunkFrame = 12;  // length, type, CRC
  if (bytes.size() < kSignature ||
      png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, kSignature) != 0) {
    return {};
  }
  for (std::size_t at = kSignature; bytes.size() - at >= kLengthAndType;) {
    const std::size_t rest = bytes.size() - at;
    const std::size_t left = rest >= kChunkFrame ? rest - kChunkFrame : 0;
    const std::uint64_t length = bigEndian32(bytes.subspan(at));
    const std::string type(reinterpret_cast<const char*>(bytes.data() + at + 4), 4);
    if (length > left) {
      return std::unexpected(std::string(name) + ": chunk \"" + type + "\" claims " +
                             std::to_string(length) + " bytes, but the file has " +
                             std::to_string(left) + " left");
    }
    if (type == "IEND" || rest < kChunkFrame) {
      break;
    }
    at += kChunkFrame + static_cast<std::size_t>(length);
  }
  return {};
}

// The header of a PNG in memory, checked against the limit; the caller frees `png`. The size is
// taken from the IHDR chunk (always the first, at a fixed place) before libpng sees the file,
// so that every claim gets the same message whatever limits the installed libpng has.
std::expected<void, std::string> beginRead(std::span<const std::byte> bytes, std::string_view name,
                                           const PngSizeLimit& limit, png_image& png) {
  constexpr std::size_t kIhdrEnd = 8 + 8 + 8;  // signature, length and type, width and height
  if (bytes.size() >= kIhdrEnd &&
      png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0 &&
      std::memcmp(bytes.data() + 12, "IHDR", 4) == 0) {
    if (auto size =
            checkSize(name, bigEndian32(bytes.subspan(16)), bigEndian32(bytes.subspan(20)), limit);
        !size) {
      return size;
    }
  }
  if (auto chunks = checkChunkLengths(bytes, name); !chunks) {
    return chunks;
  }
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()) == 0) {
    return std::unexpected(std::string(name) + ": " + png.message);
  }
  return checkSize(name, png.width, png.height, limit);
}

// Reads the pixels of a PNG whose header beginRead has read and checked, in png.format, into an
// image with width, height and a pixel vector.
template <class Image>
std::expected<Image, std::string> finishRead(std::string_view name, png_image& png) {
  Image out;
  out.width = static_cast<int>(png.width);
  out.height = static_cast<int>(png.height);
  out.pixels.resize(static_cast<std::size_t>(png.width) * png.height);
  if (png_image_finish_read(&png, nullptr, out.pixels.data(), 0, nullptr) == 0) {
    return std::unexpected(std::string(name) + ": " + png.message);
  }
  return out;
}

// The whole file, refused unread when it is larger than any PNG within the limit.
std::expected<std::vector<std::byte>, std::string> readFile(const std::filesystem::path& path,
                                                            const PngSizeLimit& limit) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) {
    return std::unexpected(path.string() + ": cannot read the file: " + ec.message());
  }
  if (size > maxPngFileBytes(limit)) {
    return std::unexpected(path.string() + ": " + std::to_string(size) +
                           " bytes, more than a PNG within the size limit can take (" +
                           std::to_string(maxPngFileBytes(limit)) + ")");
  }
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!in || in.gcount() != static_cast<std::streamsize>(bytes.size())) {
    return std::unexpected(path.string() + ": cannot read the file");
  }
  return bytes;
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

std::uint64_t maxPngFileBytes(const PngSizeLimit& limit) {
  const std::uint64_t pixels =
      limit.width > 0 && limit.height > 0
          ? static_cast<std::uint64_t>(limit.width) * static_cast<std::uint64_t>(limit.height)
          : limit.maxPixels;
  return 8 * pixels + (std::uint64_t{16} << 20U);
}

std::expected<Gray16Image, std::string> readPngGray16(std::span<const std::byte> bytes,
                                                      std::string_view name,
                                                      const PngSizeLimit& limit) {
  png_image png{};
  const ImageGuard guard{png};
  if (auto header = beginRead(bytes, name, limit, png); !header) {
    return std::unexpected(header.error());
  }
  if (png.format != PNG_FORMAT_LINEAR_Y) {
    return std::unexpected(std::string(name) + ": not a 16-bit grey PNG (" +
                           ((png.format & PNG_FORMAT_FLAG_COLOR) != 0 ? "colour" : "grey") +
                           ((png.format & PNG_FORMAT_FLAG_LINEAR) != 0 ? ", 16-bit" : ", 8-bit") +
                           ((png.format & PNG_FORMAT_FLAG_ALPHA) != 0 ? ", with alpha" : "") +
                           "); depth images are 16-bit grey");
  }
  return finishRead<Gray16Image>(name, png);
}

std::expected<RgbImage, std::string> readPngRgb8(std::span<const std::byte> bytes,
                                                 std::string_view name, const PngSizeLimit& limit) {
  png_image png{};
  const ImageGuard guard{png};
  if (auto header = beginRead(bytes, name, limit, png); !header) {
    return std::unexpected(header.error());
  }
  png.format = PNG_FORMAT_RGB;
  return finishRead<RgbImage>(name, png);
}

std::expected<Gray16Image, std::string> readPngGray16(const std::filesystem::path& path,
                                                      const PngSizeLimit& limit) {
  const auto bytes = readFile(path, limit);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  return readPngGray16(*bytes, path.string(), limit);
}

std::expected<RgbImage, std::string> readPngRgb8(const std::filesystem::path& path,
                                                 const PngSizeLimit& limit) {
  const auto bytes = readFile(path, limit);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  return readPngRgb8(*bytes, path.string(), limit);
}

}  // namespace smx::sim
