// rig.json (`stripemux-rig/1`): reading, the validation rules with their messages, writing, and
// the example rigs in boards/sim. Format: docs/rig-format.md.
#include "smx/config/rig_json.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "source_dir.hpp"

namespace smx::config {
namespace {

namespace fs = std::filesystem;
using algo::Camera;
using algo::DeviceModel;
using algo::Projector;
using algo::Rig;

const fs::path kSourceDir = smx::test::sourceDir();
const fs::path kTestData = kSourceDir / "tests/unit/testdata/rigs";

// Two cameras and two projectors, every value distinct so that one field can be replaced by text
// substitution and every index in an error path means something.
constexpr std::string_view kValidRig = R"({
  "format": "stripemux-rig/1",
  "cameras": [
    {"id": "cam0", "width": 640, "height": 480,
     "K": [800, 0, 319.5, 0, 801, 239.5, 0, 0, 1], "dist": [-0.08, 0.05, 0, 0, 0],
     "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0]},
    {"id": "cam1", "width": 1280, "height": 960,
     "K": [1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1],
     "dist": [0.01, -0.02, 0.001, -0.002, 0.003],
     "R": [0.8, 0, -0.6, 0, 1, 0, 0.6, 0, 0.8], "t": [0.25, -0.01, 0.02]}
  ],
  "projectors": [
    {"id": "proj0", "width": 1024, "height": 768,
     "K": [1400, 0, 511.5, 0, 1402, 383.5, 0, 0, 1], "dist": [0, 0, 0, 0, 0],
     "R": [0, -1, 0, 1, 0, 0, 0, 0, 1], "t": [-0.33, 0.001, 0.002],
     "pattern": {"angle_deg": 0, "stripe_px": 6, "offset_px": 0}},
    {"id": "proj1", "width": 800, "height": 600,
     "K": [1200, 0, 399.5, 0, 1203, 299.5, 0, 0, 1], "dist": [0.1, 0, 0, 0, 0.2],
     "R": [1, 0, 0, 0, 0.6, 0.8, 0, -0.8, 0.6], "t": [0.003, 0.33, 0.004],
     "pattern": {"angle_deg": 90, "stripe_px": 5.5, "offset_px": -2.25}}
  ]
})";

// kValidRig with the one occurrence of `from` replaced by `to`.
std::string validRigWith(std::string_view from, std::string_view to) {
  std::string text(kValidRig);
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: " << from << " not in kValidRig";
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "test bug: " << from << " not unique";
  if (at != std::string::npos) {
    text.replace(at, from.size(), to);
  }
  return text;
}

bool contains(std::string_view text, std::string_view part) {
  return text.find(part) != std::string_view::npos;
}

// Parses `text`, expects it to be rejected for `field`, with a problem mentioning each of `parts`.
void expectRejected(std::string_view text, std::string_view field,
                    std::initializer_list<std::string_view> parts) {
  const auto rig = parseRig(text);
  ASSERT_FALSE(rig.has_value()) << "accepted:\n" << text;
  EXPECT_EQ(rig.error().field, field) << rig.error().message();
  for (const auto part : parts) {
    EXPECT_TRUE(contains(rig.error().problem, part))
        << "problem \"" << rig.error().problem << "\" lacks \"" << part << "\"";
  }
  EXPECT_TRUE(rig.error().file.empty());
}

bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

template <std::size_t N>
bool sameBits(const std::array<double, N>& a, const std::array<double, N>& b) {
  return std::equal(a.begin(), a.end(), b.begin(),
                    [](double x, double y) { return sameBits(x, y); });
}

void expectSameDevice(const DeviceModel& a, const DeviceModel& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_TRUE(sameBits(a.K, b.K)) << a.id;
  EXPECT_TRUE(sameBits(a.dist, b.dist)) << a.id;
  EXPECT_TRUE(sameBits(a.R, b.R)) << a.id;
  EXPECT_TRUE(sameBits(a.t, b.t)) << a.id;
}

void expectSameRig(const Rig& a, const Rig& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  ASSERT_EQ(a.projectors.size(), b.projectors.size());
  for (std::size_t i = 0; i < a.cameras.size(); ++i) {
    expectSameDevice(a.cameras[i], b.cameras[i]);
  }
  for (std::size_t i = 0; i < a.projectors.size(); ++i) {
    expectSameDevice(a.projectors[i], b.projectors[i]);
    EXPECT_TRUE(sameBits(a.projectors[i].pattern.angleDeg, b.projectors[i].pattern.angleDeg));
    EXPECT_TRUE(sameBits(a.projectors[i].pattern.stripePx, b.projectors[i].pattern.stripePx));
    EXPECT_TRUE(sameBits(a.projectors[i].pattern.offsetPx, b.projectors[i].pattern.offsetPx));
  }
}

// ---------------------------------------------------------------------------------------------
// Reading valid rigs

// Given the valid rig text, when parsed, then every field lands in the matching member.
TEST(RigJson, ValidRigIsReadFieldByField) {
  const auto rig = parseRig(kValidRig);
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  ASSERT_EQ(rig->cameras.size(), 2U);
  ASSERT_EQ(rig->projectors.size(), 2U);

  const Camera& cam1 = rig->cameras[1];
  EXPECT_EQ(cam1.id, "cam1");
  EXPECT_EQ(cam1.width, 1280);
  EXPECT_EQ(cam1.height, 960);
  EXPECT_EQ(cam1.K, (std::array<double, 9>{1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1}));
  EXPECT_EQ(cam1.fx(), 1610.5);
  EXPECT_EQ(cam1.fy(), 1611.5);
  EXPECT_EQ(cam1.cx(), 640.25);
  EXPECT_EQ(cam1.cy(), 479.75);
  EXPECT_EQ(cam1.dist, (std::array<double, 5>{0.01, -0.02, 0.001, -0.002, 0.003}));
  EXPECT_EQ(cam1.R, (std::array<double, 9>{0.8, 0, -0.6, 0, 1, 0, 0.6, 0, 0.8}));
  EXPECT_EQ(cam1.t, (std::array<double, 3>{0.25, -0.01, 0.02}));

  const Projector& proj1 = rig->projectors[1];
  EXPECT_EQ(proj1.id, "proj1");
  EXPECT_EQ(proj1.width, 800);
  EXPECT_EQ(proj1.height, 600);
  EXPECT_EQ(proj1.K, (std::array<double, 9>{1200, 0, 399.5, 0, 1203, 299.5, 0, 0, 1}));
  EXPECT_EQ(proj1.dist, (std::array<double, 5>{0.1, 0, 0, 0, 0.2}));
  EXPECT_EQ(proj1.t, (std::array<double, 3>{0.003, 0.33, 0.004}));
  EXPECT_EQ(proj1.pattern.angleDeg, 90.0);
  EXPECT_EQ(proj1.pattern.stripePx, 5.5);
  EXPECT_EQ(proj1.pattern.offsetPx, -2.25);
  EXPECT_EQ(rig->projectors[0].id, "proj0");
  EXPECT_EQ(rig->projectors[0].pattern.stripePx, 6.0);
}

TEST(RigJson, WholeNumberWrittenWithFractionIsAnInteger) {
  const auto rig = parseRig(validRigWith("\"width\": 1280", "\"width\": 1280.0"));
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  EXPECT_EQ(rig->cameras[1].width, 1280);
}

// max |R*R^T - I| of 8e-7 is within the 1e-6 tolerance, 4e-6 is not.
TEST(RigJson, RotationToleranceIsOneMillionth) {
  EXPECT_TRUE(parseRig(validRigWith("\"R\": [1, 0, 0, 0, 1, 0, 0, 0, 1]",
                                    "\"R\": [1.0000004, 0, 0, 0, 1, 0, 0, 0, 1]"))
                  .has_value());
  expectRejected(validRigWith("\"R\": [1, 0, 0, 0, 1, 0, 0, 0, 1]",
                              "\"R\": [1.000002, 0, 0, 0, 1, 0, 0, 0, 1]"),
                 "cameras[0].R", {"not a rotation", "max |R*R^T - I| is 4e-06", "1e-06"});
}

// ---------------------------------------------------------------------------------------------
// One test per kind of error: the field path and the wording of the problem.

TEST(RigJsonErrors, MalformedJsonNamesLineAndColumn) {
  expectRejected("{\n  \"format\": \"stripemux-rig/1\"\n  \"cameras\": []\n}", "",
                 {"not valid JSON", "line 3, column"});
  expectRejected(" \n", "", {"not valid JSON", "the text is empty"});
  expectRejected(R"({"format": "stripemux-rig/1", "cameras": [)", "", {"not valid JSON"});
  // The parser quotes what it read; the message stays printable even for binary input.
  const auto binary = parseRig("{\"format\": \"\xff\x01\"}");
  ASSERT_FALSE(binary.has_value());
  EXPECT_TRUE(contains(binary.error().problem, "ill-formed UTF-8")) << binary.error().problem;
  EXPECT_TRUE(std::all_of(binary.error().problem.begin(), binary.error().problem.end(),
                          [](char c) { return c >= 0x20 && c < 0x7f; }));
}

TEST(RigJsonErrors, TopLevelMustBeAnObject) {
  expectRejected("[1, 2]", "", {"top level must be a JSON object", "got an array of 2 elements"});
  expectRejected("\"stripemux-rig/1\"", "", {"top level must be a JSON object", "got a string"});
}

TEST(RigJsonErrors, MissingFormat) {
  expectRejected(validRigWith("\"format\": \"stripemux-rig/1\",", ""), "format",
                 {"required field is missing", "\"format\": \"stripemux-rig/1\""});
}

TEST(RigJsonErrors, FormatMustBeAString) {
  expectRejected(validRigWith("\"stripemux-rig/1\"", "1"), "format",
                 {"must be a string", "got a number (1)"});
}

TEST(RigJsonErrors, UnsupportedFormatVersionSaysWhichIsSupported) {
  expectRejected(validRigWith("\"stripemux-rig/1\"", "\"stripemux-rig/2\""), "format",
                 {"unsupported version \"stripemux-rig/2\"", "supported: \"stripemux-rig/1\""});
  expectRejected(validRigWith("\"stripemux-rig/1\"", "\"camera-calibration\""), "format",
                 {"unknown format \"camera-calibration\"", "supported: \"stripemux-rig/1\""});
}

TEST(RigJsonErrors, MissingFieldIsNamedByItsPath) {
  expectRejected(validRigWith("\"dist\": [0.01, -0.02, 0.001, -0.002, 0.003],", ""),
                 "cameras[1].dist", {"required field is missing"});
  expectRejected(validRigWith(", \"offset_px\": -2.25", ""), "projectors[1].pattern.offset_px",
                 {"required field is missing"});
  expectRejected(
      validRigWith(",\n     \"pattern\": {\"angle_deg\": 0, \"stripe_px\": 6, \"offset_px\": 0}",
                   ""),
      "projectors[0].pattern", {"required field is missing"});
  expectRejected(R"({"format": "stripemux-rig/1", "cameras": [{"id": "c"}]})", "cameras[0].width",
                 {"required field is missing"});
  expectRejected(R"({"format": "stripemux-rig/1", "projectors": []})", "cameras",
                 {"required field is missing"});
}

TEST(RigJsonErrors, WrongTypeSaysWhatWasExpectedAndWhatWasFound) {
  expectRejected(validRigWith("0, 801, 239.5", "0, \"801\", 239.5"), "cameras[0].K[4]",
                 {"must be a number", "got a string (\"801\")"});
  expectRejected(validRigWith("\"width\": 800", "\"width\": true"), "projectors[1].width",
                 {"must be a number", "got a boolean (true)"});
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": 7"), "cameras[1].id",
                 {"must be a string", "got a number (7)"});
  expectRejected(validRigWith("\"t\": [0.25, -0.01, 0.02]", "\"t\": null"), "cameras[1].t",
                 {"must be an array of 3 numbers", "got null"});
  expectRejected(validRigWith("{\"angle_deg\": 90, \"stripe_px\": 5.5, \"offset_px\": -2.25}",
                              "[90, 5.5, -2.25]"),
                 "projectors[1].pattern", {"must be an object", "got an array of 3 elements"});
}

TEST(RigJsonErrors, DeviceListsMustBeArraysOfObjects) {
  expectRejected(R"({"format": "stripemux-rig/1", "cameras": {"id": "cam0"}})", "cameras",
                 {"must be an array of cameras", "got an object"});
  expectRejected(R"({"format": "stripemux-rig/1", "cameras": ["cam0"]})", "cameras[0]",
                 {"must be an object (one camera)", "got a string (\"cam0\")"});
}

TEST(RigJsonErrors, ArrayOfWrongLengthSaysExpectedAndGot) {
  expectRejected(validRigWith("1400, 0, 511.5, 0, 1402, 383.5, 0, 0, 1",
                              "1400, 0, 511.5, 0, 1402, 383.5, 0, 0"),
                 "projectors[0].K",
                 {"must be an array of 9 numbers", "got an array of 8 elements"});
  expectRejected(validRigWith("[0.1, 0, 0, 0, 0.2]", "[0.1, 0, 0, 0]"), "projectors[1].dist",
                 {"must be an array of 5 numbers", "k1 k2 p1 p2 k3", "got an array of 4 elements"});
  expectRejected(validRigWith("[0, -1, 0, 1, 0, 0, 0, 0, 1]", "[0, -1, 0, 1, 0, 0, 0, 0, 1, 0]"),
                 "projectors[0].R",
                 {"must be an array of 9 numbers", "got an array of 10 elements"});
  expectRejected(validRigWith("[0.003, 0.33, 0.004]", "[0.003, 0.33]"), "projectors[1].t",
                 {"must be an array of 3 numbers", "got an array of 2 elements"});
  expectRejected(validRigWith("[0.003, 0.33, 0.004]", "0.33"), "projectors[1].t",
                 {"must be an array of 3 numbers", "got a number (0.33)"});
}

// JSON has no NaN or infinity, but 1e999 overflows to infinity when read as a double.
TEST(RigJsonErrors, NumberTooLargeForADoubleIsNotFinite) {
  expectRejected(validRigWith("[0.003, 0.33, 0.004]", "[0.003, 0.33, 1e999]"), "projectors[1].t[2]",
                 {"must be a finite number", "too large"});
  expectRejected(validRigWith("\"angle_deg\": 90", "\"angle_deg\": -1e400"),
                 "projectors[1].pattern.angle_deg", {"must be a finite number"});
  expectRejected(validRigWith("\"width\": 640", "\"width\": 1e999"), "cameras[0].width",
                 {"must be a finite number"});
}

TEST(RigJsonErrors, ImageSizeMustBeAPositiveInteger) {
  expectRejected(validRigWith("\"width\": 640", "\"width\": 640.5"), "cameras[0].width",
                 {"must be a positive integer (pixels)", "got 640.5"});
  expectRejected(validRigWith("\"height\": 480", "\"height\": 0"), "cameras[0].height",
                 {"must be a positive integer (pixels)", "got 0"});
  expectRejected(validRigWith("\"height\": 768", "\"height\": -1"), "projectors[0].height",
                 {"must be a positive integer (pixels)", "got -1"});
  expectRejected(validRigWith("\"width\": 800", "\"width\": 100000"), "projectors[1].width",
                 {"must be from 16 to 8192 pixels", "got 100000"});
}

TEST(RigJsonErrors, StripeWidthMustBePositive) {
  expectRejected(validRigWith("\"stripe_px\": 5.5", "\"stripe_px\": 0"),
                 "projectors[1].pattern.stripe_px", {"must be positive", "got 0"});
  expectRejected(validRigWith("\"stripe_px\": 6", "\"stripe_px\": -6"),
                 "projectors[0].pattern.stripe_px", {"must be positive", "got -6"});
}

// Values no real rig has are refused naming the field, before anything is sized from them.
TEST(RigJsonErrors, PhysicallyImplausibleValuesAreRefused) {
  expectRejected(validRigWith("\"width\": 640", "\"width\": 65535"), "cameras[0].width",
                 {"must be from 16 to 8192 pixels", "got 65535"});
  expectRejected(validRigWith("\"height\": 480", "\"height\": 8"), "cameras[0].height",
                 {"must be from 16 to 8192 pixels", "got 8"});
  expectRejected(validRigWith("\"stripe_px\": 6", "\"stripe_px\": 1e-300"),
                 "projectors[0].pattern.stripe_px", {"must be at least 1", "got 1e-300"});
  expectRejected(validRigWith("\"stripe_px\": 6", "\"stripe_px\": 1e300"), "projectors[0].pattern",
                 {"shows 0 whole stripes", "1024x768", "window of 7"});
  expectRejected(validRigWith("\"offset_px\": -2.25", "\"offset_px\": -1e6"),
                 "projectors[1].pattern", {"shows 0 whole stripes"});
  expectRejected(validRigWith("\"angle_deg\": 90", "\"angle_deg\": 1e300"),
                 "projectors[1].pattern.angle_deg", {"from -360 to 360", "got 1e+300"});
  const std::string k = "1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1";
  expectRejected(validRigWith(k, "1e9, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1"), "cameras[1].K[0]",
                 {"fx (0.1 to 100 times the width)", "128 to 128000", "got 1000000000"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 1e-3, 479.75, 0, 0, 1"), "cameras[1].K[4]",
                 {"fy (0.1 to 100 times the height)", "got 0.001"});
  expectRejected(validRigWith(k, "1610.5, 0, -1e5, 0, 1611.5, 479.75, 0, 0, 1"), "cameras[1].K[2]",
                 {"cx", "got -100000"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 1611.5, 1e7, 0, 0, 1"), "cameras[1].K[5]",
                 {"cy", "got 10000000"});
  expectRejected(validRigWith("\"dist\": [0.1, 0, 0, 0, 0.2]", "\"dist\": [0.1, 0, 0, 0, 1e5]"),
                 "projectors[1].dist[4]", {"distortion", "got 100000"});
  expectRejected(validRigWith("\"t\": [0.25, -0.01, 0.02]", "\"t\": [0.25, -1e4, 0.02]"),
                 "cameras[1].t[1]", {"translation", "got -10000"});
}

// The method separates up to three pattern orientations in one image; a rig with more projectors
// (or more cameras than a board reads) is refused at the list, not later by a pipeline stage.
TEST(RigJsonErrors, DeviceCountsAreBounded) {
  const std::string projector = R"({"id": "pX", "width": 800, "height": 600,
     "K": [1200, 0, 399.5, 0, 1203, 299.5, 0, 0, 1], "dist": [0, 0, 0, 0, 0],
     "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0],
     "pattern": {"angle_deg": 0, "stripe_px": 6, "offset_px": 0}})";
  std::string extra;
  for (int i = 0; i < 8; ++i) {
    std::string p = projector;
    p.replace(p.find("pX"), 2, "p" + std::to_string(i));
    extra += ",\n" + p;
  }
  expectRejected(validRigWith("\"offset_px\": -2.25}}", "\"offset_px\": -2.25}}" + extra),
                 "projectors", {"at most 3 projectors", "got 10"});
  std::string cameras;
  for (int i = 0; i < 17; ++i) {
    cameras += std::string(i == 0 ? "" : ",\n") + R"({"id": "c)" + std::to_string(i) +
               R"(", "width": 640, "height": 480, "K": [800, 0, 319.5, 0, 801, 239.5, 0, 0, 1],
     "dist": [0, 0, 0, 0, 0], "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0]})";
  }
  std::string text(kValidRig);
  const auto begin = text.find('[', text.find("\"cameras\"")) + 1;
  const auto end = text.find("\n  ],\n  \"projectors\"");
  text.replace(begin, end - begin, cameras);
  expectRejected(text, "cameras", {"at most 16 cameras", "got 17"});
}

// Ids name output files and reach terminals: a name from a small alphabet, never a path.
TEST(RigJsonErrors, IdsAreNamesNotPaths) {
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"../../etc/passwd\""), "cameras[1].id",
                 {"must start with a letter or digit"});
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"/tmp/x\""), "cameras[1].id",
                 {"must start with a letter or digit"});
  expectRejected(validRigWith("\"id\": \"proj0\"", "\"id\": \"p/../../x\""), "projectors[0].id",
                 {"has a character that is not allowed"});
  expectRejected(validRigWith("\"id\": \"proj0\"", "\"id\": \"p0.png\\u0000\""), "projectors[0].id",
                 {"has a character that is not allowed", "\\u0000"});
  expectRejected(validRigWith("\"id\": \"proj0\"", "\"id\": \"p\\u001b[31m\""), "projectors[0].id",
                 {"has a character that is not allowed", "\\u001b"});
  expectRejected(validRigWith("\"id\": \"proj0\"", "\"id\": \"" + std::string(33, 'p') + "\""),
                 "projectors[0].id", {"is 33 characters long"});
  // The longest id and every allowed character are fine.
  const auto ok =
      parseRig(validRigWith("\"id\": \"proj0\"", "\"id\": \"Aa0_-." + std::string(26, 'z') + "\""));
  EXPECT_TRUE(ok.has_value()) << ok.error().message();
}

TEST(RigJsonErrors, CameraMatrixMustHaveTheOpenCvStructure) {
  const std::string k = "1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1";
  expectRejected(validRigWith(k, "-1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1"),
                 "cameras[1].K[0]", {"fx must be positive", "got -1610.5"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 0, 479.75, 0, 0, 1"), "cameras[1].K[4]",
                 {"fy must be positive", "got 0"});
  expectRejected(validRigWith(k, "1610.5, 0.5, 640.25, 0, 1611.5, 479.75, 0, 0, 1"),
                 "cameras[1].K[1]", {"skew must be 0", "[fx 0 cx; 0 fy cy; 0 0 1]", "got 0.5"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 2, 1611.5, 479.75, 0, 0, 1"),
                 "cameras[1].K[3]", {"must be 0", "[fx 0 cx; 0 fy cy; 0 0 1]", "got 2"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 1611.5, 479.75, 0.001, 0, 1"),
                 "cameras[1].K[6]", {"must be 0", "got 0.001"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, -3, 1"),
                 "cameras[1].K[7]", {"must be 0", "got -3"});
  expectRejected(validRigWith(k, "1610.5, 0, 640.25, 0, 1611.5, 479.75, 0, 0, 1610.5"),
                 "cameras[1].K[8]", {"must be 1", "got 1610.5"});
}

TEST(RigJsonErrors, RotationMustBeOrthonormalAndReportsTheDeviation) {
  // Scaled by 1.01: R*R^T = 1.0201 I.
  expectRejected(validRigWith("[1, 0, 0, 0, 0.6, 0.8, 0, -0.8, 0.6]",
                              "[1.01, 0, 0, 0, 0.606, 0.808, 0, -0.808, 0.606]"),
                 "projectors[1].R", {"not a rotation", "max |R*R^T - I| is 0.0201"});
}

TEST(RigJsonErrors, ReflectionIsNotARotation) {
  expectRejected(validRigWith("[0.8, 0, -0.6, 0, 1, 0, 0.6, 0, 0.8]",
                              "[0.8, 0, -0.6, 0, 1, 0, -0.6, 0, -0.8]"),
                 "cameras[1].R", {"not a rotation", "det R is -1", "reflection"});
}

TEST(RigJsonErrors, IdsMustBeNonEmptyAndUniqueAcrossDevices) {
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"\""), "cameras[1].id",
                 {"must not be empty"});
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"cam0\""), "cameras[1].id",
                 {"\"cam0\" is already the id of cameras[0]", "unique"});
  expectRejected(
      validRigWith("\"id\": \"proj1\"", "\"id\": \"cam1\""), "projectors[1].id",
      {"\"cam1\" is already the id of cameras[1]", "unique across cameras and projectors"});
}

TEST(RigJsonErrors, AtLeastOneCameraAndOneProjector) {
  expectRejected(R"({"format": "stripemux-rig/1", "cameras": [], "projectors": []})", "cameras",
                 {"at least one camera is required", "got none"});
  const std::string noProjectors =
      std::string(kValidRig.substr(0, kValidRig.find("\"projectors\": [") + 15)) + "]}";
  expectRejected(noProjectors, "projectors", {"at least one projector is required", "got none"});
}

// Unknown keys are rejected rather than ignored: a misspelt key must not silently fall back.
TEST(RigJsonErrors, UnknownKeyIsRejectedWithASuggestion) {
  expectRejected(validRigWith("\"stripe_px\": 5.5", "\"strip_px\": 5.5"), "projectors[1].pattern",
                 {"unknown key \"strip_px\"", "did you mean \"stripe_px\"?",
                  "allowed keys: angle_deg, stripe_px, offset_px"});
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"cam1\", \"k\": []"), "cameras[1]",
                 {"unknown key \"k\"", "did you mean \"K\"?"});
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"cam1\", \"fx\": 800"), "cameras[1]",
                 {"unknown key \"fx\"; allowed keys: id, width, height, K, dist, R, t"});
  expectRejected(
      validRigWith("\"id\": \"cam0\"", "\"id\": \"cam0\", \"pattern\": {\"angle_deg\": 0}"),
      "cameras[0]", {"unknown key \"pattern\"", "cameras have no pattern"});
  expectRejected(validRigWith("\"cameras\"", "\"camera\""), "",
                 {"unknown key \"camera\"", "did you mean \"cameras\"?"});
}

// nlohmann would keep the last of two equal keys; that hides a mistake.
TEST(RigJsonErrors, DuplicateKeyIsRejected) {
  expectRejected(
      validRigWith("\"t\": [0.003, 0.33, 0.004]", "\"t\": [0.003, 0.33, 0.004], \"t\": [0, 0, 0]"),
      "projectors[1]", {"key \"t\" appears more than once"});
  expectRejected(validRigWith("\"offset_px\": 0}", "\"offset_px\": 0, \"offset_px\": 1}"),
                 "projectors[0].pattern", {"key \"offset_px\" appears more than once"});
}

// A rig.json is a few kB and 4 levels deep; far larger or deeper input is refused before it is
// parsed, so it cannot exhaust the board's memory.
TEST(RigJsonErrors, OversizedOrDeeplyNestedTextIsRefused) {
  expectRejected(std::string(kValidRig) + std::string(std::size_t{1} << 20U, ' '), "",
                 {"bytes; a rig.json is at most 1048576 bytes"});
  const std::string deep = std::string(100, '[') + std::string(100, ']');
  expectRejected(deep, "", {"nested 100 levels deep", "at most 16"});
  // Brackets inside strings do not count: the id's own rule refuses this one, not the nesting.
  expectRejected(validRigWith("\"id\": \"cam1\"", "\"id\": \"[[[[[[[[[[[[[[[[[[[[\""),
                 "cameras[1].id", {"must start with a letter or digit"});
}

// ---------------------------------------------------------------------------------------------
// Files and messages

TEST(RigJsonLoad, ReadsAFile) {
  const auto rig = loadRig(kTestData / "one_camera_one_projector.json");
  ASSERT_TRUE(rig.has_value()) << rig.error().message();
  ASSERT_EQ(rig->projectors.size(), 1U);
  EXPECT_EQ(rig->projectors[0].t, (std::array<double, 3>{-0.3, 0, 0.2}));
}

TEST(RigJsonLoad, InvalidFileErrorNamesFileFieldAndProblem) {
  const fs::path path = kTestData / "mirrored_projector.json";
  const auto rig = loadRig(path);
  ASSERT_FALSE(rig.has_value());
  EXPECT_EQ(rig.error().file, path.string());
  EXPECT_EQ(rig.error().field, "projectors[0].R");
  EXPECT_EQ(rig.error().message(), path.string() + ": projectors[0].R: " + rig.error().problem);
  EXPECT_TRUE(contains(rig.error().problem, "det R is -1")) << rig.error().problem;
}

TEST(RigJsonLoad, UnreadableFileIsAnErrorNotAnException) {
  const fs::path missing = kTestData / "no_such_rig.json";
  const auto rig = loadRig(missing);
  ASSERT_FALSE(rig.has_value());
  EXPECT_EQ(rig.error().file, missing.string());
  EXPECT_TRUE(rig.error().field.empty());
  EXPECT_TRUE(contains(rig.error().message(), "no_such_rig.json: cannot read the file"))
      << rig.error().message();

  const auto directory = loadRig(kTestData);
  ASSERT_FALSE(directory.has_value());
  EXPECT_TRUE(contains(directory.error().message(), "is a directory"))
      << directory.error().message();
}

TEST(RigJsonLoad, MessageLeavesOutEmptyParts) {
  EXPECT_EQ((RigError{"rig.json", "cameras[0].K[4]", "fy must be positive, got 0"}.message()),
            "rig.json: cameras[0].K[4]: fy must be positive, got 0");
  EXPECT_EQ((RigError{"", "format", "required field is missing"}.message()),
            "format: required field is missing");
  EXPECT_EQ((RigError{"rig.json", "", "not valid JSON: line 1"}.message()),
            "rig.json: not valid JSON: line 1");
}

// ---------------------------------------------------------------------------------------------
// Writing

// Rodrigues' formula, for rotations that are not tidy fractions.
std::array<double, 9> rotationFromAxisAngle(std::array<double, 3> axis, double angle) {
  const double n = std::hypot(axis[0], axis[1], axis[2]);
  const double x = axis[0] / n;
  const double y = axis[1] / n;
  const double z = axis[2] / n;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double C = 1 - c;
  return {c + x * x * C,     x * y * C - z * s, x * z * C + y * s,  //
          y * x * C + z * s, c + y * y * C,     y * z * C - x * s,  //
          z * x * C - y * s, z * y * C + x * s, c + z * z * C};
}

Rig awkwardRig(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  // Values as odd as the rules allow: sizes, principal points, the largest distortion.
  auto fill = [&](DeviceModel& d, const std::string& id) {
    d.id = id;
    d.width = 200 + static_cast<int>(rng() % 3800U);
    d.height = 200 + static_cast<int>(rng() % 2800U);
    d.K = {500 + 1000 * std::abs(unit(rng)),
           0,
           d.width * (0.5 + 0.4 * unit(rng)),
           0,
           1.0 / 3.0 + 900,
           0.1,
           0,
           0,
           1};
    d.dist = {unit(rng) * 1e-300, -0.0, unit(rng), 1e-17 * unit(rng), 99.999999999999986};
    d.R = rotationFromAxisAngle({unit(rng), unit(rng), unit(rng)}, 3 * unit(rng));
    d.t = {unit(rng), 0.1, -2.5e-9};
  };
  Rig rig;
  rig.cameras.resize(2);
  fill(rig.cameras[0], "Cam_left-0.a");  // every kind of character an id may have
  fill(rig.cameras[1], "cam-1");
  rig.projectors.resize(3);
  for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
    fill(rig.projectors[i], "proj" + std::to_string(i));
    rig.projectors[i].pattern = {360 * unit(rng), 1 + 7 * std::abs(unit(rng)), -1.0 / 7.0};
  }
  return rig;
}

// Given rigs full of numbers that need all 17 digits, when written and read back, then every
// double has the same bits.
TEST(RigJsonWrite, RoundTripsExactly) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const Rig rig = awkwardRig(seed);
    ASSERT_TRUE(validateRig(rig).has_value()) << validateRig(rig).error().message();
    const std::string text = toJson(rig);
    const auto back = parseRig(text);
    ASSERT_TRUE(back.has_value()) << back.error().message() << "\n" << text;
    expectSameRig(rig, *back);
  }
}

TEST(RigJsonWrite, ValidRigTextRoundTrips) {
  const auto rig = parseRig(kValidRig);
  ASSERT_TRUE(rig.has_value());
  const auto back = parseRig(toJson(*rig));
  ASSERT_TRUE(back.has_value()) << back.error().message();
  expectSameRig(*rig, *back);
}

TEST(RigJsonWrite, NonFiniteNumberIsRejectedInMemoryAndWrittenAsNull) {
  Rig rig = awkwardRig(7);
  rig.projectors[2].K[2] = std::nan("");
  const auto checked = validateRig(rig);
  ASSERT_FALSE(checked.has_value());
  EXPECT_EQ(checked.error().field, "projectors[2].K[2]");
  EXPECT_EQ(checked.error().problem, "must be a finite number, got nan");
  expectRejected(toJson(rig), "projectors[2].K[2]", {"must be a number", "got null"});
}

TEST(RigJsonWrite, ValidateRigAppliesTheSameRules) {
  Rig rig = awkwardRig(3);
  rig.projectors[1].id = rig.cameras[1].id;
  auto checked = validateRig(rig);
  ASSERT_FALSE(checked.has_value());
  EXPECT_EQ(checked.error().field, "projectors[1].id");

  rig = awkwardRig(3);
  rig.cameras[0].width = 0;
  checked = validateRig(rig);
  ASSERT_FALSE(checked.has_value());
  EXPECT_EQ(checked.error().message(),
            "cameras[0].width: must be a positive integer (pixels), got 0");

  rig = awkwardRig(3);
  rig.projectors.clear();
  checked = validateRig(rig);
  ASSERT_FALSE(checked.has_value());
  EXPECT_EQ(checked.error().field, "projectors");
}

// ---------------------------------------------------------------------------------------------
// The example rigs in boards/sim (written by tools/host/make_example_rigs.py)

const std::set<std::string> kExampleRigs = {"rig_2proj_1cam.json", "rig_2proj_2cam.json",
                                            "rig_3proj_1cam.json", "rig_3proj_2cam.json"};

std::vector<fs::path> exampleRigFiles() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kSourceDir / "boards/sim")) {
    // The board's own board.json lives beside its rigs.
    if (entry.path().extension() == ".json" && entry.path().filename() != "board.json") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(ExampleRigs, EveryRigInBoardsSimParsesAndRoundTrips) {
  const auto files = exampleRigFiles();
  std::set<std::string> names;
  for (const auto& file : files) {
    names.insert(file.filename().string());
    const auto rig = loadRig(file);
    ASSERT_TRUE(rig.has_value()) << rig.error().message();
    const auto back = parseRig(toJson(*rig));
    ASSERT_TRUE(back.has_value()) << back.error().message();
    expectSameRig(*rig, *back);
  }
  for (const auto& name : kExampleRigs) {
    EXPECT_TRUE(names.contains(name)) << name << " missing from boards/sim";
  }
}

// Independent geometry for the realism checks (OpenCV model, world = cam0's frame).
using Vec3 = std::array<double, 3>;
using Vec2 = std::array<double, 2>;

constexpr double kDeg = std::numbers::pi / 180.0;

Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Vec3 operator*(double s, const Vec3& a) {
  return {s * a[0], s * a[1], s * a[2]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double angleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(a, b) / std::sqrt(dot(a, a) * dot(b, b)), -1.0, 1.0)) / kDeg;
}

Vec3 centre(const DeviceModel& d) {  // -R^T t
  Vec3 c{};
  for (std::size_t i = 0; i < 3; ++i) {
    c[i] = -(d.R[i] * d.t[0] + d.R[3 + i] * d.t[1] + d.R[6 + i] * d.t[2]);
  }
  return c;
}

Vec3 opticalAxis(const DeviceModel& d) {
  return {d.R[6], d.R[7], d.R[8]};
}

Vec2 distort(const DeviceModel& d, double x, double y) {
  const auto& [k1, k2, p1, p2, k3] = d.dist;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

std::optional<Vec2> project(const DeviceModel& d, const Vec3& X) {
  Vec3 xd{};
  for (std::size_t i = 0; i < 3; ++i) {
    xd[i] = d.R[3 * i] * X[0] + d.R[3 * i + 1] * X[1] + d.R[3 * i + 2] * X[2] + d.t[i];
  }
  if (xd[2] <= 0) {
    return std::nullopt;
  }
  const Vec2 n = distort(d, xd[0] / xd[2], xd[1] / xd[2]);
  return Vec2{d.fx() * n[0] + d.cx(), d.fy() * n[1] + d.cy()};
}

// World direction of the ray through pixel (u, v); distortion inverted by fixed-point iteration.
Vec3 pixelRay(const DeviceModel& d, const Vec2& uv) {
  const double xd = (uv[0] - d.cx()) / d.fx();
  const double yd = (uv[1] - d.cy()) / d.fy();
  double x = xd;
  double y = yd;
  for (int i = 0; i < 50; ++i) {
    const Vec2 f = distort(d, x, y);
    x += xd - f[0];
    y += yd - f[1];
  }
  const Vec3 dev = {x, y, 1};
  Vec3 world{};
  for (std::size_t i = 0; i < 3; ++i) {
    world[i] = d.R[i] * dev[0] + d.R[3 + i] * dev[1] + d.R[6 + i] * dev[2];
  }
  return world;
}

bool inside(const DeviceModel& d, const std::optional<Vec2>& uv) {
  return uv && (*uv)[0] >= 0 && (*uv)[1] >= 0 && (*uv)[0] <= d.width - 1 &&
         (*uv)[1] <= d.height - 1;
}

Vec2 encodingAxis(const Projector& p) {
  return {std::cos(p.pattern.angleDeg * kDeg), std::sin(p.pattern.angleDeg * kDeg)};
}

// Angle between two image lines (directions mod 180 deg), in [0, 90].
double lineAngleDeg(const Vec2& a, const Vec2& b) {
  const double c =
      std::abs(a[0] * b[0] + a[1] * b[1]) / (std::hypot(a[0], a[1]) * std::hypot(b[0], b[1]));
  return std::acos(std::min(c, 1.0)) / kDeg;
}

class ExampleRig : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    auto loaded = loadRig(kSourceDir / "boards/sim" / GetParam());
    ASSERT_TRUE(loaded.has_value()) << loaded.error().message();
    rig_ = std::move(*loaded);
    const Camera& cam0 = rig_.cameras.front();
    c0_ = centre(cam0);
    axis0_ = opticalAxis(cam0);
  }
  Vec3 target(double depthM) const { return c0_ + depthM * axis0_; }

  Rig rig_;
  Vec3 c0_{};
  Vec3 axis0_{};
};

TEST_P(ExampleRig, WorldFrameIsCam0AndDevicesAreTypical) {
  const Camera& cam0 = rig_.cameras.front();
  EXPECT_EQ(cam0.id, "cam0");
  EXPECT_EQ(cam0.R, (std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(cam0.t, (std::array<double, 3>{0, 0, 0}));
  for (const Camera& c : rig_.cameras) {
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.height, 480);
    EXPECT_NEAR(c.fx(), 800, 100) << c.id;
  }
  for (const Projector& p : rig_.projectors) {
    EXPECT_EQ(p.width, 1024);
    EXPECT_EQ(p.height, 768);
    EXPECT_NEAR(p.fx(), 1400, 200) << p.id;
  }
}

// Triangulation angle at points on cam0's axis across the working range 0.6-1.2 m.
TEST_P(ExampleRig, EveryCameraProjectorPairTriangulatesAt15To30Degrees) {
  for (const double depth : {0.6, 0.9, 1.2}) {
    const Vec3 X = target(depth);
    for (const Camera& c : rig_.cameras) {
      for (const Projector& p : rig_.projectors) {
        const double angle = angleDeg(centre(c) - X, centre(p) - X);
        EXPECT_GE(angle, 15.0) << c.id << "-" << p.id << " at " << depth << " m";
        EXPECT_LE(angle, 30.0) << c.id << "-" << p.id << " at " << depth << " m";
      }
    }
  }
}

TEST_P(ExampleRig, TargetIsInsideEveryImage) {
  for (const double depth : {0.6, 0.9, 1.2}) {
    const Vec3 X = target(depth);
    for (const Camera& c : rig_.cameras) {
      EXPECT_TRUE(inside(c, project(c, X))) << c.id << " at " << depth << " m";
    }
    for (const Projector& p : rig_.projectors) {
      EXPECT_TRUE(inside(p, project(p, X))) << p.id << " at " << depth << " m";
    }
  }
}

// Each projector's encoding axis as cam0 sees it: two projector pixels one pixel either side of
// the target along the axis, cast onto the fronto-parallel plane at 0.9 m, projected into cam0.
struct Cam0View {
  Vec2 direction;
  double pxPerStripe;
};

Cam0View seenFromCam0(const Camera& cam0, const Vec3& c0, const Vec3& axis0, const Projector& p) {
  const Vec3 X = c0 + 0.9 * axis0;
  const auto centrePx = project(p, X);
  EXPECT_TRUE(centrePx.has_value());
  const Vec2 a = encodingAxis(p);
  std::array<Vec2, 2> seen{};
  for (std::size_t i = 0; i < 2; ++i) {
    const double step = i == 0 ? -1.0 : 1.0;
    const Vec2 uv = {(*centrePx)[0] + step * a[0], (*centrePx)[1] + step * a[1]};
    const Vec3 ray = pixelRay(p, uv);
    const Vec3 pc = centre(p);
    const double s = dot(X - pc, axis0) / dot(ray, axis0);  // meet the plane through X
    const auto q = project(cam0, pc + s * ray);
    EXPECT_TRUE(q.has_value());
    seen[i] = *q;
  }
  const Vec2 d = {seen[1][0] - seen[0][0], seen[1][1] - seen[0][1]};
  return {d, std::hypot(d[0], d[1]) / 2 * p.pattern.stripePx};
}

TEST_P(ExampleRig, ProjectorAxesAreSpreadEvenlyInCam0) {
  const std::size_t n = rig_.projectors.size();
  ASSERT_GE(n, 2U);
  const double nominal = 180.0 / static_cast<double>(n);  // 90 deg for two, 60 for three
  std::vector<Cam0View> views;
  for (const Projector& p : rig_.projectors) {
    views.push_back(seenFromCam0(rig_.cameras.front(), c0_, axis0_, p));
    // A decoder needs ~3 camera pixels per stripe; much wider stripes waste resolution.
    EXPECT_GE(views.back().pxPerStripe, 3.0) << p.id;
    EXPECT_LE(views.back().pxPerStripe, 6.0) << p.id;
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      EXPECT_NEAR(lineAngleDeg(views[i].direction, views[j].direction), nominal, 15.0)
          << rig_.projectors[i].id << " vs " << rig_.projectors[j].id;
    }
  }
}

// A pair triangulates well when the epipolar line in the projector image runs along the encoding
// axis (stripe planes cut the camera ray steeply); at 90 deg the pair measures nothing.
TEST_P(ExampleRig, EncodingAxesFollowTheBaselines) {
  const Vec3 X = target(0.9);
  for (const Camera& c : rig_.cameras) {
    const Vec3 cc = centre(c);
    for (const Projector& p : rig_.projectors) {
      const auto near = project(p, cc + 0.95 * (X - cc));
      const auto far = project(p, cc + 1.05 * (X - cc));
      ASSERT_TRUE(near && far);
      const Vec2 epipolar = {(*far)[0] - (*near)[0], (*far)[1] - (*near)[1]};
      const double alignment = std::cos(lineAngleDeg(epipolar, encodingAxis(p)) * kDeg);
      // One camera: each axis lies along its own baseline. Two cameras: a compromise.
      EXPECT_GE(alignment, rig_.cameras.size() == 1 ? 0.999 : 0.4) << c.id << "-" << p.id;
    }
  }
}

std::string rigTestName(const ::testing::TestParamInfo<std::string>& param) {
  return param.param.substr(0, param.param.find('.'));
}

INSTANTIATE_TEST_SUITE_P(BoardsSim, ExampleRig, ::testing::ValuesIn(kExampleRigs), rigTestName);

}  // namespace
}  // namespace smx::config
