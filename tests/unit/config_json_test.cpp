// hal/config: the JSON checks shared by the configuration readers (rig.json, scene.json, ...),
// tested on a made-up document kind so that nothing here depends on one format. The readers'
// own tests (rig_json_test.cpp, sim_scene_test.cpp) cover the same wording in context.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"
#include "smx/config/json_paths.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/json_text.hpp"
#include "smx/config/rotation_check.hpp"

namespace smx::config {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr std::array<std::string_view, 3> kTopKeys = {"format", "ports", "stripe_px"};
constexpr std::array<FormatHint, 1> kOtherFormats = {
    {{"stripemux-rig/", " (this is a rig.json, not a board)"}}};
constexpr DocumentSpec kBoard = {.name = "board.json",
                                 .format = "stripemux-board/1",
                                 .topKeys = kTopKeys,
                                 .maxBytes = 200,
                                 .sizeNote = " (no firmware images here)",
                                 .nestingNeeded = 3,
                                 .maxNesting = 4,
                                 .otherFormats = kOtherFormats};

std::string problemOf(std::string_view text) {
  const auto doc = parseDocument(text, kBoard);
  return doc ? std::string("accepted") : doc.error().field + ": " + doc.error().problem;
}

TEST(ConfigJsonPaths, BuildMembersAndElements) {
  EXPECT_EQ(member("", "ports"), "ports");
  EXPECT_EQ(member(element("ports", 2), "pin"), "ports[2].pin");
}

TEST(ConfigJsonErrors, MessageLeavesOutEmptyParts) {
  EXPECT_EQ(errorMessage("board.json", "ports[0]", "must be an object"),
            "board.json: ports[0]: must be an object");
  EXPECT_EQ(errorMessage("", "ports", "required field is missing"),
            "ports: required field is missing");
  EXPECT_EQ(errorMessage("board.json", "", "not valid JSON"), "board.json: not valid JSON");
}

// Given numbers of every kind, when formatted, then each reads back as the same double.
TEST(ConfigJsonText, FormatNumberIsShortestAndReadsBack) {
  EXPECT_EQ(formatNumber(100000), "100000");
  EXPECT_EQ(formatNumber(0.0125), "0.0125");
  EXPECT_EQ(formatNumber(1e-5), "1e-05");
  EXPECT_EQ(formatNumber(1e300), "1e+300");
  EXPECT_EQ(formatNumber(-0.0), "-0.0");
  EXPECT_EQ(formatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(formatNumber(std::nan("")), "nan");
  for (const double v : {0.1, 1.0 / 3.0, 6.02214076e23, -2.5e-300}) {
    EXPECT_EQ(std::stod(formatNumber(v)), v) << formatNumber(v);
  }
  EXPECT_EQ(formatDeviation(0.020134), "0.0201");
}

TEST(ConfigJsonText, DescribeSaysWhatWasFound) {
  EXPECT_EQ(describe(Json::parse(R"("800")")), R"(a string ("800"))");
  EXPECT_EQ(describe(Json::parse("[1]")), "an array of 1 element");
  EXPECT_EQ(describe(Json::parse("[1, 2]")), "an array of 2 elements");
  EXPECT_EQ(describe(Json::parse("false")), "a boolean (false)");
  EXPECT_EQ(describe(Json::parse("2.5")), "a number (2.5)");
  EXPECT_EQ(describe(Json(std::string(50, 'x'))), "a string (\"" + std::string(40, 'x') + "\"...)");
  EXPECT_EQ(jsonQuote("a\"b\xff"), R"("a\"b�")");
}

// Given a misspelt key, when checked, then the likely meant key is suggested, and only then.
TEST(ConfigJsonKeys, SuggestsOnlyCloseKeys) {
  constexpr std::array<std::string_view, 4> kAllowed = {"K", "stripe_px", "angle_deg", "id"};
  EXPECT_EQ(closestWord("k", kAllowed), "K");                 // case
  EXPECT_EQ(closestWord("strip_px", kAllowed), "stripe_px");  // one edit
  EXPECT_EQ(closestWord("angle", kAllowed), "angle_deg");     // prefix
  EXPECT_EQ(closestWord("fx", kAllowed), "");                 // two edits of two letters
  EXPECT_EQ(unknownKeyProblem("strip_px", kAllowed),
            R"(unknown key "strip_px" (did you mean "stripe_px"?); allowed keys: K, stripe_px, )"
            "angle_deg, id");
  EXPECT_EQ(unknownKeyProblem("pattern", kAllowed, "cameras have no pattern"),
            R"(unknown key "pattern" (cameras have no pattern); allowed keys: K, stripe_px, )"
            "angle_deg, id");
  EXPECT_EQ(unknownKey(Json::parse(R"({"K": 1, "Id": 2})"), kAllowed), "Id");
  EXPECT_EQ(unknownKey(Json::parse(R"({"K": 1})"), kAllowed), std::nullopt);
}

TEST(ConfigJsonReader, NestingDepthIgnoresBracketsInStrings) {
  EXPECT_EQ(nestingDepth(R"({"a": [[1], {"b": "[[[{"}]})"), 3U);
  EXPECT_EQ(nestingDepth(R"(["\"[[", 1])"), 1U);
}

// Given documents with one problem each, when parsed, then the first common check that fails
// names the field, in the documented order.
TEST(ConfigJsonReader, ReportsTheCommonProblems) {
  EXPECT_EQ(problemOf(R"({"format": "stripemux-board/1", "ports": [1]})"), "accepted");
  EXPECT_EQ(
      problemOf(" \n"),
      R"(: not valid JSON: the text is empty; a board.json is a JSON object {"format": ...})");
  EXPECT_EQ(problemOf(std::string(201, ' ') + "{}"),
            ": the text is 203 bytes; a board.json is at most 200 bytes (no firmware images here)");
  EXPECT_EQ(problemOf("[[[[[1]]]]]"),
            ": nested 5 levels deep; a board.json needs 3 and at most 4 are accepted");
  // Bytes the parser quotes are kept printable.
  EXPECT_EQ(problemOf("{\"format\": \xe9}"),
            ": not valid JSON: line 1, column 12: syntax error while parsing value - invalid "
            "literal; last read: '\"format\": ?'");
  EXPECT_EQ(problemOf(R"({"ports": [{"pin": 1}, {"pin": [2, 1e999]}]})"),
            "ports[1].pin[1]: must be a finite number; 1e999 is too large for a double");
  EXPECT_EQ(problemOf("[]"), R"(: the top level must be a JSON object {"format": ...}, got an )"
                             "array of 0 elements");
  EXPECT_EQ(problemOf("{}"), R"(format: required field is missing; a board.json starts with )"
                             R"("format": "stripemux-board/1")");
  EXPECT_EQ(problemOf(R"({"format": 1})"),
            R"(format: must be a string such as "stripemux-board/1", got a number (1))");
  EXPECT_EQ(problemOf(R"({"format": "stripemux-board/2"})"),
            R"(format: unsupported version "stripemux-board/2"; supported: "stripemux-board/1")");
  EXPECT_EQ(problemOf(R"({"format": "stripemux-rig/1"})"),
            R"(format: unknown format "stripemux-rig/1" (this is a rig.json, not a board); )"
            R"(supported: "stripemux-board/1")");
  EXPECT_EQ(problemOf(R"({"format": "stripemux-board/1", "ports": [{"a": 1, "a": 2}]})"),
            R"(ports[0]: key "a" appears more than once)");
  EXPECT_EQ(problemOf(R"({"format": "stripemux-board/1", "port": []})"),
            R"(: unknown key "port" (did you mean "ports"?); allowed keys: format, ports, )"
            "stripe_px");
}

TEST(ConfigJsonReader, ReadsFilesWithinTheBound) {
  const fs::path dir = fs::temp_directory_path() / "smx_config_json_test";
  fs::create_directories(dir);
  const auto write = [&](std::string_view name, std::size_t bytes) {
    std::ofstream(dir / name, std::ios::binary) << std::string(bytes, ' ');
    return dir / name;
  };
  EXPECT_EQ(readDocumentFile(write("small.json", 200), kBoard).value(), std::string(200, ' '));
  EXPECT_EQ(readDocumentFile(write("large.json", 201), kBoard).error().problem,
            "file is larger than 200 bytes; a board.json is a few kB");
  EXPECT_EQ(readDocumentFile(dir / "absent.json", kBoard).error().problem,
            "cannot read the file: No such file or directory");
  EXPECT_EQ(readDocumentFile(dir, kBoard).error().problem,
            "cannot read the file: it is a directory");
  fs::remove_all(dir);
}

TEST(ConfigRotationCheck, AcceptsRotationsOnly) {
  EXPECT_EQ(rotationProblem(std::array<double, 9>{0, -1, 0, 1, 0, 0, 0, 0, 1}), std::nullopt);
  EXPECT_EQ(rotationProblem(std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1.000004}),
            "not a rotation: max |R*R^T - I| is 8e-06 (must be at most 1e-06)");
  EXPECT_EQ(rotationProblem(std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, -1}),
            "not a rotation: det R is -1 (must be 1 within 1e-06; det -1 is a reflection)");
}

}  // namespace
}  // namespace smx::config
