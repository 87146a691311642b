// SimCanPort: a simulated CAN bus endpoint for tests and the simulated robot. Frames the firmware
// sends wait in a bounded transmit queue until the simulated wire takes them (drain_tx), or are
// taken at once by a connected wire (connect_wire: an idle bus, as the daemon simulates); frames
// for the firmware are injected into a bounded receive queue. Faults: link down, a transmit
// queue that fills (the controller stalls), and receive floods that overflow the queue.
// Fixed capacities: no allocation after construction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "odo/hal/can_bus.hpp"

namespace odo::sim {

// FrameRing: a bounded FIFO of frames, allocated once.
class FrameRing {
 public:
  explicit FrameRing(std::size_t capacity) : buf_(capacity) {}
  // push: false when full (the frame is not stored).
  bool push(const CanFrame& f) noexcept;
  // pop: false when empty.
  bool pop(CanFrame& out) noexcept;
  std::size_t size() const noexcept { return size_; }
  std::size_t capacity() const noexcept { return buf_.size(); }
  void clear() noexcept { head_ = size_ = 0; }

 private:
  std::vector<CanFrame> buf_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

struct SimCanCounters {
  std::uint64_t sent = 0;        // frames accepted (queued, or taken by a connected wire)
  std::uint64_t tx_full = 0;     // sends refused: transmit queue full
  std::uint64_t tx_down = 0;     // sends refused: link down
  std::uint64_t rx_dropped = 0;  // injected frames lost: receive queue full or link down
};

class SimCanPort final : public CanBus {
 public:
  // tx_capacity, rx_capacity: queue lengths [frames], >= 1.
  explicit SimCanPort(std::size_t tx_capacity = 64, std::size_t rx_capacity = 256);

  CanTx send(const CanFrame& f) noexcept override;
  bool receive(CanFrame& out) noexcept override;

  // inject: a frame arrives from the bus (stamp in ns of the loop's clock); false if dropped.
  bool inject(const CanFrame& f) noexcept;
  // drain_tx: the wire takes the oldest queued frame; false when the queue is empty.
  bool drain_tx(CanFrame& out) noexcept { return tx_.pop(out); }
  // connect_wire: from now on the wire takes every frame as it is sent (an idle bus that never
  // backs up): nothing waits in the transmit queue, nobody has to drain it.
  void connect_wire() noexcept { wire_ = true; }
  // set_link_up: a downed link refuses sends and loses what was queued, like a bus-off.
  void set_link_up(bool up) noexcept;
  bool link_up() const noexcept { return up_; }
  std::size_t tx_queued() const noexcept { return tx_.size(); }
  const SimCanCounters& counters() const noexcept { return counters_; }

 private:
  FrameRing tx_;
  FrameRing rx_;
  bool up_ = true;
  bool wire_ = false;  // connect_wire()
  SimCanCounters counters_;
};

}  // namespace odo::sim
