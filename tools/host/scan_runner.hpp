#pragma once

#include <filesystem>
#include <string>

#include "cli.hpp"
#include "fuse_runner.hpp"

// `stripemux scan` as a function (cmd_scan.cpp), for the command and for scans started from the
// live view's page (cmd_view.cpp).
namespace smx::host {

class LiveView;

struct ScanOptions {
  std::string device;
  std::filesystem::path out;
  bool turntable = false;
  int views = 24;
  bool handheld = false;
  int frames = 0;
  bool noColour = false;
  double timeoutS = 10;
  FuseFolderOptions fuse;
};

// Runs a turntable or hand-held scan into opts.out; its exit code. With `live`, the page shows
// the views or frames, the growing model, coverage and tracking, and can end a hand-held scan.
[[nodiscard]] int runScan(const ScanOptions& opts, const CliStreams& io, LiveView* live);

}  // namespace smx::host
