#include "web/access.h"

#include <boost/asio/ip/address.hpp>
#include <random>

namespace softsight {

std::string NewAccessToken() {
  std::random_device device;  // /dev/urandom on Linux.
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (int word = 0; word < 4; ++word) {
    uint32_t bits = device();
    for (int i = 0; i < 8; ++i, bits >>= 4) token += kHex[bits & 0xF];
  }
  return token;
}

bool IsLoopbackAddress(const std::string& address) {
  if (address == "localhost") return true;
  boost::system::error_code error;
  const boost::asio::ip::address parsed = boost::asio::ip::make_address(address, error);
  return !error && parsed.is_loopback();
}

bool TokenMatches(std::string_view given, std::string_view expected) {
  // Every byte is compared whatever the earlier ones were: the time says nothing of how much
  // of a guess was right. (The length is not secret: every token is 32 digits.)
  if (given.size() != expected.size()) return false;
  unsigned char differ = 0;
  for (size_t i = 0; i < given.size(); ++i) {
    differ |= static_cast<unsigned char>(given[i] ^ expected[i]);
  }
  return differ == 0;
}

std::string_view TargetPath(std::string_view target) {
  return target.substr(0, target.find('?'));
}

std::string QueryValue(std::string_view target, std::string_view key) {
  const size_t question = target.find('?');
  if (question == std::string_view::npos) return {};
  std::string_view query = target.substr(question + 1);
  while (!query.empty()) {
    const size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const size_t equals = pair.find('=');
    if (pair.substr(0, equals) == key) {
      return equals == std::string_view::npos ? std::string() : std::string(pair.substr(equals + 1));
    }
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return {};
}

std::string CookieValue(std::string_view cookie_header, std::string_view name) {
  while (!cookie_header.empty()) {
    const size_t semicolon = cookie_header.find(';');
    std::string_view pair = cookie_header.substr(0, semicolon);
    while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
    const size_t equals = pair.find('=');
    if (equals != std::string_view::npos && pair.substr(0, equals) == name) {
      return std::string(pair.substr(equals + 1));
    }
    if (semicolon == std::string_view::npos) break;
    cookie_header.remove_prefix(semicolon + 1);
  }
  return {};
}

bool OriginMatchesHost(std::string_view origin, std::string_view host) {
  if (origin.empty()) return true;
  constexpr std::string_view kScheme = "http://";
  return origin.size() == kScheme.size() + host.size() && origin.substr(0, kScheme.size()) == kScheme &&
         origin.substr(kScheme.size()) == host;
}

bool AccessPolicy::allows(std::string_view target, std::string_view cookie_header) const {
  if (token_.empty()) return true;
  const std::string in_query = QueryValue(target, "token");
  if (!in_query.empty()) return TokenMatches(in_query, token_);
  return TokenMatches(CookieValue(cookie_header, kTokenCookie), token_);
}

}  // namespace softsight
