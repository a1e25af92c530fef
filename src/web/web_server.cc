#include "web/web_server.h"

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "softsight/core/error.h"
#include "web/access.h"
#include "web/page_messages.h"

namespace softsight {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Message = std::shared_ptr<const std::string>;

namespace {

// A request's head and body are a few hundred bytes; anything much larger is not from the page.
constexpr uint32_t kMaxRequestBytes = 16 * 1024;
// A message larger than kMaxPageMessageBytes is refused with an error the page shows; one
// larger than this closes the connection (1009, "message too big") without being read whole.
constexpr size_t kMaxWebSocketMessageBytes = 64 * 1024;
// A connection that sends nothing of a request for this long is closed.
constexpr std::chrono::seconds kRequestTimeout{30};

// Beast's string_view is Boost's; the access checks take the standard one.
std::string_view View(beast::string_view text) { return {text.data(), text.size()}; }

std::string RoleMessage(bool controls, int pages) {
  return std::string("{\"type\":\"role\",\"controls\":") + (controls ? "true" : "false") +
         ",\"pages\":" + std::to_string(pages) + "}";
}

}  // namespace

class WebSocketPage;

class WebServer::Impl {
 public:
  Impl(const WebServerOptions& options, std::vector<PageAsset> assets, Inbox inbox,
       Departure departure)
      : options_(options), policy_(options.token), inbox_(std::move(inbox)),
        departure_(std::move(departure)), acceptor_(io_) {
    for (PageAsset& asset : assets) assets_[asset.path] = std::move(asset);
  }

  void listen();
  void start() {
    thread_ = std::thread([this] { io_.run(); });
  }
  void stop() {
    io_.stop();
    if (thread_.joinable()) thread_.join();
  }

  // On the server's thread.
  void accept();
  void join(const std::shared_ptr<WebSocketPage>& page);
  void leave(uint64_t id);
  void set_controller(uint64_t id);
  void each_page(const std::function<void(WebSocketPage&)>& action);
  std::shared_ptr<WebSocketPage> find(uint64_t id);
  std::optional<http::response<http::string_body>> refuse(const http::request<http::string_body>& request) const;
  http::response<http::string_body> respond(const http::request<http::string_body>& request) const;

  WebServerOptions options_;
  AccessPolicy policy_;
  Inbox inbox_;
  Departure departure_;
  std::map<std::string, PageAsset> assets_;
  // Before the acceptor (built on it); destroyed last, with the handlers still pending in it,
  // which hold the pages and connections (whose destructors touch nothing else of the server).
  asio::io_context io_{1};
  tcp::acceptor acceptor_;
  std::thread thread_;
  int port_ = 0;
  std::map<uint64_t, std::weak_ptr<WebSocketPage>> pages_;  // In the order they connected.
  uint64_t next_id_ = 1;
  uint64_t controller_ = 0;  // 0: none.
  std::mutex greeting_mutex_;
  std::string greeting_;
  std::atomic<int> page_count_{0};
  std::atomic<int64_t> frames_skipped_{0}, texts_dropped_{0};
};

// One page's WebSocket: reads its messages into the inbox, writes the run's messages out.
class WebSocketPage : public std::enable_shared_from_this<WebSocketPage> {
 public:
  WebSocketPage(tcp::socket socket, WebServer::Impl& server, uint64_t id)
      : ws_(std::move(socket)), server_(server), id_(id) {}

  uint64_t id() const { return id_; }

  void run(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kMaxWebSocketMessageBytes);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code error) {
      if (error) return;
      self->server_.join(self);
      self->read();
    });
  }

  void queue_text(Message text) {
    if (texts_.size() >= server_.options_.max_queued_texts) {
      texts_.pop_front();
      ++server_.texts_dropped_;
    }
    texts_.push_back(std::move(text));
    write_next();
  }

  void queue_frame(Message frame) {
    if (frame_) ++server_.frames_skipped_;  // Replaced before it was written: the page lags.
    frame_ = std::move(frame);
    write_next();
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code error, size_t) {
      self->on_read(error);
    });
  }

  void on_read(beast::error_code error) {
    if (error) {
      server_.leave(id_);
      return;
    }
    if (!ws_.got_text()) {
      queue_text(std::make_shared<const std::string>(
          "{\"type\":\"error\",\"message\":\"binary messages are not taken\"}"));
    } else {
      server_.inbox_(id_, server_.controller_ == id_, beast::buffers_to_string(buffer_.data()));
    }
    buffer_.consume(buffer_.size());
    read();
  }

  void write_next() {
    if (writing_) return;
    // Texts first: a frame's result goes before its picture, and a page shows a picture once
    // it has the result to draw on it.
    if (!texts_.empty()) {
      writing_message_ = std::move(texts_.front());
      texts_.pop_front();
      ws_.text(true);
    } else if (frame_) {
      writing_message_ = std::move(frame_);
      frame_.reset();
      ws_.binary(true);
    } else {
      return;
    }
    writing_ = true;
    ws_.async_write(asio::buffer(*writing_message_),
                    [self = shared_from_this()](beast::error_code error, size_t) {
                      self->writing_ = false;
                      self->writing_message_.reset();
                      if (error) return;  // The read side sees the connection end and leaves.
                      self->write_next();
                    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  // The server outlives every page: pages live in the handlers of its io_context, which it
  // destroys (with them) before anything else of it.
  WebServer::Impl& server_;
  uint64_t id_;
  beast::flat_buffer buffer_;
  std::deque<Message> texts_;
  Message frame_;
  Message writing_message_;
  bool writing_ = false;
};

namespace {

// One HTTP connection: the page's files, or the upgrade to a WebSocket.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket socket, WebServer::Impl& server)
      : stream_(std::move(socket)), server_(server) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxRequestBytes);
    parser_->body_limit(kMaxRequestBytes);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code error, size_t) {
                       self->on_read(error);
                     });
  }

 private:
  void on_read(beast::error_code error) {
    if (error) {
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
      return;
    }
    http::request<http::string_body> request = parser_->release();
    if (websocket::is_upgrade(request) && TargetPath(View(request.target())) == "/ws") {
      if (auto refusal = server_.refuse(request)) {
        write(std::move(*refusal), /*close=*/true);
        return;
      }
      stream_.expires_never();  // The WebSocket keeps its own timeouts.
      auto page = std::make_shared<WebSocketPage>(stream_.release_socket(), server_,
                                                  server_.next_id_++);
      page->run(std::move(request));
      return;
    }
    write(server_.respond(request), !request.keep_alive());
  }

  void write(http::response<http::string_body> response, bool close) {
    response.keep_alive(!close);
    response.prepare_payload();
    response_ = std::move(response);
    http::async_write(stream_, response_, [self = shared_from_this(), close](beast::error_code error, size_t) {
      if (error || close) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
        return;
      }
      self->read();
    });
  }

  beast::tcp_stream stream_;
  WebServer::Impl& server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  http::response<http::string_body> response_;
};

http::response<http::string_body> TextResponse(http::status status, unsigned version,
                                               std::string body) {
  http::response<http::string_body> response(status, version);
  response.set(http::field::content_type, "text/plain; charset=utf-8");
  response.set(http::field::cache_control, "no-store");
  response.body() = std::move(body);
  return response;
}

}  // namespace

std::optional<http::response<http::string_body>> WebServer::Impl::refuse(
    const http::request<http::string_body>& request) const {
  if (!policy_.allows(View(request.target()), View(request[http::field::cookie]))) {
    return TextResponse(http::status::forbidden, request.version(),
                        "refused: this server needs the token printed in its URL "
                        "(http://...:PORT/?token=...)\n");
  }
  if (websocket::is_upgrade(request) &&
      !OriginMatchesHost(View(request[http::field::origin]), View(request[http::field::host]))) {
    return TextResponse(http::status::forbidden, request.version(),
                        "refused: a WebSocket from a page of another site\n");
  }
  return std::nullopt;
}

http::response<http::string_body> WebServer::Impl::respond(
    const http::request<http::string_body>& request) const {
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    return TextResponse(http::status::method_not_allowed, request.version(), "GET only\n");
  }
  std::string path(TargetPath(View(request.target())));
  if (path == "/") path = "/index.html";
  const auto asset = assets_.find(path);
  if (asset == assets_.end()) {
    return TextResponse(http::status::not_found, request.version(), "not found\n");
  }
  if (auto refusal = refuse(request)) return std::move(*refusal);
  http::response<http::string_body> response(http::status::ok, request.version());
  response.set(http::field::content_type, asset->second.content_type);
  response.set(http::field::cache_control, "no-store");
  response.set("X-Content-Type-Options", "nosniff");
  // Nothing from elsewhere: the page's own files, its WebSocket, and the frames it decodes.
  response.set("Content-Security-Policy",
               "default-src 'self'; connect-src 'self' ws: ; img-src 'self' blob: data:");
  if (policy_.token_required() && !QueryValue(View(request.target()), "token").empty()) {
    // The page's other requests (its script, its WebSocket) carry the token as this cookie.
    response.set(http::field::set_cookie, std::string(kTokenCookie) + "=" + policy_.token() +
                                              "; Path=/; HttpOnly; SameSite=Strict");
  }
  if (request.method() == http::verb::get) response.body() = std::string(asset->second.body);
  return response;
}

void WebServer::Impl::listen() {
  beast::error_code error;
  const asio::ip::address address = asio::ip::make_address(options_.bind, error);
  const std::string where = options_.bind + ":" + std::to_string(options_.port);
  if (error) throw InputError("--bind " + options_.bind + " is not an IP address");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(options_.port));
  acceptor_.open(endpoint.protocol(), error);
  if (!error) acceptor_.set_option(asio::socket_base::reuse_address(true), error);
  if (!error) acceptor_.bind(endpoint, error);
  if (!error) acceptor_.listen(asio::socket_base::max_listen_connections, error);
  if (error) {
    throw InputError("cannot listen on " + where + ": " + error.message() +
                     " (another --port, or --port 0 for any free one)");
  }
  port_ = acceptor_.local_endpoint().port();
  accept();
}

void WebServer::Impl::accept() {
  acceptor_.async_accept([this](beast::error_code error, tcp::socket socket) {
    if (!error) std::make_shared<HttpConnection>(std::move(socket), *this)->read();
    if (error == asio::error::operation_aborted) return;
    accept();  // A failed accept (too many open files) does not stop the server.
  });
}

void WebServer::Impl::join(const std::shared_ptr<WebSocketPage>& page) {
  pages_[page->id()] = page;
  page_count_ = static_cast<int>(pages_.size());
  {
    std::lock_guard lock(greeting_mutex_);
    if (!greeting_.empty()) page->queue_text(std::make_shared<const std::string>(greeting_));
  }
  if (controller_ == 0) controller_ = page->id();
  each_page([this](WebSocketPage& each) {
    each.queue_text(std::make_shared<const std::string>(
        RoleMessage(each.id() == controller_, page_count_)));
  });
}

void WebServer::Impl::leave(uint64_t id) {
  if (pages_.erase(id) == 0) return;
  page_count_ = static_cast<int>(pages_.size());
  if (departure_) departure_(id, controller_ == id);
  // The page that controlled the run left (closed, or its connection broke): the page
  // connected longest takes over, so the run is never left without one while pages watch.
  if (controller_ == id) controller_ = pages_.empty() ? 0 : pages_.begin()->first;
  each_page([this](WebSocketPage& each) {
    each.queue_text(std::make_shared<const std::string>(
        RoleMessage(each.id() == controller_, page_count_)));
  });
}

void WebServer::Impl::set_controller(uint64_t id) {
  if (find(id) == nullptr || controller_ == id) return;
  controller_ = id;
  each_page([this](WebSocketPage& each) {
    each.queue_text(std::make_shared<const std::string>(
        RoleMessage(each.id() == controller_, page_count_)));
  });
}

void WebServer::Impl::each_page(const std::function<void(WebSocketPage&)>& action) {
  for (auto& [id, weak] : pages_) {
    if (auto page = weak.lock()) action(*page);
  }
}

std::shared_ptr<WebSocketPage> WebServer::Impl::find(uint64_t id) {
  const auto it = pages_.find(id);
  return it == pages_.end() ? nullptr : it->second.lock();
}

WebServer::WebServer(const WebServerOptions& options, std::vector<PageAsset> assets, Inbox inbox,
                     Departure departure)
    : impl_(std::make_unique<Impl>(options, std::move(assets), std::move(inbox),
                                   std::move(departure))) {
  impl_->listen();
  impl_->start();
}

WebServer::~WebServer() { impl_->stop(); }

int WebServer::port() const { return impl_->port_; }

std::string WebServer::url() const {
  const std::string& bind = impl_->options_.bind;
  // An IPv6 address is bracketed in a URL; 0.0.0.0 and :: are not addresses to open: the page
  // is on this computer's name or address, which the person knows better than we do.
  std::string host = bind == "0.0.0.0" || bind == "::" ? "HOST" : bind;
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  std::string url = "http://" + host + ":" + std::to_string(port()) + "/";
  if (impl_->policy_.token_required()) url += "?token=" + impl_->policy_.token();
  return url;
}

void WebServer::set_greeting(std::string text) {
  std::lock_guard lock(impl_->greeting_mutex_);
  impl_->greeting_ = std::move(text);
}

void WebServer::broadcast_text(std::string text) {
  Message message = std::make_shared<const std::string>(std::move(text));
  asio::post(impl_->io_, [impl = impl_.get(), message] {
    impl->each_page([&message](WebSocketPage& page) { page.queue_text(message); });
  });
}

void WebServer::broadcast_frame(std::string bytes) {
  Message message = std::make_shared<const std::string>(std::move(bytes));
  asio::post(impl_->io_, [impl = impl_.get(), message] {
    impl->each_page([&message](WebSocketPage& page) { page.queue_frame(message); });
  });
}

void WebServer::send_text(uint64_t page, std::string text) {
  Message message = std::make_shared<const std::string>(std::move(text));
  asio::post(impl_->io_, [impl = impl_.get(), page, message] {
    if (auto found = impl->find(page)) found->queue_text(message);
  });
}

void WebServer::give_control(uint64_t page) {
  asio::post(impl_->io_, [impl = impl_.get(), page] { impl->set_controller(page); });
}

int WebServer::pages() const { return impl_->page_count_; }
int64_t WebServer::frames_skipped() const { return impl_->frames_skipped_; }

}  // namespace softsight
