// Fuzz target: set-pose command frames received from the bus (odo::protocol::decode_set_pose and
// the broadcaster's receive path). Input: byte 0 = DLC (0..15, only 0..8 exist on the wire, the
// rest must be refused), byte 1 = node offset, bytes 2..9 = data.
// Properties: an accepted command is DLC 0 (reset to zero) or DLC 8 with every value finite and
// inside the documented range, and re-encodes to the same bytes; the broadcaster applies
// exactly the accepted commands for its own node and counts every refused one.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numbers>

#include "fuzz_check.hpp"
#include "odo/firmware/can_broadcast.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/sim/sim_can_bus.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  namespace can = odo::protocol;
  if (size < 2) return 0;
  odo::CanFrame f;
  f.len = static_cast<std::uint8_t>(data[0] & 0x0F);
  const int node = data[1] % 4;  // our node is 1
  f.id = odo::protocol::frame_id(odo::protocol::kDefaultBaseId, node, odo::protocol::Msg::kSetPose);
  std::memcpy(f.data.data(), data + 2, std::min<std::size_t>(8, size - 2));

  odo::SetPose sp;
  const bool ok = odo::protocol::decode_set_pose(f, sp);
  const odo::Pose2& c = sp.pose;
  if (f.len != 0 && f.len != 8)
    require(!ok, "accepted a set-pose frame of a length other than 0/8");
  if (ok) {
    require(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.theta), "not finite");
    require(std::fabs(c.x) <= 8388.608 + 1e-9 && std::fabs(c.y) <= 8388.608 + 1e-9,
            "position outside +-8388.608 m");
    require(c.theta > -std::numbers::pi - 1e-4 && c.theta <= std::numbers::pi + 1e-4,
            "theta outside (-pi, pi] beyond one step");
    if (f.len == 0) require(c.x == 0 && c.y == 0 && c.theta == 0, "reset is not (0, 0, 0)");
    odo::CanFrame g;
    if (f.len == 0)
      odo::protocol::encode_set_pose_reset(f.id, g);
    else
      odo::protocol::encode_set_pose(f.id, sp, g);
    require(g.len == f.len, "re-encoded length differs");
    // Raw theta -31416 decodes to -pi-ish and re-encodes as +31416 (the wire's +pi): the only
    // byte pattern that does not survive unchanged.
    const bool minus_pi = f.len == 8 && f.data[6] == 0x48 && f.data[7] == 0x85;
    if (!minus_pi)
      require(std::memcmp(g.data.data(), f.data.data(), g.len) == 0, "re-encoded bytes differ");
  }

  // The receive path: one frame per tick through a simulated port, no loop attached.
  static odo::sim::SimCanPort port(8, 8);
  odo::fw::CanBroadcastOptions o;  // node 1, nothing sent (all rates 0)
  static odo::fw::CanBroadcaster bc(o, port, nullptr, nullptr);
  const auto before = bc.counters();
  require(port.inject(f), "inject refused");
  odo::loop::LoopSnapshot snap;
  bc.on_tick(snap);
  const auto& after = bc.counters();
  const bool ours = node == odo::protocol::kDefaultNodeId;
  require(after.set_pose_applied - before.set_pose_applied == (ours && ok ? 1u : 0u),
          "applied count does not match the decoder");
  require(after.set_pose_rejected - before.set_pose_rejected == (ours && !ok ? 1u : 0u),
          "rejected count does not match the decoder");
  return 0;
}
