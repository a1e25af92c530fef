#include "softsight/control/protocol.h"

#include <cctype>
#include <cstring>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace softsight::wire {
namespace {

std::string Encode(MessageType type, std::initializer_list<int32_t> args) {
  Message m;
  m.type = type;
  for (int32_t a : args) m.args[m.argc++] = a;
  char buffer[kLineBufferSize];
  const size_t n = EncodeMessage(m, buffer, sizeof(buffer));
  return std::string(buffer, n);
}

TEST(Protocol, EncodesReadableLinesWithXorChecksum) {
  // XOR of "SETP 17 25000" is 0x0D... computed by hand below rather than trusted from the encoder.
  const std::string body = "SETP 17 25000";
  uint8_t sum = 0;
  for (char c : body) sum ^= static_cast<uint8_t>(c);
  char hex[3];
  std::snprintf(hex, sizeof(hex), "%02X", sum);
  EXPECT_EQ(Encode(MessageType::kSetPressure, {17, 25000}), "$" + body + "*" + hex + "\n");
  EXPECT_EQ(Encode(MessageType::kSetDuty, {3, -1000}).substr(0, 14), "$DUTY 3 -1000*");
}

TEST(Protocol, RoundTripsEveryMessageType) {
  const MessageType types[] = {MessageType::kHello, MessageType::kSetPressure,
                               MessageType::kSetDuty, MessageType::kRead, MessageType::kStop,
                               MessageType::kPing, MessageType::kHelloReply, MessageType::kState,
                               MessageType::kError};
  std::mt19937 rng(5);
  std::uniform_int_distribution<int32_t> value(-2147483647, 2147483647);
  for (MessageType type : types) {
    for (int trial = 0; trial < 20; ++trial) {
      Message m;
      m.type = type;
      m.argc = static_cast<uint8_t>(ArgumentCount(type));
      for (int i = 0; i < m.argc; ++i) m.args[i] = trial == 0 ? 0 : value(rng);
      char buffer[kLineBufferSize];
      const size_t n = EncodeMessage(m, buffer, sizeof(buffer));
      ASSERT_GT(n, 0u) << CommandWord(type);
      Message back;
      ASSERT_EQ(DecodeLine(buffer, n - 1, &back), DecodeStatus::kOk) << buffer;
      EXPECT_EQ(back.type, type);
      ASSERT_EQ(back.argc, m.argc);
      for (int i = 0; i < m.argc; ++i) EXPECT_EQ(back.args[i], m.args[i]);
    }
  }
}

TEST(Protocol, AcceptsCarriageReturnBeforeNewline) {
  Message m;
  std::string line = Encode(MessageType::kPing, {4});
  line.back() = '\r';
  EXPECT_EQ(DecodeLine(line.data(), line.size(), &m), DecodeStatus::kOk);
}

TEST(Protocol, RejectsEveryTruncation) {
  const std::string line = Encode(MessageType::kState, {9, 1234, 25000, 26000, -150, 17, 0});
  for (size_t n = 1; n + 1 < line.size(); ++n) {  // Every prefix of the body (no '\n').
    Message m;
    EXPECT_NE(DecodeLine(line.data(), n, &m), DecodeStatus::kOk) << line.substr(0, n);
    EXPECT_EQ(m.type, MessageType::kNone);
  }
  // And every suffix (the start of a line lost).
  for (size_t start = 1; start + 1 < line.size(); ++start) {
    Message m;
    EXPECT_NE(DecodeLine(line.data() + start, line.size() - 1 - start, &m), DecodeStatus::kOk);
  }
}

TEST(Protocol, RejectsEverySingleBitFlip) {
  const std::string lines[] = {Encode(MessageType::kSetPressure, {17, 25000}),
                               Encode(MessageType::kState, {9, 1234, 25000, 26000, -150, 17, 0})};
  for (const std::string& line : lines) {
    for (size_t i = 0; i + 1 < line.size(); ++i) {
      for (int bit = 0; bit < 8; ++bit) {
        std::string bad = line;
        bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
        Message m;
        EXPECT_NE(DecodeLine(bad.data(), bad.size() - 1, &m), DecodeStatus::kOk)
            << "byte " << i << " bit " << bit;
      }
    }
  }
}

TEST(Protocol, RejectsRandomGarbage) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> length(1, 120);
  int accepted = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    std::string junk(static_cast<size_t>(length(rng)), '\0');
    for (char& c : junk) c = static_cast<char>(byte(rng));
    Message m;
    if (DecodeLine(junk.data(), junk.size(), &m) == DecodeStatus::kOk) ++accepted;
  }
  EXPECT_EQ(accepted, 0);
}

TEST(Protocol, RejectsWellFormedButWrongContent) {
  auto with_checksum = [](const std::string& body) {
    uint8_t sum = 0;
    for (char c : body) sum ^= static_cast<uint8_t>(c);
    char hex[3];
    std::snprintf(hex, sizeof(hex), "%02X", sum);
    return "$" + body + "*" + hex;
  };
  Message m;
  auto decode = [&](const std::string& body) {
    const std::string line = with_checksum(body);
    return DecodeLine(line.data(), line.size(), &m);
  };
  EXPECT_EQ(decode("FLY 1"), DecodeStatus::kUnknownCommand);
  EXPECT_EQ(decode("SETP 1"), DecodeStatus::kBadArguments);          // Too few.
  EXPECT_EQ(decode("SETP 1 2 3"), DecodeStatus::kBadArguments);      // Too many.
  EXPECT_EQ(decode("SETP 1 2.5"), DecodeStatus::kBadArguments);      // Not an integer.
  EXPECT_EQ(decode("SETP 1  2"), DecodeStatus::kBadArguments);       // Double space.
  EXPECT_EQ(decode("SETP 1 99999999999"), DecodeStatus::kBadArguments);  // Overflow.
  EXPECT_EQ(decode("SETP 1 -"), DecodeStatus::kBadArguments);
  EXPECT_EQ(decode("SETP 1 2"), DecodeStatus::kOk);
  // Lower-case hex digits are never written, so they are not accepted either.
  const std::string upper = with_checksum("PING 28");
  ASSERT_EQ(upper, "$PING 28*3A");
  EXPECT_EQ(DecodeLine(upper.data(), upper.size(), &m), DecodeStatus::kOk);
  const std::string lowered = "$PING 28*3a";
  EXPECT_EQ(DecodeLine(lowered.data(), lowered.size(), &m), DecodeStatus::kNoChecksum);
  EXPECT_EQ(DecodeLine("", 0, &m), DecodeStatus::kEmpty);
  EXPECT_EQ(DecodeLine("   ", 3, &m), DecodeStatus::kEmpty);
}

TEST(Protocol, EncoderRefusesSmallBuffersAndWrongArgumentCounts) {
  Message m;
  m.type = MessageType::kState;
  m.argc = 7;
  char small[12];
  EXPECT_EQ(EncodeMessage(m, small, sizeof(small)), 0u);
  m.argc = 2;
  char buffer[kLineBufferSize];
  EXPECT_EQ(EncodeMessage(m, buffer, sizeof(buffer)), 0u);
}

TEST(LineAssembler, SplitsLinesAndDropsOverlongOnesWhole) {
  LineAssembler a;
  std::string stream = "$PING 1*XX\n" + std::string(300, 'x') + "\n$READ 2*YY\n";
  std::vector<std::string> lines;
  int too_long = 0;
  for (char c : stream) {
    const LineAssembler::Event e = a.push(c);
    if (e == LineAssembler::Event::kLine) lines.emplace_back(a.line(), a.length());
    if (e == LineAssembler::Event::kTooLong) ++too_long;
  }
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "$PING 1*XX");
  EXPECT_EQ(lines[1], "$READ 2*YY");
  EXPECT_EQ(too_long, 1);
}

}  // namespace
}  // namespace softsight::wire
