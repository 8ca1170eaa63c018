#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "png_claim.hpp"
#include "smx/sim/mesh_io.hpp"
#include "smx/sim/pfm_io.hpp"
#include "smx/sim/ply_io.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::sim {
namespace {

namespace fs = std::filesystem;

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("smx_sim_io_" + name);
}

void writeBytes(const fs::path& path, const std::vector<std::byte>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

// Given a 3x2 grey float image, when written as PFM, then the bytes follow the format: header
// "Pf", width height, -1 (little endian), then rows from the bottom up.
TEST(SimIo, GreyPfmLayoutFollowsTheFormat) {
  std::vector<float> px = {1, 2, 3, 4, 5, std::numeric_limits<float>::quiet_NaN()};
  const auto view = *algo::ImageView<const float>::packed(px, 3, 2);
  const auto path = tempFile("grey.pfm");
  ASSERT_TRUE(writePfm(path, view).has_value());
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string header = "Pf\n3 2\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 6 * sizeof(float));
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  float first = 0;
  std::memcpy(&first, bytes.data() + header.size(), sizeof(float));
  EXPECT_EQ(first, 4.0F);  // bottom row first

  const auto back = readPfm(path);
  ASSERT_TRUE(back.has_value()) << back.error();
  EXPECT_EQ(back->channels, 1);
  EXPECT_EQ(back->values[0], 1.0F);
  EXPECT_EQ(back->values[4], 5.0F);
  EXPECT_TRUE(std::isnan(back->values[5]));
  fs::remove(path);
}

TEST(SimIo, ColourPfmRoundTrips) {
  std::vector<std::array<float, 3>> px = {{0.1F, 0.2F, 0.3F}, {-1, 0, 1}};
  const auto path = tempFile("colour.pfm");
  ASSERT_TRUE(writePfm(path, *algo::ImageView<const std::array<float, 3>>::packed(px, 1, 2)));
  const auto back = readPfm(path);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->channels, 3);
  EXPECT_EQ(back->values, (std::vector<float>{0.1F, 0.2F, 0.3F, -1, 0, 1}));
  fs::remove(path);
}

TEST(SimIo, TruncatedOrForeignPfmIsRejectedWithTheFileName) {
  const auto path = tempFile("bad.pfm");
  std::ofstream(path) << "Pf\n4 4\n-1.0\nxx";
  const auto truncated = readPfm(path);
  ASSERT_FALSE(truncated.has_value());
  EXPECT_NE(truncated.error().find("truncated"), std::string::npos);
  EXPECT_NE(truncated.error().find(path.string()), std::string::npos);
  std::ofstream(path) << "P6\n4 4\n255\n";
  EXPECT_FALSE(readPfm(path).has_value());
  fs::remove(path);
}

// A header that claims more than the file holds is refused before anything is allocated (a
// 30-byte file claiming 2^31-1 squared floats used to end in std::bad_alloc).
TEST(SimIo, PfmHeaderClaimingMoreThanTheFileIsRefusedBeforeAllocating) {
  const auto path = tempFile("bomb.pfm");
  std::ofstream(path) << "PF\n2147483647 2147483647\n-1.0\nxxxx";
  const auto bomb = readPfm(path);
  ASSERT_FALSE(bomb.has_value());
  EXPECT_NE(bomb.error().find("the header announces 2147483647x2147483647"), std::string::npos)
      << bomb.error();
  fs::remove(path);
}

TEST(SimIo, GreyAndRgbPngRoundTrip) {
  std::vector<std::uint8_t> mask = {0, 255, 7, 0, 128, 255};
  const auto maskPath = tempFile("mask.png");
  ASSERT_TRUE(writePngGray8(maskPath, *algo::ImageView<const std::uint8_t>::packed(mask, 3, 2)));
  const auto asRgb = readPngRgb8(maskPath);
  ASSERT_TRUE(asRgb.has_value());
  EXPECT_EQ(asRgb->pixels[1], (algo::Rgb8{255, 255, 255}));
  EXPECT_EQ(asRgb->pixels[2], (algo::Rgb8{7, 7, 7}));
  fs::remove(maskPath);

  // A padded RGB view is written without its padding.
  std::vector<std::byte> padded(2 * 8);
  auto view = *algo::RgbView::create(padded.data(), 2, 2, 8);
  view(0, 0) = {1, 2, 3};
  view(1, 1) = {250, 251, 252};
  const auto rgbPath = tempFile("rgb.png");
  ASSERT_TRUE(writePngRgb8(rgbPath, view));
  const auto back = readPngRgb8(rgbPath);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->pixels[0], (algo::Rgb8{1, 2, 3}));
  EXPECT_EQ(back->pixels[3], (algo::Rgb8{250, 251, 252}));
  EXPECT_FALSE(readPngRgb8(tempFile("missing.png")).has_value());
  fs::remove(rgbPath);
}

// The raw samples of a 1×1 16-bit PNG: the zlib stream of its IDAT chunks inflated by hand is
// [filter byte][high byte][low byte] (for a single pixel every PNG filter leaves the bytes as
// they are), so the stored value is checked independently of libpng's reader.
std::vector<std::uint8_t> rawSamplesOfOnePixelPng(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> file((std::istreambuf_iterator<char>(in)), {});
  std::vector<std::uint8_t> idat;
  std::uint8_t bitDepth = 0;
  std::uint8_t colourType = 255;
  for (std::size_t at = 8; at + 12 <= file.size();) {
    const std::size_t length = (std::size_t{file[at]} << 24) | (std::size_t{file[at + 1]} << 16) |
                               (std::size_t{file[at + 2]} << 8) | file[at + 3];
    const std::string type(reinterpret_cast<const char*>(&file[at + 4]), 4);
    if (type == "IHDR") {
      bitDepth = file[at + 8 + 8];
      colourType = file[at + 8 + 9];
    } else if (type == "IDAT") {
      idat.insert(idat.end(), file.begin() + static_cast<std::ptrdiff_t>(at + 8),
                  file.begin() + static_cast<std::ptrdiff_t>(at + 8 + length));
    }
    at += 12 + length;
  }
  EXPECT_EQ(bitDepth, 16);
  EXPECT_EQ(colourType, 0);  // greyscale
  std::vector<std::uint8_t> raw(16);
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &size, idat.data(), idat.size()), Z_OK);
  raw.resize(size);
  return raw;
}

// Given depth values, when written as a 16-bit grey PNG, then they read back exactly, and the
// file stores them big-endian without a gamma conversion (what OpenCV and Open3D read).
TEST(SimIo, Gray16PngStoresTheValuesExactly) {
  std::vector<std::uint16_t> depth = {0, 1, 9000, 65535, 0x1234, 300};
  const auto path = tempFile("depth.png");
  ASSERT_TRUE(writePngGray16(path, *algo::ImageView<const std::uint16_t>::packed(depth, 3, 2)));
  const auto back = readPngGray16(path);
  ASSERT_TRUE(back.has_value()) << back.error();
  EXPECT_EQ(back->width, 3);
  EXPECT_EQ(back->height, 2);
  EXPECT_EQ(back->pixels, depth);

  std::vector<std::uint16_t> one = {0x1234};
  const auto onePath = tempFile("one.png");
  ASSERT_TRUE(writePngGray16(onePath, *algo::ImageView<const std::uint16_t>::packed(one, 1, 1)));
  const auto raw = rawSamplesOfOnePixelPng(onePath);
  ASSERT_EQ(raw.size(), 3U);
  EXPECT_EQ(raw[1], 0x12);
  EXPECT_EQ(raw[2], 0x34);
  fs::remove(path);
  fs::remove(onePath);
}

TEST(SimIo, Gray16ReaderNamesOtherKindsOfPng) {
  std::vector<std::uint8_t> mask = {0, 255};
  const auto path = tempFile("grey8.png");
  ASSERT_TRUE(writePngGray8(path, *algo::ImageView<const std::uint8_t>::packed(mask, 2, 1)));
  const auto r = readPngGray16(path);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().find("grey8.png"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("8-bit"), std::string::npos) << r.error();
  fs::remove(path);
}

// Given a 65-byte PNG whose header claims 20000x20000 pixels (1.2 GB as RGB), when read, then
// it is refused against the global maximum before the pixels are allocated, naming the file and
// both sizes.
TEST(SimIo, PngClaiming20000SquaredIsRefusedNamingBothSizes) {
  const auto path = tempFile("claims_20000.png");
  writeBytes(path, test::pngClaiming(20000, 20000));
  const auto rgb = readPngRgb8(path);
  ASSERT_FALSE(rgb.has_value());
  EXPECT_NE(rgb.error().find("claims_20000.png: image is 20000x20000"), std::string::npos)
      << rgb.error();
  EXPECT_NE(rgb.error().find("up to 16384 pixels a side and 67108864 in all"), std::string::npos)
      << rgb.error();
  const auto grey = readPngGray16(path);
  ASSERT_FALSE(grey.has_value());
  EXPECT_NE(grey.error().find("claims_20000.png: image is 20000x20000"), std::string::npos)
      << grey.error();
  fs::remove(path);
}

// Given headers claiming 2^31 - 1 pixels a side (the most PNG allows) and 10^6 (the most
// libpng's default limits let through: 3 TB as RGB), when read, then both are refused by the
// same size check naming both sizes, never by std::bad_alloc.
TEST(SimIo, PngClaimingTheLargestSizesIsRefusedNamingBothSizes) {
  for (const std::uint32_t side : {2147483647U, 1000000U}) {
    const auto path = tempFile("claims_" + std::to_string(side) + ".png");
    writeBytes(path, test::pngClaiming(side, side));
    const auto rgb = readPngRgb8(path);
    ASSERT_FALSE(rgb.has_value());
    EXPECT_NE(rgb.error().find(path.filename().string() + ": image is " + std::to_string(side) +
                               "x" + std::to_string(side)),
              std::string::npos)
        << rgb.error();
    EXPECT_NE(rgb.error().find("up to 16384 pixels a side and 67108864 in all"), std::string::npos)
        << rgb.error();
    fs::remove(path);
  }
}

// Given the 45 bytes png_fuzz found (a 1x1 IHDR, then an "sPLT" chunk claiming 1951419476
// bytes with none behind it), when read, then the chunk is refused by name before anything
// near its claim is allocated (libpng allocated the claim, then found the data missing).
TEST(SimIo, PngChunkClaimingMoreThanTheFileHasIsRefusedUnallocated) {
  const std::vector<std::uint8_t> found = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
      0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x10, 0x06, 0x00, 0x00, 0x00, 0x4f,
      0x85, 0x18, 0xca, 0x74, 0x50, 0x4c, 0x54, 0x73, 0x50, 0x4c, 0x54, 0x49, 0x44, 0x41, 0x54};
  const test::AllocationCounter counter;
  const auto rgb = readPngRgb8(std::as_bytes(std::span(found)), "found.png");
  EXPECT_LT(counter.bytes(), 1U << 20U);
  ASSERT_FALSE(rgb.has_value());
  EXPECT_NE(rgb.error().find("found.png: chunk \"sPLT\" claims 1951419476 bytes"),
            std::string::npos)
      << rgb.error();
}

// Given the 42 bytes png_fuzz found (a 3x2 IHDR, then a "zTXt" chunk claiming 738197525 bytes,
// the file ending before the chunk's CRC), when read, then the chunk is refused by name before
// anything near its claim is allocated.
TEST(SimIo, PngChunkCutInsideItsFrameIsRefusedUnallocated) {
  const std::vector<std::uint8_t> found = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
      0x44, 0x52, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x02, 0x10, 0x00, 0x00, 0x00,
      0x00, 0xe8, 0x8f, 0xe5, 0x85, 0x2c, 0x00, 0x00, 0x15, 0x7a, 0x54, 0x58, 0x74, 0x63};
  const test::AllocationCounter counter;
  const auto grey = readPngGray16(std::as_bytes(std::span(found)), "found.png");
  EXPECT_LT(counter.bytes(), 1U << 20U);
  ASSERT_FALSE(grey.has_value());
  EXPECT_NE(grey.error().find("found.png: chunk \"zTXt\" claims 738197525 bytes, but the file "
                              "has 0 left"),
            std::string::npos)
      << grey.error();
}

// Given PNGs whose last chunk frame is cut after its length and type (an empty chunk without its
// CRC, as png_fuzz found), when read, then each is refused with libpng's reason and nothing is
// read past the bytes (the host-asan tier runs this under AddressSanitizer).
TEST(SimIo, PngEndingInsideAnEmptyChunksFrameIsRefusedWithoutReadingPastIt) {
  const auto whole = test::pngClaiming(3, 2);
  for (std::size_t cut = 8; cut < 12; ++cut) {
    std::vector<std::byte> bytes(whole.begin(), whole.begin() + 33);  // signature and IHDR
    const std::array<std::uint8_t, 11> emptyChunk = {0, 0, 0, 0, 'I', 'D', 'A', 'T', 0, 0, 0};
    for (std::size_t i = 0; i < cut; ++i) {
      bytes.push_back(static_cast<std::byte>(emptyChunk[i]));
    }
    const auto rgb = readPngRgb8(std::span<const std::byte>(bytes), "cut.png");
    ASSERT_FALSE(rgb.has_value()) << cut;
    EXPECT_EQ(rgb.error().rfind("cut.png: ", 0), 0U) << rgb.error();
  }
}

// Given a caller that knows the size (a 640x480 camera), when a PNG claims another, then the
// error names the claim and the camera's size, and an expected size beyond the maxima is refused;
// the in-memory reader, which the file reader uses, gives the same answers; sizes at the limits
// pass and one pixel more does not.
TEST(SimIo, PngSizeLimitsAreExactForCamerasAndInclusiveMaxima) {
  const auto huge = test::pngClaiming(20000, 20000);
  const auto camera = readPngRgb8(huge, "upload.png", PngSizeLimit::exactly(640, 480, "camera c0"));
  ASSERT_FALSE(camera.has_value());
  EXPECT_NE(camera.error().find("upload.png: image is 20000x20000, camera c0 is 640x480"),
            std::string::npos)
      << camera.error();
  // A camera size from a rig is input too: the maxima hold for it.
  const auto big =
      readPngRgb8(huge, "upload.png", PngSizeLimit::exactly(20000, 20000, "camera c1"));
  ASSERT_FALSE(big.has_value());
  EXPECT_NE(big.error().find("up to 16384 pixels a side and 67108864 in all"), std::string::npos)
      << big.error();

  std::vector<algo::Rgb8> px = {{1, 2, 3}, {4, 5, 6}};
  const auto path = tempFile("two.png");
  ASSERT_TRUE(writePngRgb8(path, *algo::ConstRgbView::packed(px, 2, 1)));
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> file((std::istreambuf_iterator<char>(in)), {});
  const auto bytes = std::as_bytes(std::span(file));
  const auto back = readPngRgb8(bytes, "two.png", PngSizeLimit{.maxSide = 2, .maxPixels = 2});
  ASSERT_TRUE(back.has_value()) << back.error();
  EXPECT_EQ(back->pixels[1].g, 5);
  EXPECT_FALSE(readPngRgb8(bytes, "two.png", {.maxSide = 1, .maxPixels = 2}).has_value());
  EXPECT_FALSE(readPngRgb8(bytes, "two.png", {.maxSide = 2, .maxPixels = 1}).has_value());
  EXPECT_TRUE(readPngRgb8(path, PngSizeLimit::exactly(2, 1, "camera c")).has_value());
  EXPECT_FALSE(readPngRgb8(path, PngSizeLimit::exactly(1, 2, "camera c")).has_value());
  fs::remove(path);
}

// Given points, when written as PLY, then the header is the documented one and the points
// read back exactly.
TEST(SimIo, PlyPointsRoundTripWithTheDocumentedHeader) {
  const std::vector<PlyPoint> points = {{0.1F, -0.2F, 0.9F, 255, 0, 7},
                                        {1e-3F, 2.5F, 3.25F, 1, 2, 3}};
  const auto path = tempFile("cloud.ply");
  ASSERT_TRUE(writePlyPoints(path, points));
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment stripemux range output, metres\n"
      "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  ASSERT_EQ(text.substr(0, header.size()), header);
  EXPECT_EQ(text.size(), header.size() + 2 * 15);
  float x = 0;
  std::memcpy(&x, text.data() + header.size(), 4);
  EXPECT_EQ(x, 0.1F);
  const auto back = readPlyPoints(path);
  ASSERT_TRUE(back.has_value()) << back.error();
  ASSERT_EQ(back->size(), 2U);
  EXPECT_EQ((*back)[1].z, 3.25F);
  EXPECT_EQ((*back)[0].r, 255);
  EXPECT_EQ((*back)[0].b, 7);
  fs::remove(path);
}

TEST(SimIo, PlyReaderAcceptsAsciiAndRejectsTruncatedOrForeignFiles) {
  const auto ascii = tempFile("ascii.ply");
  std::ofstream(ascii) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n";
  const auto a = readPlyPoints(ascii);
  ASSERT_TRUE(a.has_value()) << a.error();
  EXPECT_EQ((*a)[1].y, 5.0F);

  const std::vector<PlyPoint> points(10);
  const auto cut = tempFile("cut.ply");
  ASSERT_TRUE(writePlyPoints(cut, points));
  fs::resize_file(cut, fs::file_size(cut) - 20);
  const auto truncated = readPlyPoints(cut);
  ASSERT_FALSE(truncated.has_value());
  EXPECT_NE(truncated.error().find("truncated"), std::string::npos) << truncated.error();

  // A corrupt vertex count must be rejected before anything is allocated for it.
  const auto huge = tempFile("huge.ply");
  std::ofstream(huge) << "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\n"
                         "property float x\nproperty float y\nproperty float z\nend_header\n";
  EXPECT_FALSE(readPlyPoints(huge).has_value());

  const auto mesh = tempFile("mesh.ply");
  std::ofstream(mesh) << "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                         "property float y\nproperty float z\nelement face 0\nend_header\n";
  EXPECT_FALSE(readPlyPoints(mesh).has_value());
  EXPECT_FALSE(readPlyPoints(tempFile("missing.ply")).has_value());
  for (const auto& p : {ascii, cut, huge, mesh}) {
    fs::remove(p);
  }
}

// Point clouds go through the mesh reader: its encodings, its checks and its messages.
TEST(SimIo, PlyPointsAreReadByTheMeshReaderWithColourAndItsChecks) {
  const auto write = [](const std::string& name, const std::string& bytes) {
    const auto path = tempFile(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  };
  const std::string colourHeader =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n";
  // Given ascii with colour, then big-endian binary (which the old point reader refused)
  const auto colour = write("colour.ply", colourHeader + "1 2 3 10 20 30\n4 5 6 255 0 1\n");
  const auto c = readPlyPoints(colour);
  ASSERT_TRUE(c.has_value()) << c.error();
  ASSERT_EQ(c->size(), 2U);
  EXPECT_EQ((*c)[1].x, 4.0F);
  EXPECT_EQ((*c)[0].g, 20);
  EXPECT_EQ((*c)[1].r, 255);
  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (const std::uint32_t bits : {0x3F800000U, 0x40000000U, 0xC0400000U}) {  // 1, 2, -3
    for (int shift = 24; shift >= 0; shift -= 8) {
      big += static_cast<char>((bits >> static_cast<unsigned>(shift)) & 0xFFU);
    }
  }
  const auto bigEndian = write("big.ply", big);
  const auto b = readPlyPoints(bigEndian);
  ASSERT_TRUE(b.has_value()) << b.error();
  ASSERT_EQ(b->size(), 1U);
  EXPECT_EQ((*b)[0].z, -3.0F);
  EXPECT_EQ((*b)[0].r, 0);

  // Then hostile values are refused with the file, the line and the problem
  const auto expectRefused = [&](const std::string& name, const std::string& bytes,
                                 const std::string& part) {
    const auto path = write(name, bytes);
    const auto r = readPlyPoints(path);
    ASSERT_FALSE(r.has_value()) << name;
    EXPECT_NE(r.error().find(path.string() + ": "), std::string::npos) << r.error();
    EXPECT_NE(r.error().find(part), std::string::npos) << r.error();
    fs::remove(path);
  };
  expectRefused("nan.ply", colourHeader + "1 2 3 0 0 0\nnan 5 6 0 0 0\n",
                "line 12: vertex 1: x is not a finite number");
  expectRefused("inf.ply", colourHeader + "1 2 inf 0 0 0\n4 5 6 0 0 0\n",
                "z is not a finite number");
  expectRefused("red.ply", colourHeader + "1 2 3 256 0 0\n4 5 6 0 0 0\n",
                "colour \"red\" = 256 is not an integer 0..255");
  expectRefused("short.ply", colourHeader + "1 2 3 0 0 0\n",
                "the file ends before vertex 1 of the 2");
  // A count below the 32-bit limit but far beyond the file: refused, not allocated.
  expectRefused("count.ply",
                "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                "property float x\nproperty float y\nproperty float z\nend_header\n",
                "the file ends before property \"x\"");
  expectRefused("count64.ply",
                "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\n"
                "property float y\nproperty float z\nend_header\n",
                "at most 4294967295 are supported");
  fs::remove(colour);
  fs::remove(bigEndian);
}

}  // namespace
}  // namespace smx::sim
