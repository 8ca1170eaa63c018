// `stripemux info` and `stream`: what they do before any device is involved.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli.hpp"
#include "cli_harness.hpp"

namespace smx::host {
namespace {

class CliDevice : public test::CliTest {};

// Given a --device that is not HOST[:PORT], when info or stream runs, then it is a usage error
// (exit 1, docs/cli.md) naming the bad address, and no connection is tried.
TEST_F(CliDevice, AMalformedDeviceAddressIsAUsageError) {
  const std::string out = (dir_ / "out").string();
  for (const std::string bad :
       {"10.0.0.2:99999", "10.0.0.2:", "10.0.0.2:port", ":5555", "[::1", "[::1]:", "[::1]:0"}) {
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"info", "--device", bad},
          std::vector<std::string>{"stream", "--device", bad, "--out", out}}) {
      const auto result = test::runCli(args);
      EXPECT_EQ(result.code, kExitUsage) << args[0] << " --device " << bad << ": " << result.err;
      EXPECT_NE(result.err.find(bad), std::string::npos) << result.err;
    }
  }
}

}  // namespace
}  // namespace smx::host
