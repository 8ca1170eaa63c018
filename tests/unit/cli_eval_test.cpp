// `stripemux eval`: the report it writes (one section run for real) and how it rejects bad
// arguments. The figures' definitions are tested in eval_suite_test.cpp, depth_eval_test.cpp
// and boundary_eval_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_harness.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

class CliEval : public test::CliTest {};

std::string readText(const fs::path& path) {
  const std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The cells of the report's table row that starts with `label`.
std::vector<std::string> rowCells(const std::string& md, const std::string& label) {
  const auto at = md.find("| " + label + " |");
  if (at == std::string::npos) {
    return {};
  }
  std::istringstream line(md.substr(at, md.find('\n', at) - at));
  std::vector<std::string> cells;
  std::string cell;
  std::getline(line, cell, '|');
  while (std::getline(line, cell, '|')) {
    cells.push_back(cell.substr(1, cell.size() - 2));
  }
  return cells;
}

bool isPng(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  return in && std::string(sig, 8) == "\x89PNG\r\n\x1a\n";
}

// Given the flat-target section for the plane scene, when eval runs, then results.md quotes
// the command that made it, has a row per distance with the fill rate and plane-fit RMS a
// depth camera would report (nearly full; sub-millimetre noise growing with distance, as
// triangulation's does), and the error-vs-distance plot is a PNG; other sections are absent.
TEST_F(CliEval, FlatTargetsReportFillRateAndPlaneFitGrowingWithDistance) {
  const auto out = dir_ / "report";
  const auto run =
      test::runCli({"eval", "--out", out.string(), "--only", "flat", "--scene", "plane"});
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("flat target plane at 0.60 m"), std::string::npos) << run.out;
  const std::string md = readText(out / "results.md");
  EXPECT_NE(md.find("stripemux eval --out " + out.string() + " --only flat --scene plane"),
            std::string::npos);
  EXPECT_NE(md.find("## Flat targets"), std::string::npos);
  EXPECT_EQ(md.find("## Scenes"), std::string::npos);
  EXPECT_EQ(md.find("## Robustness sweeps"), std::string::npos);
  const auto nearRow = rowCells(md, "plane at 0.60 m");
  const auto farRow = rowCells(md, "plane at 1.20 m");
  ASSERT_GE(nearRow.size(), 4U) << md;
  ASSERT_GE(farRow.size(), 4U) << md;
  EXPECT_GE(std::stod(nearRow[2]), 95.0);  // fill rate, %
  EXPECT_GE(std::stod(farRow[2]), 95.0);
  const double nearRms = std::stod(nearRow[3]);
  const double farRms = std::stod(farRow[3]);
  EXPECT_GT(nearRms, 0.0);
  EXPECT_LT(farRms, 1.5);
  EXPECT_GT(farRms, 2.0 * nearRms);  // depth noise ∝ z² for a fixed disparity noise
  EXPECT_TRUE(isPng(out / "results" / "error_vs_distance.png"));
  EXPECT_FALSE(fs::exists(out / "results" / "completeness.png"));
}

// Given the plane scenes rendered with 4 × 4 samples per pixel, the report says so, quotes the
// option, and the two-projector plane's disparity RMSE is under 0.1 px (0.13 px with the scenes'
// own 2 × 2, which place a stripe edge only to within half a pixel).
TEST_F(CliEval, SupersamplingRendersFinerAndSaysSo) {
  const auto out = dir_ / "report";
  const auto run = test::runCli({"eval", "--out", out.string(), "--only", "scenes", "--scene",
                                 "plane", "--supersampling", "4"});
  ASSERT_EQ(run.code, 0) << run.err;
  const std::string md = readText(out / "results.md");
  EXPECT_NE(md.find("--supersampling 4"), std::string::npos);
  EXPECT_NE(md.find("4 × 4 samples per pixel"), std::string::npos);
  const auto row = rowCells(md, "plane | rig_2proj_1cam");
  ASSERT_GE(row.size(), 10U) << md;
  EXPECT_LT(std::stod(row[9]), 0.1);  // RMSE, disparity px

  const auto tooMany = test::runCli({"eval", "--out", out.string(), "--supersampling", "9"});
  EXPECT_EQ(tooMany.code, kExitUsage);
  EXPECT_NE(tooMany.err.find("--supersampling"), std::string::npos) << tooMany.err;
}

TEST_F(CliEval, RejectsAnUnknownSectionOrSceneNamingIt) {
  const auto section = test::runCli({"eval", "--out", dir_.string(), "--only", "flat,tabel2"});
  EXPECT_EQ(section.code, kExitUsage);
  EXPECT_NE(section.err.find("unknown section 'tabel2'"), std::string::npos) << section.err;
  const auto scene = test::runCli({"eval", "--out", dir_.string(), "--scene", "plain"});
  EXPECT_EQ(scene.code, kExitUsage);
  EXPECT_NE(scene.err.find("unknown scene 'plain'"), std::string::npos) << scene.err;
  EXPECT_NE(scene.err.find("plane"), std::string::npos) << scene.err;
  EXPECT_FALSE(fs::exists(dir_ / "results.md"));
}

// A report folder that cannot be made (a file is in the way) is an I/O error naming it.
TEST_F(CliEval, AnUnwritableReportFolderIsAnIoErrorNamingIt) {
  const auto blocker = writeFile("blocker", "a file, not a folder");
  // cups has no flat target: the run is empty and fast.
  const auto run = test::runCli(
      {"eval", "--out", (blocker / "sub").string(), "--only", "flat", "--scene", "cups"});
  EXPECT_EQ(run.code, kExitDeviceOrIo);
  EXPECT_NE(run.err.find("blocker"), std::string::npos) << run.err;
  EXPECT_EQ(readText(blocker), "a file, not a folder");
}

}  // namespace
}  // namespace smx::host
