// The live view's page server (tools/host/view, docs/live-view.md) through a real socket: what
// it serves, whom it refuses, and that a page that has not drawn its frame gets no backlog.
#include "smx/view/view_server.hpp"

#include <gtest/gtest.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstring>
#include <thread>

#include "smx/protocol/rvl.hpp"
#include "smx/view/live_feed.hpp"
#include "smx/view/messages.hpp"
#include "smx/view/sides_seen.hpp"

namespace smx::view {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using Tcp = asio::ip::tcp;

std::uint32_t le32(const std::vector<std::byte>& m, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    v |= std::to_integer<std::uint32_t>(m.at(at + i)) << (8 * i);
  }
  return v;
}

std::vector<std::byte> frameOf(std::uint8_t camera, std::uint16_t value) {
  std::vector<std::uint16_t> depth(8 * 4, value);
  depth[3] = 0;
  const auto plane = algo::ConstDepthPlane::packed(std::span(std::as_const(depth)), 8, 4);
  return depthMessage(camera, 0, 7, *plane, {});
}

class ViewServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.threeDir = "/nonexistent";  // the page must still be served
    auto server = ViewServer::start(feed_, options);
    ASSERT_TRUE(server) << server.error();
    server_ = std::move(*server);
    feed_.setSession({{"type", "session"}, {"cameras", 2}});
  }

  struct Reply {
    unsigned status = 0;
    std::string body;
  };

  Reply get(const std::string& target, const std::string& host = "") {
    Tcp::socket socket(ioc_);
    socket.connect({asio::ip::make_address("127.0.0.1"), server_->port()});
    http::request<http::empty_body> request(http::verb::get, target, 11);
    request.set(http::field::host,
                host.empty() ? "127.0.0.1:" + std::to_string(server_->port()) : host);
    http::write(socket, request);
    beast::flat_buffer buffer;
    http::response<http::string_body> response;
    http::read(socket, buffer, response);
    return {static_cast<unsigned>(response.result_int()), response.body()};
  }

  // A WebSocket as the page opens it (its own origin unless told otherwise).
  std::unique_ptr<websocket::stream<Tcp::socket>> open(const std::string& origin = "") {
    auto ws = std::make_unique<websocket::stream<Tcp::socket>>(ioc_);
    ws->next_layer().connect({asio::ip::make_address("127.0.0.1"), server_->port()});
    const std::string host = "127.0.0.1:" + std::to_string(server_->port());
    ws->set_option(websocket::stream_base::decorator([&](websocket::request_type& r) {
      r.set(http::field::origin, origin.empty() ? "http://" + host : origin);
    }));
    ws->handshake(host, "/ws");
    return ws;
  }

  // The next message: (is text, bytes).
  static std::pair<bool, std::vector<std::byte>> next(websocket::stream<Tcp::socket>& ws) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    const auto* data = static_cast<const std::byte*>(buffer.data().data());
    return {ws.got_text(), std::vector<std::byte>(data, data + buffer.size())};
  }

  // The next binary message, skipping status texts.
  static std::vector<std::byte> nextBinary(websocket::stream<Tcp::socket>& ws) {
    while (true) {
      auto [text, bytes] = next(ws);
      if (!text) {
        return bytes;
      }
    }
  }

  static std::string textOf(const std::vector<std::byte>& bytes) {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }

  LiveFeed feed_;
  std::unique_ptr<ViewServer> server_;
  asio::io_context ioc_;
};

TEST_F(ViewServerTest, ServesThePageAndRefusesOtherPaths) {
  const Reply page = get("/");
  EXPECT_EQ(page.status, 200U);
  EXPECT_NE(page.body.find("<script src=\"view.js\">"), std::string::npos);
  EXPECT_NE(get("/view.js").body.find("function rvlDecode"), std::string::npos);
  EXPECT_EQ(get("/style.css").status, 200U);
  EXPECT_EQ(get("/status.json").status, 200U);
  EXPECT_EQ(get("/../etc/passwd").status, 404U);
  EXPECT_EQ(get("/web/view.js").status, 404U);
  // Without three.js the page loads and says why it has no 3D view.
  const Reply three = get("/three.min.js");
  EXPECT_EQ(three.status, 404U);
  EXPECT_NE(three.body.find("libjs-three"), std::string::npos);
}

TEST_F(ViewServerTest, RefusesAnotherHostOrOrigin) {
  // DNS rebinding: a foreign name that resolves to 127.0.0.1.
  EXPECT_EQ(get("/", "attacker.example:" + std::to_string(server_->port())).status, 403U);
  EXPECT_EQ(get("/status.json", "localhost:1").status, 403U);
  EXPECT_EQ(get("/", "localhost:" + std::to_string(server_->port())).status, 200U);
  EXPECT_THROW(open("http://attacker.example"), beast::system_error);
}

TEST_F(ViewServerTest, AtMostSixteenPagesAtOnce) {
  std::vector<std::unique_ptr<websocket::stream<Tcp::socket>>> pages;
  for (int i = 0; i < 16; ++i) {
    pages.push_back(open());
  }
  EXPECT_THROW(open(), beast::system_error);
  pages.front()->close(websocket::close_code::normal);
  pages.erase(pages.begin());
  // A closed page's place is free again once the server has seen it go (asynchronously).
  bool reopened = false;
  for (int attempt = 0; attempt < 200 && !reopened; ++attempt) {
    try {
      pages.push_back(open());
      reopened = true;
    } catch (const beast::system_error&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  EXPECT_TRUE(reopened);
}

TEST_F(ViewServerTest, SessionFirstThenOnlyTheNewestFrameOfACameraUntilDrawn) {
  auto ws = open();
  auto [text, session] = next(*ws);
  ASSERT_TRUE(text);
  EXPECT_NE(textOf(session).find("\"session\""), std::string::npos);

  feed_.publishFrame(0, frameOf(0, 1000), monotonicNs());
  const auto first = nextBinary(*ws);
  const std::uint32_t firstSeq = le32(first, 8);
  // Three more while the page has not drawn the first: none is sent yet...
  for (const std::uint16_t v : {std::uint16_t{2000}, std::uint16_t{3000}, std::uint16_t{4000}}) {
    feed_.publishFrame(0, frameOf(0, v), monotonicNs());
  }
  // ...but another camera's frame is.
  feed_.publishFrame(1, frameOf(1, 500), monotonicNs());
  const auto other = nextBinary(*ws);
  EXPECT_EQ(std::to_integer<int>(other[1]), 1);
  ws->write(
      asio::buffer(std::string(R"({"type":"drawn","seq":)") + std::to_string(firstSeq) + "}"));
  // After the draw: the newest of camera 0 (4000), not the ones it replaced.
  const auto newest = nextBinary(*ws);
  EXPECT_EQ(std::to_integer<int>(newest[0]), static_cast<int>(MessageKind::kDepth));
  EXPECT_EQ(le32(newest, 8), firstSeq + 3);
  std::vector<std::uint16_t> depth(8 * 4);
  const std::uint32_t rvlBytes = le32(newest, 12);
  ASSERT_TRUE(protocol::rvlDecode(std::span(newest).subspan(kHeaderBytes, rvlBytes), depth));
  EXPECT_EQ(depth[0], 4000);
  EXPECT_EQ(depth[3], 0);
  EXPECT_EQ(feed_.figures().framesDrawn, 1U);
  EXPECT_EQ(feed_.figures().latencySamples, 1U);
}

TEST_F(ViewServerTest, ControlsAreCheckedBeforeTheyQueue) {
  auto ws = open();
  (void)next(*ws);
  const auto answer = [&](const std::string& message) {
    ws->write(asio::buffer(message));
    while (true) {
      auto [text, bytes] = next(*ws);
      const std::string s = textOf(bytes);
      if (text && s.find("\"status\"") == std::string::npos) {
        return s;
      }
    }
  };
  EXPECT_NE(answer(R"({"type":"control","action":"stop"})").find("accepted"), std::string::npos);
  EXPECT_NE(answer(R"({"type":"control","action":"preset","value":"fast"})").find("accepted"),
            std::string::npos);
  EXPECT_NE(
      answer(R"({"type":"control","action":"config","value":")" + std::string(300, 'x') + "\"}")
          .find("at most 256"),
      std::string::npos);
  EXPECT_NE(answer(R"({"type":"control","action":"format-disk"})").find("unknown action"),
            std::string::npos);
  EXPECT_NE(answer(R"({"type":"control","action":"preset"})").find("needs a value"),
            std::string::npos);
  EXPECT_NE(answer(R"({"type":"control","action":"scan","value":7})").find("must be a string"),
            std::string::npos);
  EXPECT_NE(answer("not json").find("error"), std::string::npos);
  const auto controls = feed_.takeControls();
  ASSERT_EQ(controls.size(), 2U);
  EXPECT_EQ(controls[0].action, "stop");
  EXPECT_EQ(controls[1].action, "preset");
  EXPECT_EQ(controls[1].value, "fast");
  EXPECT_TRUE(feed_.takeControls().empty());
  // A message larger than any control ends the connection. The server may close it while the
  // write is still going, so the write may fail (broken pipe) as well as the read after it.
  beast::error_code ec;
  ws->write(asio::buffer(std::string(64 * 1024, 'x')), ec);
  beast::flat_buffer buffer;
  for (int i = 0; i < 10 && !ec; ++i) {
    ws->read(buffer, ec);
  }
  EXPECT_TRUE(ec);
}

TEST(ViewMessages, DepthHeaderAndPlanesDecodeToTheInput) {
  std::vector<std::uint16_t> depth(16 * 6);
  std::vector<std::uint8_t> confidence(8 * 3);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = static_cast<std::uint16_t>(i % 5 == 0 ? 0 : 9000 + 37 * i);
  }
  for (std::size_t i = 0; i < confidence.size(); ++i) {
    confidence[i] = static_cast<std::uint8_t>(i * 11 % 256);
  }
  const auto d = algo::ConstDepthPlane::packed(std::span(std::as_const(depth)), 16, 6);
  const auto c =
      algo::ImageView<const std::uint8_t>::packed(std::span(std::as_const(confidence)), 8, 3);
  const auto m = depthMessage(3, 0, 0x1'2345'6789ULL, *d, *c);
  EXPECT_EQ(std::to_integer<int>(m[0]), 1);
  EXPECT_EQ(std::to_integer<int>(m[1]), 3);
  EXPECT_EQ(std::to_integer<int>(m[2]) | std::to_integer<int>(m[3]) << 8, 16);
  EXPECT_EQ(std::to_integer<int>(m[4]) | std::to_integer<int>(m[5]) << 8, 6);
  EXPECT_EQ(std::to_integer<int>(m[6]), 2);  // the confidence's step
  EXPECT_EQ(le32(m, 20), 0x2345'6789U);
  const std::uint32_t a = le32(m, 12);
  const std::uint32_t b = le32(m, 16);
  ASSERT_EQ(kHeaderBytes + a + b, m.size());
  std::vector<std::uint16_t> depthBack(depth.size());
  std::vector<std::uint8_t> confidenceBack(confidence.size());
  ASSERT_TRUE(protocol::rvlDecode(std::span(m).subspan(kHeaderBytes, a), depthBack));
  ASSERT_TRUE(protocol::rvlDecode(std::span(m).subspan(kHeaderBytes + a, b), confidenceBack));
  EXPECT_EQ(depthBack, depth);
  // RVL codes 1…255: a zero confidence is "no depth", so both round trips hold.
  EXPECT_EQ(confidenceBack, confidence);
}

TEST(SidesSeen, EachViewCoversTheSectorsWithin30DegreesOfIt) {
  SidesSeen sides;
  EXPECT_EQ(sides.percent(), 0.0);
  sides.add(0.0);  // the sectors 330–360° and 0–30°
  EXPECT_DOUBLE_EQ(sides.percent(), 100.0 * 2 / 12);
  sides.add(360.0);  // the same direction
  EXPECT_DOUBLE_EQ(sides.percent(), 100.0 * 2 / 12);
  sides.add(-90.0);  // 240–300°
  EXPECT_DOUBLE_EQ(sides.percent(), 100.0 * 4 / 12);
  SidesSeen ring;
  for (int k = 0; k < 6; ++k) {
    ring.add(60.0 * k);
  }
  EXPECT_DOUBLE_EQ(ring.percent(), 100.0);
}

}  // namespace
}  // namespace smx::view
