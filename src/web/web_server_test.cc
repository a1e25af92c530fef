// The server on its own, over real sockets on the loopback: files, refusals, roles, a flood of
// connections opened and dropped.
#include "web/web_server.h"

#include <gtest/gtest.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "web/access.h"

namespace softsight {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

constexpr char kPage[] = "<!doctype html><title>test page</title>";

struct Received {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::pair<uint64_t, std::string>> messages;
  std::vector<bool> controls;
  std::vector<std::pair<uint64_t, bool>> departures;  // (page, controlled then)
};

class WebServerTest : public ::testing::Test {
 protected:
  void Start(const std::string& token) {
    WebServerOptions options;
    options.port = 0;
    options.token = token;
    server_ = std::make_unique<WebServer>(
        options, std::vector<PageAsset>{{"/index.html", "text/html", kPage}},
        [this](uint64_t page, bool controls, std::string text) {
          std::lock_guard lock(received_.mutex);
          received_.messages.emplace_back(page, std::move(text));
          received_.controls.push_back(controls);
          received_.changed.notify_all();
        },
        [this](uint64_t page, bool controlled) {
          std::lock_guard lock(received_.mutex);
          received_.departures.emplace_back(page, controlled);
          received_.changed.notify_all();
        });
  }

  http::response<http::string_body> Get(const std::string& target, const std::string& cookie = "") {
    asio::io_context io;
    beast::tcp_stream stream(io);
    stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server_->port()));
    http::request<http::string_body> request(http::verb::get, target, 11);
    request.set(http::field::host, "127.0.0.1");
    if (!cookie.empty()) request.set(http::field::cookie, cookie);
    http::write(stream, request);
    beast::flat_buffer buffer;
    http::response<http::string_body> response;
    http::read(stream, buffer, response);
    return response;
  }

  // A WebSocket to the server; throws (beast::system_error) when the handshake is refused.
  std::unique_ptr<websocket::stream<tcp::socket>> Connect(const std::string& target) {
    auto ws = std::make_unique<websocket::stream<tcp::socket>>(io_);
    ws->next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server_->port()));
    ws->handshake("127.0.0.1:" + std::to_string(server_->port()), target);
    return ws;
  }

  static std::string ReadText(websocket::stream<tcp::socket>& ws) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    return beast::buffers_to_string(buffer.data());
  }

  // Reads until a message containing `needle` arrives (the role messages may come first).
  static std::string ReadUntil(websocket::stream<tcp::socket>& ws, const std::string& needle) {
    for (int i = 0; i < 20; ++i) {
      const std::string text = ReadText(ws);
      if (text.find(needle) != std::string::npos) return text;
    }
    return "";
  }

  bool WaitForMessages(size_t count) {
    std::unique_lock lock(received_.mutex);
    return received_.changed.wait_for(lock, std::chrono::seconds(10),
                                      [&] { return received_.messages.size() >= count; });
  }

  bool WaitForDepartures(size_t count) {
    std::unique_lock lock(received_.mutex);
    return received_.changed.wait_for(lock, std::chrono::seconds(10),
                                      [&] { return received_.departures.size() >= count; });
  }

  asio::io_context io_;
  Received received_;
  std::unique_ptr<WebServer> server_;
};

TEST_F(WebServerTest, ServesOnlyItsOwnFiles) {
  Start("");
  EXPECT_EQ(Get("/").body(), kPage);
  EXPECT_EQ(Get("/index.html").result(), http::status::ok);
  EXPECT_EQ(Get("/../../etc/passwd").result(), http::status::not_found);
  EXPECT_EQ(Get("/index.html/../../etc/passwd").result(), http::status::not_found);
  EXPECT_EQ(Get("/%2e%2e/etc/passwd").result(), http::status::not_found);
  EXPECT_EQ(server_->url(), "http://127.0.0.1:" + std::to_string(server_->port()) + "/");
}

TEST_F(WebServerTest, AWrongOrMissingTokenIsRefusedForPagesAndWebSockets) {
  const std::string token = NewAccessToken();
  Start(token);
  EXPECT_NE(server_->url().find("?token=" + token), std::string::npos);
  EXPECT_EQ(Get("/").result(), http::status::forbidden);
  EXPECT_EQ(Get("/?token=" + std::string(32, '0')).result(), http::status::forbidden);
  const auto page = Get("/?token=" + token);
  EXPECT_EQ(page.result(), http::status::ok);
  EXPECT_NE(page[http::field::set_cookie].find(token), beast::string_view::npos);
  // The page's other requests carry the cookie.
  EXPECT_EQ(Get("/index.html", std::string(kTokenCookie) + "=" + token).result(), http::status::ok);
  EXPECT_THROW(Connect("/ws"), beast::system_error);
  EXPECT_THROW(Connect("/ws?token=" + std::string(32, 'f')), beast::system_error);
  auto ws = Connect("/ws?token=" + token);
  EXPECT_NE(ReadUntil(*ws, "\"role\"").find("\"controls\":true"), std::string::npos);
}

TEST_F(WebServerTest, OnePageControlsAndTheNextTakesOverWhenItLeaves) {
  Start("");
  server_->set_greeting("{\"type\":\"hello\"}");
  auto first = Connect("/ws");
  EXPECT_EQ(ReadText(*first), "{\"type\":\"hello\"}");
  EXPECT_NE(ReadUntil(*first, "role").find("\"controls\":true"), std::string::npos);
  auto second = Connect("/ws");
  EXPECT_EQ(ReadText(*second), "{\"type\":\"hello\"}");
  EXPECT_NE(ReadUntil(*second, "role").find("\"controls\":false"), std::string::npos);
  first->write(asio::buffer(std::string("from first")));
  second->write(asio::buffer(std::string("from second")));
  ASSERT_TRUE(WaitForMessages(2));
  {
    std::lock_guard lock(received_.mutex);
    for (size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(received_.controls[i], received_.messages[i].second == "from first");
    }
  }
  first->close(websocket::close_code::normal);
  first.reset();
  EXPECT_NE(ReadUntil(*second, "\"controls\":true").find("\"pages\":1"), std::string::npos);
  second->write(asio::buffer(std::string("now in control")));
  ASSERT_TRUE(WaitForMessages(3));
  {
    std::lock_guard lock(received_.mutex);
    EXPECT_TRUE(received_.controls[2]);
    // The run was told the first page left, while it controlled (the rig holds, then vents).
    ASSERT_EQ(received_.departures.size(), 1u);
    EXPECT_EQ(received_.departures[0].first, received_.messages[0].second == "from first"
                                                 ? received_.messages[0].first
                                                 : received_.messages[1].first);
    EXPECT_TRUE(received_.departures[0].second);
  }
  // A connection dropped without a close (a crashed browser, a pulled cable) is a departure too.
  second->next_layer().close();
  ASSERT_TRUE(WaitForDepartures(2));
  std::lock_guard lock(received_.mutex);
  EXPECT_TRUE(received_.departures[1].second);
}

TEST_F(WebServerTest, FramesAndResultsReachEveryPage) {
  Start("");
  auto a = Connect("/ws");
  auto b = Connect("/ws");
  ReadUntil(*b, "role");
  for (int i = 0; i < 50 && server_->pages() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // Polled: the join is async.
  }
  ASSERT_EQ(server_->pages(), 2);
  server_->broadcast_text("{\"type\":\"result\",\"frame\":7}");
  server_->broadcast_frame(std::string("\x01\x00\x00\x00{JPEG", 9));
  for (auto* ws : {a.get(), b.get()}) {
    EXPECT_EQ(ReadUntil(*ws, "result"), "{\"type\":\"result\",\"frame\":7}");
    beast::flat_buffer buffer;
    ws->read(buffer);
    EXPECT_TRUE(ws->got_binary());
    EXPECT_EQ(buffer.size(), 9u);
  }
}

TEST_F(WebServerTest, AnOversizedMessageClosesOnlyItsOwnConnection) {
  Start("");
  auto flooder = Connect("/ws");
  auto watcher = Connect("/ws");
  // Under 64 KB it reaches the run (which refuses it with an error, page_messages.h); beyond,
  // the server closes that connection without reading it whole.
  flooder->write(asio::buffer(std::string(5000, 'x')));
  ASSERT_TRUE(WaitForMessages(1));
  // (The server may close while the 70 KB are still being written: the write itself then fails
  // with a broken pipe or a reset, which is the same end.)
  beast::error_code error;
  flooder->write(asio::buffer(std::string(70 * 1024, 'x')), error);
  for (int i = 0; i < 20 && !error; ++i) {
    beast::flat_buffer buffer;
    flooder->read(buffer, error);  // Role messages, then the close.
  }
  // The server sends its close (too big) and drops the connection. The client sees the close,
  // or, when the server's socket is gone before the client's answer to the close is written,
  // that write failing (a broken pipe, a reset, not connected): either way it is over.
  if (error == websocket::error::closed) {
    EXPECT_EQ(flooder->reason().code, websocket::close_code::too_big);
  } else {
    EXPECT_TRUE(error == asio::error::broken_pipe || error == asio::error::connection_reset ||
                error == asio::error::eof || error == asio::error::not_connected)
        << error.message();
  }
  watcher->write(asio::buffer(std::string("still here")));
  ASSERT_TRUE(WaitForMessages(2));
  std::lock_guard lock(received_.mutex);
  EXPECT_EQ(received_.messages.back().second, "still here");
  EXPECT_EQ(received_.messages.size(), 2u);  // The 70 KB message never reached the run.
}

TEST_F(WebServerTest, SurvivesAHundredConnectionsOpenedAndDropped) {
  Start(NewAccessToken());
  for (int i = 0; i < 100; ++i) {
    tcp::socket socket(io_);
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server_->port()));
    // Nothing, half a request, a whole upgrade without the token, or garbage: then dropped.
    const std::string sent[] = {"", "GET / HTT", "GET /ws HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\n"
                                "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                                "Sec-WebSocket-Version: 13\r\n\r\n", std::string(3000, '\xff')};
    const std::string& bytes = sent[i % 4];
    if (!bytes.empty()) asio::write(socket, asio::buffer(bytes));
    socket.close();
  }
  EXPECT_EQ(Get("/").result(), http::status::forbidden);
  const std::string url = server_->url();
  EXPECT_EQ(Get(url.substr(url.find('/', 7))).result(), http::status::ok);
}

}  // namespace
}  // namespace softsight
