// SimOdrive: a simulated pair of ODrive-style motor controller axes that publish their
// encoder counts cyclically on a SimCanPort as CAN Simple Get_Encoder_Count messages (id
// node_id << 5 | 0x00A, DLC 8: int32 shadow count at byte 0, int32 count-in-CPR at byte 4,
// little endian). The frames are packed here independently of the firmware's decoder.
// Fault hooks: an axis stops sending (wire cut, controller reset), a count jump.
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/time.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::sim {

struct SimOdriveOptions {
  std::uint32_t node_left = 0;   // CAN node id of the left axis, 0..63
  std::uint32_t node_right = 1;  // right axis
  std::int64_t cpr = 8192;       // counts per motor revolution (for count-in-CPR) [counts]
};

class SimOdrive {
 public:
  // port: where the frames go (not owned, must outlive this object).
  SimOdrive(SimCanPort& port, const SimOdriveOptions& o) : port_(port), opts_(o) {}

  // publish: one Get_Encoder_Count frame per sending axis with the cumulative counts `left`,
  // `right` [counts] received at `stamp` [ns]; the shadow count wraps as an int32.
  void publish(TimeNs stamp, std::int64_t left, std::int64_t right) noexcept;

  // set_sending: fault hook: axis `wheel` (0 left, 1 right) stops (false) or resumes sending.
  void set_sending(int wheel, bool on) noexcept { sending_[idx(wheel)] = on; }
  // add_jump: fault hook: the axis' count leaps by `delta` [counts] from now on.
  void add_jump(int wheel, std::int64_t delta) noexcept { jump_[idx(wheel)] += delta; }
  // frames: frames offered to the port so far.
  std::uint64_t frames() const noexcept { return frames_; }

 private:
  static std::size_t idx(int wheel) noexcept { return wheel == 0 ? 0 : 1; }
  SimCanPort& port_;
  SimOdriveOptions opts_;
  std::array<bool, 2> sending_{true, true};
  std::array<std::int64_t, 2> jump_{};
  std::uint64_t frames_ = 0;
};

}  // namespace odo::sim
