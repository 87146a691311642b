// Uart: one STM32F4 USART at 8N1. Transmission through a ring drained by the TXE interrupt (the
// loop never waits for the line; a full ring drops and counts); reception into a ring filled by
// the RXNE interrupt. Polled writes for fault reports.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace odo::board {

class Uart {
 public:
  static constexpr std::size_t kTxSize = 2048;  // power of two [bytes]
  static constexpr std::size_t kRxSize = 256;   // power of two [bytes]

  // Uart: the USART at `base` (stm32f4.hpp usart::kUsart1, kUsart2).
  explicit constexpr Uart(std::uintptr_t base) noexcept : base_(base) {}
  // init: `baud` [bit/s] from the peripheral clock `pclk_hz` [Hz]; interrupt `irq` enabled.
  void init(std::uint32_t pclk_hz, std::uint32_t baud, int irq) noexcept;
  // write: queues n bytes; false (and nothing queued) when they do not fit.
  bool write(const char* p, std::size_t n) noexcept;
  // read: takes one received byte; false when none is waiting.
  bool read(char& c) noexcept;
  // write_polled: waits for each byte to leave (faults, interrupts off).
  void write_polled(const char* p) noexcept;
  // flush: waits until the ring is empty (end of a run).
  void flush() noexcept;
  // irq: the interrupt handler's body.
  void irq() noexcept;
  std::uint32_t tx_dropped() const noexcept { return tx_dropped_; }
  std::uint32_t rx_overruns() const noexcept { return rx_overruns_; }

 private:
  // drain: bytes from the ring into the data register while it is empty (interrupts masked).
  void drain() noexcept;
  std::uintptr_t base_;
  char tx_[kTxSize] = {};
  char rx_[kRxSize] = {};
  std::atomic<std::uint32_t> tx_head_{0}, tx_tail_{0}, rx_head_{0}, rx_tail_{0};
  std::uint32_t tx_dropped_ = 0;
  std::uint32_t rx_overruns_ = 0;
};

// uart1, uart2: the board's two serial lines (USART1: SLCAN and reports; USART2: serial counts).
Uart& uart1() noexcept;
Uart& uart2() noexcept;

}  // namespace odo::board
