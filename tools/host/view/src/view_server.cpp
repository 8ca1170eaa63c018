#include "smx/view/view_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "smx/view/messages.hpp"
#include "web_assets.hpp"

namespace smx::view {

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using Tcp = asio::ip::tcp;

constexpr std::size_t kMaxHeaderBytes = 8192;
constexpr std::size_t kMaxPageMessageBytes = 4096;
constexpr auto kStatusPeriod = std::chrono::milliseconds(500);
constexpr auto kModelPeriod = std::chrono::milliseconds(1000);
// A page that never says it drew a frame gets the newest again after this.
constexpr auto kDrawnTimeout = std::chrono::seconds(5);
constexpr std::size_t kMaxValueChars = 256;
constexpr std::size_t kMaxPages = 16;  // WebSockets open at once

// A file's text, or empty when it cannot be read.
std::string readText(const std::string& path) {
  const std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return in ? std::move(text).str() : std::string();
}

// The page's controls as the server accepts them: anything else is refused with a reason.
std::expected<Control, std::string> parseControl(const nlohmann::json& j) {
  const auto action = j.find("action");
  if (action == j.end() || !action->is_string()) {
    return std::unexpected("a control needs an \"action\" string");
  }
  const std::string a = action->get<std::string>();
  if (a != "start" && a != "stop" && a != "preset" && a != "config" && a != "scan" &&
      a != "stop-scan") {
    return std::unexpected("unknown action");
  }
  std::string value;
  if (const auto v = j.find("value"); v != j.end()) {
    if (!v->is_string() || v->get_ref<const std::string&>().size() > kMaxValueChars) {
      return std::unexpected("\"value\" must be a string of at most 256 characters");
    }
    value = v->get<std::string>();
  }
  if ((a == "preset" || a == "config" || a == "scan") && value.empty()) {
    return std::unexpected("\"" + a + "\" needs a value");
  }
  return Control{a, value};
}

}  // namespace

class WsSession;

struct ViewServer::Impl {
  LiveFeed& feed;
  ServerOptions options;
  asio::io_context ioc{1};
  Tcp::acceptor acceptor{ioc};
  std::uint16_t port = 0;
  bool loopbackOnly = true;
  std::string threeJs;  // empty when not found
  std::string orbitControls;
  std::vector<std::weak_ptr<WsSession>> sessions;
  std::thread thread;

  Impl(LiveFeed& f, ServerOptions o) : feed(f), options(std::move(o)) {}

  void accept();
  void pumpAll();
  // Host header check for a loopback-bound server: another site's page that resolves its own
  // name to 127.0.0.1 (DNS rebinding) must not reach the scanner.
  [[nodiscard]] bool hostAllowed(std::string_view host) const {
    if (!loopbackOnly) {
      return true;
    }
    const std::string p = ":" + std::to_string(port);
    return host == "localhost" + p || host == "127.0.0.1" + p || host == "[::1]" + p;
  }
};

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Tcp::socket socket, ViewServer::Impl& server)
      : ws_(std::move(socket)), server_(server), statusTimer_(server.ioc) {}

  void run(const http::request<http::empty_body>& request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kMaxPageMessageBytes);
    server_.sessions.push_back(weak_from_this());  // counted from the handshake on
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (!ec) {
        self->started();
      }
    });
  }

  // Sends what is due when nothing is being written: queued texts and the static messages
  // first, then the newest frame when the page has drawn the last, then the model.
  void pump() {
    if (!open_ || writing_ || closed_) {
      return;
    }
    if (!queue_.empty()) {
      auto [text, message] = std::move(queue_.front());
      queue_.pop_front();
      write(text, message);
      return;
    }
    const auto now = std::chrono::steady_clock::now();
    // A camera whose last frame the page has not drawn gets nothing newer yet.
    std::vector<std::uint32_t> after = sent_;
    for (std::size_t c = 0; c < after.size(); ++c) {
      if (inFlight_[c] != 0 && now - sentAt_[c] <= kDrawnTimeout) {
        after[c] = std::numeric_limits<std::uint32_t>::max();
      }
    }
    if (auto frame = server_.feed.nextFrame(after)) {
      const auto camera = static_cast<std::size_t>(std::to_integer<unsigned>((*frame->message)[1]));
      sent_[camera] = frame->seq;
      inFlight_[camera] = frame->seq;
      sentAt_[camera] = now;
      write(false, frame->message);
      return;
    }
    if (now - modelSentAt_ >= kModelPeriod) {
      if (auto model = server_.feed.model(); model && model->seq != modelSeq_) {
        modelSeq_ = model->seq;
        modelSentAt_ = now;
        write(false, model->message);
      }
    }
  }

 private:
  void started() {
    connectedNs_ = monotonicNs();
    open_ = true;
    enqueueText(server_.feed.sessionText());
    for (auto& m : server_.feed.staticMessages()) {
      queue_.emplace_back(false, std::move(m));
    }
    enqueueText(server_.feed.statusText());
    read();
    tickStatus();
    pump();
  }

  void enqueueText(const std::string& text) {
    const auto* bytes = reinterpret_cast<const std::byte*>(text.data());
    queue_.emplace_back(true,
                        std::make_shared<const std::vector<std::byte>>(bytes, bytes + text.size()));
  }

  void tickStatus() {
    statusTimer_.expires_after(kStatusPeriod);
    statusTimer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closed_) {
        return;
      }
      // At most one status waiting: a slow page gets the newest, not a backlog.
      if (self->queue_.empty()) {
        self->enqueueText(self->server_.feed.statusText());
      }
      self->pump();
      self->tickStatus();
    });
  }

  void write(bool text, const Message& message) {
    writing_ = true;
    ws_.text(text);
    auto buffer = asio::buffer(message->data(), message->size());
    ws_.async_write(
        buffer, [self = shared_from_this(), message](beast::error_code ec, std::size_t /*bytes*/) {
          self->writing_ = false;
          if (ec) {
            self->close();
            return;
          }
          self->pump();
        });
  }

  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t /*bytes*/) {
      if (ec) {
        self->close();
        return;
      }
      self->onMessage(beast::buffers_to_string(self->in_.data()));
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  // {"type":"drawn","seq":N} or {"type":"control","action":...}; anything else is answered with
  // an error text and otherwise ignored.
  void onMessage(const std::string& text) {
    const auto j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("type") || !j["type"].is_string()) {
      reply("error", "not a JSON object with a \"type\"");
      return;
    }
    const auto& type = j["type"].get_ref<const std::string&>();
    if (type == "drawn") {
      if (j.contains("seq") && j["seq"].is_number_unsigned()) {
        const auto seq = j["seq"].get<std::uint64_t>();
        const auto match = std::ranges::find(inFlight_, seq);
        if (seq != 0 && match != inFlight_.end()) {
          server_.feed.drawn(static_cast<std::uint32_t>(seq), monotonicNs(), connectedNs_);
          *match = 0;
          pump();
        }
      }
      return;
    }
    if (type == "control") {
      auto control = parseControl(j);
      if (!control) {
        reply("error", control.error());
      } else if (!server_.feed.pushControl(*control)) {
        reply("error", "too many controls waiting; try again");
      } else {
        reply("accepted", control->action);
      }
      return;
    }
    reply("error", "unknown message type");
  }

  void reply(const std::string& type, const std::string& message) {
    enqueueText(nlohmann::json{{"type", type}, {"message", message}}.dump(
        -1, ' ', false, nlohmann::json::error_handler_t::replace));
    pump();
  }

  void close() {
    closed_ = true;
    statusTimer_.cancel();
  }

  websocket::stream<beast::tcp_stream> ws_;
  ViewServer::Impl& server_;
  asio::steady_timer statusTimer_;
  beast::flat_buffer in_;
  std::deque<std::pair<bool, Message>> queue_;  // (text?, bytes)
  // Per camera: the last seq sent, the one sent and not yet drawn (0: none), and when.
  std::vector<std::uint32_t> sent_ = std::vector<std::uint32_t>(LiveFeed::kMaxCameras, 0);
  std::vector<std::uint32_t> inFlight_ = std::vector<std::uint32_t>(LiveFeed::kMaxCameras, 0);
  std::vector<std::chrono::steady_clock::time_point> sentAt_ =
      std::vector<std::chrono::steady_clock::time_point>(LiveFeed::kMaxCameras);
  std::uint32_t modelSeq_ = 0;
  std::chrono::steady_clock::time_point modelSentAt_{};
  std::int64_t connectedNs_ = 0;
  bool open_ = false;  // the handshake is done
  bool writing_ = false;
  bool closed_ = false;
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Tcp::socket socket, ViewServer::Impl& server)
      : stream_(std::move(socket)), server_(server) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxHeaderBytes);
    parser_->body_limit(0);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t /*bytes*/) {
                       if (!ec) {
                         self->handle(self->parser_->release());
                       }
                     });
  }

 private:
  void handle(const http::request<http::empty_body>& request) {
    const std::string host(request[http::field::host]);
    if (!server_.hostAllowed(host)) {
      respond(request, http::status::forbidden, "text/plain",
              "this page is served to localhost only\n");
      return;
    }
    const std::string target(request.target());
    if (target == "/ws" && websocket::is_upgrade(request)) {
      // A page of another origin must not drive the scanner (browsers always send Origin).
      const std::string origin(request[http::field::origin]);
      if (origin != "http://" + host) {
        respond(request, http::status::forbidden, "text/plain", "origin refused\n");
        return;
      }
      std::erase_if(server_.sessions, [](const auto& s) { return s.expired(); });
      if (server_.sessions.size() >= kMaxPages) {
        respond(request, http::status::service_unavailable, "text/plain",
                "too many pages open on this view\n");
        return;
      }
      stream_.expires_never();
      std::make_shared<WsSession>(stream_.release_socket(), server_)->run(request);
      return;
    }
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      respond(request, http::status::method_not_allowed, "text/plain", "GET only\n");
      return;
    }
    if (target == "/status.json") {
      respond(request, http::status::ok, "application/json", server_.feed.statusText());
      return;
    }
    if (target == "/three.min.js" || target == "/OrbitControls.js") {
      const std::string& script =
          target == "/three.min.js" ? server_.threeJs : server_.orbitControls;
      if (script.empty()) {
        respond(request, http::status::not_found, "text/plain",
                "three.js not found in " + server_.options.threeDir +
                    " (Debian package libjs-three)\n");
      } else {
        respond(request, http::status::ok, "text/javascript; charset=utf-8", script);
      }
      return;
    }
    const std::string name = target == "/" ? "index.html" : target.substr(1);
    if (const auto asset = webAsset(name)) {
      respond(request, http::status::ok, asset->contentType, std::string(asset->body));
      return;
    }
    respond(request, http::status::not_found, "text/plain", "not found\n");
  }

  void respond(const http::request<http::empty_body>& request, http::status status,
               std::string_view type, std::string body) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
    response->set(http::field::content_type, std::string(type));
    response->set(http::field::cache_control, "no-store");
    response->set("X-Content-Type-Options", "nosniff");
    response->keep_alive(request.keep_alive());
    if (request.method() != http::verb::head) {
      response->body() = std::move(body);
    }
    response->prepare_payload();
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code ec, std::size_t) {
                        if (ec || response->need_eof()) {
                          beast::error_code ignored;
                          self->stream_.socket().shutdown(Tcp::socket::shutdown_send, ignored);
                          return;
                        }
                        self->read();
                      });
  }

  beast::tcp_stream stream_;
  ViewServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::empty_body>> parser_;
};

void ViewServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, Tcp::socket socket) {
    if (!ec) {
      std::make_shared<HttpSession>(std::move(socket), *this)->read();
    }
    if (acceptor.is_open()) {
      accept();
    }
  });
}

void ViewServer::Impl::pumpAll() {
  std::erase_if(sessions, [](const auto& s) { return s.expired(); });
  for (const auto& weak : sessions) {
    if (auto s = weak.lock()) {
      s->pump();
    }
  }
}

std::expected<std::unique_ptr<ViewServer>, std::string> ViewServer::start(
    LiveFeed& feed, const ServerOptions& options) {
  auto impl = std::make_unique<Impl>(feed, options);
  beast::error_code ec;
  const auto address = asio::ip::make_address(options.bind, ec);
  if (ec) {
    return std::unexpected("--bind " + options.bind + ": not an IP address");
  }
  const Tcp::endpoint endpoint(address, options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) {
    impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  }
  if (!ec) {
    impl->acceptor.bind(endpoint, ec);
  }
  if (!ec) {
    impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  }
  if (ec) {
    return std::unexpected("cannot serve the page on " + options.bind + ":" +
                           std::to_string(options.port) + ": " + ec.message());
  }
  impl->port = impl->acceptor.local_endpoint().port();
  impl->loopbackOnly = address.is_loopback();
  impl->threeJs = readText(options.threeDir + "/three.min.js");
  impl->orbitControls = readText(options.threeDir + "/examples/js/controls/OrbitControls.js");
  if (impl->orbitControls.empty()) {
    impl->threeJs.clear();
  }
  Impl* raw = impl.get();
  feed.setNotifier([raw] { asio::post(raw->ioc, [raw] { raw->pumpAll(); }); });
  impl->accept();
  impl->thread = std::thread([raw] { raw->ioc.run(); });
  return std::unique_ptr<ViewServer>(new ViewServer(std::move(impl)));
}

ViewServer::ViewServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ViewServer::~ViewServer() {
  impl_->feed.setNotifier({});
  impl_->ioc.stop();
  if (impl_->thread.joinable()) {
    impl_->thread.join();
  }
}

std::uint16_t ViewServer::port() const {
  return impl_->port;
}

std::string ViewServer::url() const {
  const std::string host =
      impl_->loopbackOnly || impl_->options.bind == "0.0.0.0" ? "127.0.0.1" : impl_->options.bind;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/";
}

bool ViewServer::hasThreeJs() const {
  return !impl_->threeJs.empty();
}

}  // namespace smx::view
