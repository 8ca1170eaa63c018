// The owner's channel end to end on the simulated board over loopback (label "sim",
// docs/security.md): the device behind a SecureLink streams to a paired host without touching
// the heap, the host tool reads encrypted frames, and a host that never paired is refused.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "alloc_counter.hpp"
#include "device_client.hpp"
#include "device_socket.hpp"
#include "pairing_store.hpp"
#include "replay_board.hpp"
#include "smx/device/device.hpp"
#include "smx/device/owners.hpp"
#include "smx/device/secure_link.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/protocol/secure_keys.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kReplayFrames = 3;

// A device with an owner: its state in a fresh folder, `hostKey` paired by hand (hosts/*.pub).
struct OwnedDevice {
  explicit OwnedDevice(const protocol::Key32& hostKey)
      : state(fs::temp_directory_path() /
              ("smx_secure_sim_" +
               std::string(testing::UnitTest::GetInstance()->current_test_info()->name()))),
        board(test::replayBoard(1, kReplayFrames)) {
    fs::remove_all(state);
    fs::create_directories(state / "hosts");
    std::ofstream(state / "hosts" / "test.pub") << protocol::formatPublicKey(hostKey, "test");
    board.config.network.sendBufferBytes = 64 * 1024;
    boardHal = std::move(*hal::createBoardHal(board.config, board.rig));
    owners.emplace(*device::Owners::open(state, false));
    const hal::Hal devices = boardHal->hal();
    link = std::make_unique<device::SecureLink>(devices.link, *owners, devices.clock);
    device = std::move(*device::Device::create(
        board, {devices.cameras, devices.trigger, *link, devices.clock}, {}));
    network = std::jthread([this] { device->runNetwork(stop); });
  }
  ~OwnedDevice() {
    stop = true;
    network.join();
    fs::remove_all(state);
  }
  OwnedDevice(const OwnedDevice&) = delete;
  OwnedDevice& operator=(const OwnedDevice&) = delete;

  [[nodiscard]] net::DeviceAddress address() const { return {"127.0.0.1", link->port()}; }

  fs::path state;
  config::Board board;
  std::unique_ptr<hal::BoardHal> boardHal;
  std::optional<device::Owners> owners;
  std::unique_ptr<device::SecureLink> link;
  std::unique_ptr<device::Device> device;
  std::atomic<bool> stop = false;
  std::jthread network;
};

class SecureSim : public testing::Test {
 protected:
  static void SetUpTestSuite() { (void)test::replayFrames(1, kReplayFrames); }
};

TEST_F(SecureSim, EncryptedFramesWhileStreamingAllocateNothing) {
  const protocol::KeyPair host = protocol::generateKeyPair();
  OwnedDevice owned(host.publicKey);
  auto tcp = net::TcpClient::connect(owned.address(), 2000ms);
  ASSERT_TRUE(tcp) << tcp.error();
  auto socket =
      host::DeviceSocket::secure(std::move(*tcp), host, owned.owners->identity().publicKey, 3000ms);
  ASSERT_TRUE(socket) << socket.error();
  std::array<std::byte, 256> out{};
  ASSERT_TRUE(socket->sendAll(*protocol::encode(protocol::Hello{"secure host"}, out), 2000ms));
  ASSERT_TRUE(socket->sendAll(*protocol::encode(protocol::StartStream{}, out), 2000ms));
  std::atomic<std::uint64_t> bytes = 0;
  std::atomic<bool> stopReading = false;
  std::array<std::byte, 1 << 16> buffer{};
  std::jthread reader([&] {
    while (!stopReading) {
      const auto got = socket->receiveSome(buffer, 50ms);
      if (!got) {
        return;
      }
      bytes += *got;
    }
  });
  while (!owned.device->streaming()) {
    std::this_thread::sleep_for(1ms);
  }
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(owned.device->captureOnce().has_value());
  }
  const std::uint64_t sentBefore = owned.device->counters().framesSent;

  constexpr int frames = test::kSteadyStateFrames;
  const test::AllocationCounter allocations;
  for (int i = 0; i < frames; ++i) {
    (void)owned.device->captureOnce();
  }
  const std::uint64_t heapCalls = allocations.allocations();
  std::this_thread::sleep_for(200ms);
  stopReading = true;
  reader.join();

  EXPECT_EQ(heapCalls, 0U) << "encrypting and sending " << frames << " frames allocated";
  EXPECT_GT(owned.device->counters().framesSent - sentBefore, std::uint64_t{frames / 2});
  EXPECT_GT(bytes.load(), std::uint64_t{frames / 2} * 50'000U) << "decrypted bytes at the host";
}

TEST_F(SecureSim, ThePairedHostToolStreamsEncryptedAndAnotherHostIsRefused) {
  const fs::path config = fs::temp_directory_path() / "smx_secure_sim_host";
  fs::remove_all(config);
  ASSERT_EQ(setenv("XDG_CONFIG_HOME", config.c_str(), 1), 0);
  const auto host = host::hostIdentity();
  ASSERT_TRUE(host) << host.error();
  OwnedDevice owned(host->publicKey);
  const std::string address = net::toString(owned.address());

  const auto unpaired = host::DeviceClient::connect(address, 3000ms);
  ASSERT_FALSE(unpaired);
  EXPECT_NE(unpaired.error().find("not paired with the device"), std::string::npos)
      << unpaired.error();
  EXPECT_NE(unpaired.error().find("stripemux pair --device " + address), std::string::npos);

  ASSERT_TRUE(host::storePairedDevice(owned.address(), owned.owners->identity().publicKey));
  auto client = host::DeviceClient::connect(address, 3000ms);
  ASSERT_TRUE(client) << client.error();
  EXPECT_TRUE(client->encrypted());
  EXPECT_EQ(client->info().board, owned.board.config.name);
  std::jthread capture([&] {
    for (int i = 0; i < 6; ++i) {
      (void)owned.device->captureOnce();
    }
  });
  ASSERT_TRUE(client->startStream(protocol::Compression::kRvl));
  int frames = 0;
  for (int i = 0; i < 50 && frames < 2; ++i) {
    const auto event = client->next(500ms);
    ASSERT_TRUE(event) << event.error();
    frames += event->kind == host::DeviceEvent::Kind::kFrame ? 1 : 0;
  }
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(client->protocolErrors(), 0U);
  client->close();
  capture.join();

  // Another key at the same address: the device refuses it with its reason.
  fs::remove_all(config);
  ASSERT_TRUE(host::storePairedDevice(owned.address(), owned.owners->identity().publicKey));
  const auto stranger = host::DeviceClient::connect(address, 3000ms);
  ASSERT_FALSE(stranger);
  EXPECT_NE(stranger.error().find("no longer lists this host"), std::string::npos)
      << stranger.error();
  fs::remove_all(config);
  unsetenv("XDG_CONFIG_HOME");
}

}  // namespace
}  // namespace smx
