// Hostile and careless input to the offline commands: ids that try to be paths, files that are
// not what they claim, option values that lose data. Each is refused with a message naming the
// problem, and nothing is written outside the output folder, or at all.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"
#include "smx/sim/png_io.hpp"
#include "source_dir.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

using test::CliRun;
using test::runCli;

const fs::path kRig = smx::test::sourceDir() / "boards/sim/rig_2proj_1cam.json";

// rig_2proj_1cam.json with the first occurrence of `from` replaced by `to`.
std::string exampleRigWith(const std::string& from, const std::string& to) {
  return test::textWith(kRig, from, to);
}

// Every regular file below `dir`.
std::vector<fs::path> filesBelow(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(dir, ec)) {
    if (entry.is_regular_file()) {
      files.push_back(entry.path());
    }
  }
  return files;
}

class CliHostileInput : public test::CliTest {
 protected:
  // A rendered camera image of the example rig, made once per test that needs one.
  fs::path cameraImage() {
    const auto out = dir_ / "frame";
    const auto sim = runCli(
        {"sim", "--rig", kRig.string(), "--scene", "plane", "--out", out.string(), "--no-truth"});
    EXPECT_EQ(sim.code, kExitOk) << sim.err;
    return out / "cam0.png";
  }
};

struct HostileId {
  const char* name;
  const char* json;  // as written inside the JSON string
};

// Traversal, an absolute path, an embedded NUL that would cut the suffix, a terminal escape, a
// separator, a name longer than any file system takes.
const HostileId kHostileIds[] = {
    {"traversal", "../../escaped"},
    {"absolute", "/tmp/smx_escaped"},
    {"nul", "escaped.png\\u0000"},
    {"escape", "\\u001b]0;owned\\u0007"},
    {"separator", "a/b"},
    {"overlong", "abcdefghijklmnopqrstuvwxyz0123456789abcdefghijklmnopqrstuvwxyz"},
};

// Given a rig whose projector or camera id is not a name, when any command that writes files
// named after ids runs, then it exits 2 naming the id's field, and no file appears anywhere
// in the scratch folder (or at the absolute path the id names).
TEST_F(CliHostileInput, IdsThatAreNotNamesAreRefusedByEveryCommand) {
  const auto image = cameraImage();
  for (const auto& id : kHostileIds) {
    const auto work = dir_ / id.name / "deep" / "er";
    fs::create_directories(work);
    const auto projectorRig =
        writeFile(std::string(id.name) + "_p.json",
                  exampleRigWith("\"proj0\"", '"' + std::string(id.json) + '"'));
    const auto cameraRig = writeFile(std::string(id.name) + "_c.json",
                                     exampleRigWith("\"cam0\"", '"' + std::string(id.json) + '"'));
    const std::string out = (work / "out").string();
    const std::string cam = "cam0=" + image.string();
    const std::vector<std::pair<std::vector<std::string>, std::string>> runs = {
        {{"pattern", "--rig", projectorRig.string(), "--out", out}, "projectors[0].id"},
        {{"demux", "--rig", projectorRig.string(), "--image", cam, "--debug", out},
         "projectors[0].id"},
        {{"decode", "--rig", projectorRig.string(), "--image", cam, "--out", out, "--debug",
          out + "2"},
         "projectors[0].id"},
        {{"sim", "--rig", cameraRig.string(), "--scene", "plane", "--out", out}, "cameras[0].id"},
        {{"decode", "--rig", cameraRig.string(), "--image", std::string(id.json) + "=x.png",
          "--out", out},
         "cameras[0].id"},
    };
    for (const auto& [args, field] : runs) {
      const CliRun result = runCli(args);
      EXPECT_EQ(result.code, kExitBadInput) << id.name << " " << args[0] << ": " << result.err;
      EXPECT_NE(result.err.find(field + ": "), std::string::npos)
          << id.name << " " << args[0] << ": " << result.err;
      EXPECT_EQ(result.err.find('\x1b'), std::string::npos) << id.name << " " << args[0];
    }
    EXPECT_FALSE(fs::exists(work / "out")) << id.name;
    EXPECT_FALSE(fs::exists("/tmp/smx_escaped.png"));
    EXPECT_FALSE(fs::exists("/tmp/smx_escaped"));
  }
  std::vector<fs::path> written;
  for (const auto& file : filesBelow(dir_)) {
    if (file.extension() == ".png" && file.parent_path() != image.parent_path()) {
      written.push_back(file);
    }
  }
  EXPECT_TRUE(written.empty()) << written.front();
}

// Given a rig whose cameras or projectors could never be built, when pattern or decode runs, then
// it exits 2 naming the field, before anything is allocated for the absurd size.
TEST_F(CliHostileInput, ImplausibleRigsAreRefusedNamingTheField) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"\"width\": 1024", "\"width\": 65535", "projectors[0].width"},
      {"\"stripe_px\": 6", "\"stripe_px\": 1e-300", "projectors[0].pattern.stripe_px"},
      {"\"stripe_px\": 6", "\"stripe_px\": 1e300", "projectors[0].pattern"},
      {"\"angle_deg\": 0", "\"angle_deg\": 1e300", "projectors[0].pattern.angle_deg"},
      {"\"offset_px\": 0", "\"offset_px\": 1e9", "projectors[0].pattern"},
  };
  for (const auto& [from, to, field] : cases) {
    const auto rig = writeFile("rig.json", exampleRigWith(from, to));
    const auto result = runCli({"pattern", "--rig", rig.string(), "--out", (dir_ / "p").string()});
    EXPECT_EQ(result.code, kExitBadInput) << to << ": " << result.err;
    EXPECT_NE(result.err.find(field + ": "), std::string::npos) << to << ": " << result.err;
    EXPECT_FALSE(fs::exists(dir_ / "p")) << to;
  }
}

// Given a rig with more projectors than the method separates, when decode runs, then the message
// names the rig's "projectors" field and the limit (not an internal stage).
TEST_F(CliHostileInput, TooManyProjectorsIsARigErrorNamingTheField) {
  std::ifstream in(kRig);
  auto rig = nlohmann::json::parse(in);
  const auto projectors = rig["projectors"];
  rig["projectors"] = nlohmann::json::array();
  for (int copy = 0; copy < 5; ++copy) {
    for (auto projector : projectors) {
      projector["id"] = projector["id"].get<std::string>() + "_" + std::to_string(copy);
      rig["projectors"].push_back(projector);
    }
  }
  const auto file = writeFile("ten.json", rig.dump());
  const auto image = cameraImage();
  const auto result = runCli({"decode", "--rig", file.string(), "--image", "cam0=" + image.string(),
                              "--out", (dir_ / "out").string()});
  EXPECT_EQ(result.code, kExitBadInput) << result.err;
  EXPECT_NE(result.err.find("projectors: at most 3 projectors"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("pipeline"), std::string::npos) << result.err;
}

// Given --depth-unit 1e-6 (65 mm of range in 16 bits) and a rig working at 0.9 m, when decode
// runs, then it refuses the option and says which depths would be lost, instead of "0 depth
// pixels" and exit 0.
TEST_F(CliHostileInput, DepthUnitThatCannotHoldTheWorkingRangeIsRefused) {
  const auto image = cameraImage();
  const auto result = runCli({"decode", "--rig", kRig.string(), "--image", "cam0=" + image.string(),
                              "--out", (dir_ / "out").string(), "--depth-unit", "1e-6"});
  EXPECT_EQ(result.code, kExitUsage) << result.err;
  EXPECT_NE(result.err.find("--depth-unit 1e-06"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("lost"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  // The smallest unit that holds twice the nominal depth is accepted.
  const auto ok = runCli({"decode", "--rig", kRig.string(), "--image", "cam0=" + image.string(),
                          "--out", (dir_ / "out").string(), "--depth-unit", "2.75e-5"});
  EXPECT_EQ(ok.code, kExitOk) << ok.err;
}

// Given a grey image (a monochrome camera, or colour lost on the way), when decode or demux runs,
// then it says the image has no colour rather than reporting 0 depth pixels.
TEST_F(CliHostileInput, GreyImageIsRefusedWithAHintThatColourIsNeeded) {
  const auto colour = sim::readPngRgb8(cameraImage());
  ASSERT_TRUE(colour.has_value());
  sim::RgbImage grey = *colour;
  for (auto& p : grey.pixels) {
    const auto y = static_cast<std::uint8_t>((p.r + p.g + p.b) / 3);
    p = {y, y, y};
  }
  const auto file = dir_ / "grey.png";
  ASSERT_TRUE(sim::writePngRgb8(file, grey.view()).has_value());
  for (const std::string command : {"decode", "demux"}) {
    std::vector<std::string> args = {command, "--rig", kRig.string(), "--image",
                                     "cam0=" + file.string()};
    if (command == "decode") {
      args.insert(args.end(), {"--out", (dir_ / "out").string()});
    }
    const auto result = runCli(args);
    EXPECT_EQ(result.code, kExitBadInput) << command << ": " << result.err;
    EXPECT_NE(result.err.find("no colour"), std::string::npos) << command << ": " << result.err;
  }
}

// Given two images for one camera, when decode runs, then it refuses instead of silently using
// one of them.
TEST_F(CliHostileInput, TwoImagesForOneCameraAreRefused) {
  const auto image = cameraImage();
  const auto result =
      runCli({"decode", "--rig", kRig.string(), "--image", "cam0=" + image.string(), "--image",
              "cam0=" + image.string(), "--out", (dir_ / "out").string()});
  EXPECT_EQ(result.code, kExitBadInput) << result.err;
  EXPECT_NE(result.err.find("camera cam0 already has an image"), std::string::npos) << result.err;
}

// Given a FIFO where a rig or an image is expected, when decode runs, then it refuses at once
// (a reader would block until something writes to the FIFO, maybe forever).
TEST_F(CliHostileInput, FifoInputIsRefusedWithoutBlocking) {
  const auto image = cameraImage();
  const auto fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::vector<std::vector<std::string>> runs = {
      {"decode", "--rig", fifo.string(), "--image", "cam0=" + image.string(), "--out",
       (dir_ / "out").string()},
      {"decode", "--rig", kRig.string(), "--image", "cam0=" + fifo.string(), "--out",
       (dir_ / "out").string()},
  };
  for (const auto& args : runs) {
    auto running = std::async(std::launch::async, [&] { return runCli(args); });
    if (running.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
      // Unblock the reader (a writer that closes at once: end of file) so the test can end.
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) {
        ::close(fd);
      }
      ADD_FAILURE() << "blocked on the FIFO: " << args[2] << " " << args[4];
    }
    const auto result = running.get();
    EXPECT_EQ(result.code, kExitBadInput) << result.err;
    EXPECT_NE(result.err.find("not a regular file"), std::string::npos) << result.err;
  }
}

// Given a decode that fails (an image of the wrong size), when it exits, then the output folder
// it would have created does not exist; and given a folder with an earlier result, a run that
// fails at its second camera leaves the first camera's earlier files as they were.
TEST_F(CliHostileInput, FailedDecodeLeavesNoFolderAndKeepsWhatExisted) {
  const auto small = dir_ / "small.png";
  const std::vector<algo::Rgb8> pixels(16 * 16, algo::Rgb8{200, 10, 10});
  ASSERT_TRUE(sim::writePngRgb8(small, *algo::ConstRgbView::packed(pixels, 16, 16)).has_value());
  auto result =
      runCli({"decode", "--rig", kRig.string(), "--image", "cam0=" + small.string(), "--out",
              (dir_ / "new" / "out").string(), "--debug", (dir_ / "new" / "debug").string()});
  EXPECT_EQ(result.code, kExitBadInput) << result.err;
  EXPECT_FALSE(fs::exists(dir_ / "new")) << "a failed decode left its output folder";

  const std::string rig2 = (smx::test::sourceDir() / "boards/sim/rig_2proj_2cam.json").string();
  const auto frames = dir_ / "frames2";
  ASSERT_EQ(
      runCli({"sim", "--rig", rig2, "--scene", "plane", "--out", frames.string(), "--no-truth"})
          .code,
      kExitOk);
  const auto kept = dir_ / "kept";
  result = runCli({"decode", "--rig", rig2, "--image", "cam0=" + (frames / "cam0.png").string(),
                   "--image", "cam1=" + (frames / "cam1.png").string(), "--out", kept.string()});
  ASSERT_EQ(result.code, kExitOk) << result.err;
  const auto before = sim::readPngGray16(kept / "cam0.depth.png");
  ASSERT_TRUE(before.has_value());
  const auto beforeFiles = filesBelow(kept);
  // Another depth unit would change cam0.depth.png, had it been written.
  result = runCli({"decode", "--rig", rig2, "--image", "cam0=" + (frames / "cam0.png").string(),
                   "--image", "cam1=" + small.string(), "--out", kept.string(), "--depth-unit",
                   "0.0002"});
  EXPECT_EQ(result.code, kExitBadInput) << result.err;
  const auto after = sim::readPngGray16(kept / "cam0.depth.png");
  ASSERT_TRUE(after.has_value());
  EXPECT_EQ(after->pixels, before->pixels) << "a failed decode replaced an earlier result";
  EXPECT_EQ(filesBelow(kept), beforeFiles);
}

// Given a file system that takes only a few kB more (a full disk, simulated by RLIMIT_FSIZE in a
// child process), when decode runs, then it exits 3 naming the file, and no truncated PNG, PLY or
// temporary file is left: before, a PLY whose header claimed every point remained.
TEST_F(CliHostileInput, FullDiskLeavesNoTruncatedFiles) {
  const auto image = cameraImage();
  const auto out = dir_ / "full";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit then fails with EFBIG
    const rlimit limit{64 * 1024, 64 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    const auto result = runCli({"decode", "--rig", kRig.string(), "--image",
                                "cam0=" + image.string(), "--out", out.string()});
    std::fputs(result.err.c_str(), stderr);
    ::_exit(result.code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), kExitDeviceOrIo);
  EXPECT_TRUE(filesBelow(out).empty()) << filesBelow(out).front();
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace smx::host
