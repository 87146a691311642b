#include "odo/board/uart.hpp"

#include "odo/board/stm32f4.hpp"

namespace odo::board {

void Uart::init(std::uint32_t pclk_hz, std::uint32_t baud, int irq) noexcept {
  // Oversampling by 16: BRR = pclk / baud as 12.4 fixed point, rounded.
  reg(base_ + usart::kBrr) = (pclk_hz + baud / 2) / baud;
  reg(base_ + usart::kCr1) = usart::kCr1Ue | usart::kCr1Te | usart::kCr1Re | usart::kCr1Rxneie;
  nvic_enable(irq, 2);
}

bool Uart::write(const char* p, std::size_t n) noexcept {
  const std::uint32_t head = tx_head_.load(std::memory_order_relaxed);
  const std::uint32_t tail = tx_tail_.load(std::memory_order_acquire);
  if (kTxSize - (head - tail) < n) {
    ++tx_dropped_;
    return false;
  }
  for (std::size_t i = 0; i < n; ++i) tx_[(head + i) & (kTxSize - 1)] = p[i];
  tx_head_.store(head + static_cast<std::uint32_t>(n), std::memory_order_release);
  // Start the line here, then the TXE interrupt drains the ring; a USART model that never raises
  // TXE interrupts (QEMU 7.2's) but is always ready takes everything here.
  asm volatile("cpsid i" ::: "memory");
  drain();
  reg(base_ + usart::kCr1) |= usart::kCr1Txeie;
  asm volatile("cpsie i" ::: "memory");
  return true;
}

void Uart::drain() noexcept {
  std::uint32_t tail = tx_tail_.load(std::memory_order_relaxed);
  while (tail != tx_head_.load(std::memory_order_acquire) &&
         (reg(base_ + usart::kSr) & usart::kSrTxe) != 0) {
    reg(base_ + usart::kDr) = static_cast<std::uint8_t>(tx_[tail & (kTxSize - 1)]);
    tx_tail_.store(++tail, std::memory_order_release);
  }
}

bool Uart::read(char& c) noexcept {
  const std::uint32_t tail = rx_tail_.load(std::memory_order_relaxed);
  if (tail == rx_head_.load(std::memory_order_acquire)) return false;
  c = rx_[tail & (kRxSize - 1)];
  rx_tail_.store(tail + 1, std::memory_order_release);
  return true;
}

void Uart::write_polled(const char* p) noexcept {
  for (; *p != '\0'; ++p) {
    while ((reg(base_ + usart::kSr) & usart::kSrTxe) == 0) {
    }
    reg(base_ + usart::kDr) = static_cast<std::uint8_t>(*p);
  }
}

void Uart::flush() noexcept {
  while (tx_tail_.load(std::memory_order_acquire) != tx_head_.load(std::memory_order_relaxed)) {
    asm volatile("cpsid i" ::: "memory");
    drain();
    asm volatile("cpsie i" ::: "memory");
  }
}

void Uart::irq() noexcept {
  const std::uint32_t sr = reg(base_ + usart::kSr);
  if ((sr & (usart::kSrRxne | usart::kSrOre)) != 0) {
    const auto c = static_cast<char>(reg(base_ + usart::kDr) & 0xFFu);  // clears RXNE and ORE
    const std::uint32_t head = rx_head_.load(std::memory_order_relaxed);
    if (head - rx_tail_.load(std::memory_order_acquire) < kRxSize) {
      rx_[head & (kRxSize - 1)] = c;
      rx_head_.store(head + 1, std::memory_order_release);
    } else {
      ++rx_overruns_;
    }
  }
  if ((sr & usart::kSrTxe) != 0 && (reg(base_ + usart::kCr1) & usart::kCr1Txeie) != 0) {
    drain();
    if (tx_tail_.load(std::memory_order_relaxed) == tx_head_.load(std::memory_order_acquire))
      reg(base_ + usart::kCr1) &= ~usart::kCr1Txeie;
  }
}

Uart& uart1() noexcept {
  static constinit Uart u{usart::kUsart1};
  return u;
}
Uart& uart2() noexcept {
  static constinit Uart u{usart::kUsart2};
  return u;
}

}  // namespace odo::board

extern "C" void odo_usart1_irq() {
  odo::board::uart1().irq();
}
extern "C" void odo_usart2_irq() {
  odo::board::uart2().irq();
}
