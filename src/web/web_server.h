// Internal to web (and its tests). The HTTP and WebSocket server of `softsight serve`, on
// Boost.Beast: it serves the page's files (PageAsset: compiled in, looked up by exact path, so
// no request names a file on disk), refuses what AccessPolicy does not allow (HTTP 403, also for
// the WebSocket's upgrade), and moves messages: the run's results, frames and status out to
// every page, each page's text messages in to the run (Inbox), unread and unchecked here.
//
// One page controls the run at a time: the first to connect, then, when it leaves, the page
// connected longest; another page takes control with give_control(). Each page is told its
// role ({"type":"role"}) whenever it changes.
//
// Everything runs on one thread of its own; the public calls may come from any thread. A slow
// page never holds up the run: its frames are newest-wins (one waits while one is written; the
// rest are skipped and counted) and at most kMaxQueuedTexts text messages wait for it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace softsight {

struct PageAsset {
  std::string path;          // "/index.html"; "/" serves "/index.html".
  std::string content_type;  // "text/html; charset=utf-8".
  std::string_view body;     // Static storage (the compiled-in files).
};

struct WebServerOptions {
  std::string bind = "127.0.0.1";  // The address to listen on.
  int port = 8090;                 // 0: a free port, chosen by the system (port() says which).
  std::string token;               // Required of every request when not empty (AccessPolicy).
  // Text messages that may wait for a slow page; beyond, the oldest are dropped (counted).
  size_t max_queued_texts = 512;
};

class WebServer {
 public:
  // A page's text message, on the server's thread: which page, and whether it controls the run.
  using Inbox = std::function<void(uint64_t page, bool controls, std::string text)>;
  // A page's WebSocket ended (closed, or its connection broke), on the server's thread: which
  // page, and whether it controlled the run then. Once per page. The rig's panel holds, then
  // vents, when the page that runs the rig leaves mid-run.
  using Departure = std::function<void(uint64_t page, bool controlled)>;

  // Listens at once (so port() is known); throws InputError naming the address when it cannot.
  WebServer(const WebServerOptions& options, std::vector<PageAsset> assets, Inbox inbox,
            Departure departure = {});
  ~WebServer();  // Closes every connection.
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const;
  // The page's address: http://<bind>:<port>/, with ?token=... when one is required.
  std::string url() const;

  // The first message every page gets when it connects (the run's description); any thread.
  void set_greeting(std::string text);
  void broadcast_text(std::string text);
  // A frame (binary message); a page still writing the previous one keeps only the newest.
  void broadcast_frame(std::string bytes);
  void send_text(uint64_t page, std::string text);
  void give_control(uint64_t page);

  int pages() const;                 // Connected WebSocket pages.
  int64_t frames_skipped() const;    // Frames a page was too slow for, all pages together.

  class Impl;  // web_server.cc: the state on the server's thread.

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace softsight
