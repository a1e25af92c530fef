// Internal to web (and its tests). Who may use the server: a page served on the loopback
// interface is reachable from this computer only and needs nothing more; on any other address
// every request must carry the token the server printed in its URL (`?token=`, as Jupyter does),
// or the cookie the page got with it. A WebSocket must also come from a page of this server
// (its Origin names the Host it connects to), so another site open in the same browser cannot
// drive the rig through it.
#pragma once

#include <string>
#include <string_view>

namespace softsight {

// 32 hex digits (128 bits) from the system's random device.
std::string NewAccessToken();

// True for 127.0.0.0/8, ::1 and "localhost". False for anything else, including what does not
// parse as an address (a host name could resolve anywhere).
bool IsLoopbackAddress(const std::string& address);

// Equal, in a time that does not depend on where `given` first differs.
bool TokenMatches(std::string_view given, std::string_view expected);

// The value of `key` in the query of a request target ("/ws?token=ab12&x=1"); empty when absent.
// Values are taken as they are (the token is hex: nothing to decode).
std::string QueryValue(std::string_view target, std::string_view key);
// The path of a request target, without its query.
std::string_view TargetPath(std::string_view target);
// The value of cookie `name` in a Cookie header ("a=1; softsight_token=ab12"); empty when absent.
std::string CookieValue(std::string_view cookie_header, std::string_view name);
// A WebSocket's Origin header is the page's own: "http://" + the Host it connects to. An absent
// Origin (a program, not a browser) is allowed: only browsers carry other sites' pages.
bool OriginMatchesHost(std::string_view origin, std::string_view host);

inline constexpr char kTokenCookie[] = "softsight_token";

// The check every request passes. `token` empty: none required (a loopback bind).
class AccessPolicy {
 public:
  explicit AccessPolicy(std::string token) : token_(std::move(token)) {}
  bool token_required() const { return !token_.empty(); }
  const std::string& token() const { return token_; }
  // The token in the target's query, else in the cookie, matches (or none is required).
  bool allows(std::string_view target, std::string_view cookie_header) const;

 private:
  std::string token_;
};

}  // namespace softsight
