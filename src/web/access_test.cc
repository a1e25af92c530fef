#include "web/access.h"

#include <gtest/gtest.h>

#include <set>

namespace softsight {
namespace {

TEST(AccessTest, TokensAre32HexDigitsAndDifferEachTime) {
  std::set<std::string> seen;
  for (int i = 0; i < 50; ++i) {
    const std::string token = NewAccessToken();
    ASSERT_EQ(token.size(), 32u);
    EXPECT_EQ(token.find_first_not_of("0123456789abcdef"), std::string::npos) << token;
    seen.insert(token);
  }
  EXPECT_EQ(seen.size(), 50u);
}

TEST(AccessTest, LoopbackIsOnlyTheLoopbackInterface) {
  EXPECT_TRUE(IsLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("127.1.2.3"));
  EXPECT_TRUE(IsLoopbackAddress("::1"));
  EXPECT_TRUE(IsLoopbackAddress("localhost"));
  EXPECT_FALSE(IsLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(IsLoopbackAddress("::"));
  EXPECT_FALSE(IsLoopbackAddress("192.168.1.20"));
  EXPECT_FALSE(IsLoopbackAddress("rig.local"));  // A name could resolve anywhere.
}

TEST(AccessTest, TokenMatchesOnlyTheWholeToken) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  EXPECT_TRUE(TokenMatches(token, token));
  EXPECT_FALSE(TokenMatches("0123456789abcdef0123456789abcdee", token));
  EXPECT_FALSE(TokenMatches("0123456789abcdef", token));
  EXPECT_FALSE(TokenMatches("", token));
  EXPECT_FALSE(TokenMatches(token + "0", token));
}

TEST(AccessTest, QueryAndCookieValues) {
  EXPECT_EQ(QueryValue("/ws?token=ab12", "token"), "ab12");
  EXPECT_EQ(QueryValue("/?x=1&token=ab12&y=2", "token"), "ab12");
  EXPECT_EQ(QueryValue("/?tokens=ab12", "token"), "");
  EXPECT_EQ(QueryValue("/index.html", "token"), "");
  EXPECT_EQ(TargetPath("/ws?token=ab12"), "/ws");
  EXPECT_EQ(CookieValue("a=1; softsight_token=ab12; b=2", kTokenCookie), "ab12");
  EXPECT_EQ(CookieValue("softsight_token_old=zz", kTokenCookie), "");
}

TEST(AccessTest, PolicyTakesTheQueryFirstThenTheCookie) {
  const std::string token = NewAccessToken();
  const AccessPolicy open("");
  EXPECT_TRUE(open.allows("/", ""));
  const AccessPolicy guarded(token);
  EXPECT_TRUE(guarded.allows("/?token=" + token, ""));
  EXPECT_TRUE(guarded.allows("/app.js", std::string(kTokenCookie) + "=" + token));
  EXPECT_FALSE(guarded.allows("/", ""));
  EXPECT_FALSE(guarded.allows("/?token=0000", ""));
  // A wrong token in the URL is refused even with the right cookie.
  EXPECT_FALSE(guarded.allows("/?token=0000", std::string(kTokenCookie) + "=" + token));
}

TEST(AccessTest, WebSocketsOnlyFromTheServersOwnPages) {
  EXPECT_TRUE(OriginMatchesHost("http://127.0.0.1:8090", "127.0.0.1:8090"));
  EXPECT_TRUE(OriginMatchesHost("", "127.0.0.1:8090"));  // Not a browser.
  EXPECT_FALSE(OriginMatchesHost("http://evil.example", "127.0.0.1:8090"));
  EXPECT_FALSE(OriginMatchesHost("http://127.0.0.1:8091", "127.0.0.1:8090"));
}

}  // namespace
}  // namespace softsight
