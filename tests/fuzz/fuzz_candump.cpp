// Fuzz target: the candump -L log parser of `odomctl decode` (odo::protocol::parse_candump_line)
// and the protocol decoder behind it. Input: text, split into lines. Properties: an accepted line
// has a classic frame (id within 11/29 bits, 0..8 bytes), printing it again in candump -L format
// and parsing that gives the same frame; a decoded frame of our protocol has a node 0..63 and
// finite values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "odo/firmware/can_broadcast.hpp"
#include "odo/protocol/candump_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    auto p = odo::protocol::parse_candump_line(line);
    if (!p) {
      require(!p.error().message.empty(), "rejected without a message");
      continue;
    }
    const odo::CanFrame& f = p->frame;
    require(f.len <= 8, "more than 8 data bytes");
    require(f.id <= (f.extended ? 0x1FFFFFFFu : 0x7FFu), "id out of range");
    require(p->usec >= 0 && p->usec <= 999999, "microseconds out of range");
    char buf[128];
    const std::size_t n = odo::protocol::format_candump_line(
        buf, sizeof buf, p->sec * 1'000'000'000 + p->usec * 1000, p->iface.c_str(), f);
    require(n > 1, "could not print an accepted frame");
    auto q = odo::protocol::parse_candump_line(std::string_view(buf, n - 1));
    require(q.ok(), "own output not parsed back:", std::string(buf, n));
    require(q->frame.id == f.id && q->frame.extended == f.extended && q->frame.len == f.len &&
                q->frame.data == f.data && q->sec == p->sec && q->usec == p->usec,
            "round trip changed the frame:", std::string(buf, n));
    odo::protocol::DecodedFrame d;
    if (odo::protocol::decode_protocol_frame(odo::protocol::kDefaultBaseId, f, d)) {
      require(d.node >= 0 && d.node <= 63, "node out of range");
      for (std::size_t i = 0; i < d.n_fields; ++i)
        require(std::isfinite(d.fields[i].value), "decoded value not finite", d.fields[i].name);
    }
  }
  return 0;
}
