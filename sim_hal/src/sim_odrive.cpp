#include "odo/sim/sim_odrive.hpp"

#include "odo/hal/bytes.hpp"

namespace odo::sim {

void SimOdrive::publish(TimeNs stamp, std::int64_t left, std::int64_t right) noexcept {
  const std::array<std::int64_t, 2> counts{left, right};
  const std::array<std::uint32_t, 2> nodes{opts_.node_left, opts_.node_right};
  for (std::size_t i = 0; i < 2; ++i) {
    if (!sending_[i]) continue;
    const std::int64_t c = counts[i] + jump_[i];
    CanFrame f;
    f.id = (nodes[i] << 5) | 0x00A;
    f.len = 8;
    f.stamp = stamp;
    put_le(f.data.data(), 4, static_cast<std::uint64_t>(c));  // the low 32 bits
    const std::int64_t in_cpr = ((c % opts_.cpr) + opts_.cpr) % opts_.cpr;
    put_le(f.data.data() + 4, 4, static_cast<std::uint64_t>(in_cpr));
    port_.inject(f);
    ++frames_;
  }
}

}  // namespace odo::sim
