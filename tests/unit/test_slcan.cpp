// SLCAN framing (protocol/slcan.hpp): the Lawicel lines written out by hand.
#include <gtest/gtest.h>

#include <string>

#include "odo/protocol/slcan.hpp"

namespace {

using odo::CanFrame;
using odo::protocol::encode_slcan;
using odo::protocol::kSlcanLineMax;
using Event = odo::protocol::SlcanDecoder::Event;

std::string line_of(const CanFrame& f) {
  char out[kSlcanLineMax];
  return std::string(out, encode_slcan(f, out));
}

// feed: pushes s; the last event.
Event feed(odo::protocol::SlcanDecoder& d, const std::string& s) {
  Event e = Event::kNone;
  for (char c : s) e = d.push(c);
  return e;
}

TEST(Slcan, EncodesStandardExtendedAndRemoteFrames) {
  CanFrame f;
  f.id = 0x410;
  f.len = 8;
  f.data = {0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x0E};
  EXPECT_EQ(line_of(f), "t4108030000000000000E\r");
  f.id = 0x1ABCDEF0;  // 29 bits: 8 digits
  f.extended = true;
  f.len = 2;
  f.data = {0xFF, 0x0A};
  EXPECT_EQ(line_of(f), "T1ABCDEF02FF0A\r");
  f.rtr = true;  // remote: the DLC, no data
  EXPECT_EQ(line_of(f), "R1ABCDEF02\r");
  CanFrame e;  // DLC 0 (the set-pose reset): no data digits
  e.id = 0x418;
  EXPECT_EQ(line_of(e), "t4180\r");
  EXPECT_EQ(line_of(f).size() + 16, kSlcanLineMax);  // the longest: T, 8 id, DLC, 16 data, \r
}

TEST(Slcan, DecodesWhatItEncodes) {
  odo::protocol::SlcanDecoder d;
  ASSERT_EQ(feed(d, "t4188002710004E201010\r"), Event::kFrame);
  const CanFrame& f = d.frame();
  EXPECT_EQ(f.id, 0x418u);
  EXPECT_FALSE(f.extended);
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data[0], 0x00);
  EXPECT_EQ(f.data[1], 0x27);
  EXPECT_EQ(f.data[7], 0x10);
  ASSERT_EQ(feed(d, "T1abcdef02ff0a\r"), Event::kFrame);  // lower-case hex too
  EXPECT_TRUE(d.frame().extended);
  EXPECT_EQ(d.frame().id, 0x1ABCDEF0u);
  EXPECT_EQ(d.frame().data[0], 0xFF);
}

TEST(Slcan, CommandsAndBadLines) {
  odo::protocol::SlcanDecoder d;
  EXPECT_EQ(feed(d, "S6\r"), Event::kCommand);  // what slcand sends: bit rate, open
  EXPECT_EQ(d.command(), 'S');
  EXPECT_EQ(feed(d, "O\r"), Event::kCommand);
  EXPECT_EQ(feed(d, "# a comment line\r"), Event::kCommand);
  EXPECT_EQ(feed(d, "\r"), Event::kNone);           // empty line
  EXPECT_EQ(feed(d, "t4189\r"), Event::kError);     // DLC 9
  EXPECT_EQ(feed(d, "t4182001\r"), Event::kError);  // 2 bytes announced, 1.5 given
  EXPECT_EQ(feed(d, "t8001\r"), Event::kError);     // 0x800: not an 11-bit id
  EXPECT_EQ(feed(d, "t41G0\r"), Event::kError);     // not hex
  std::string overlong(40, '0');
  overlong += '\r';  // two steps: see TESTING.md, "The tests' precompiled header"
  EXPECT_EQ(feed(d, overlong), Event::kError);
  EXPECT_EQ(feed(d, "\nt4180\r"), Event::kFrame);  // a line feed is no part of a line
  EXPECT_EQ(d.frame().len, 0);
}

}  // namespace
