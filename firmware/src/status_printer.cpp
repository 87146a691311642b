#include "status_printer.hpp"

#include <chrono>

#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"
#include "status_line.hpp"

namespace odo::fw {

StatusPrinter::StatusPrinter(std::ostream& log, double period, loop::OdometryLoop& loop,
                             sim::TruthRecorder* truth)
    : log_(log), period_(period), loop_(loop), truth_(truth) {
  thread_ = std::thread([this] { run(); });
}

StatusPrinter::~StatusPrinter() {
  stop();
}

void StatusPrinter::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lk(m_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void StatusPrinter::run() {
  loop::LoopSnapshot s;
  sim::TruthSample truth;
  bool have_truth = false;
  std::uint64_t last_tick = 0;
  auto last = std::chrono::steady_clock::now();
  std::unique_lock lk(m_);
  const auto period = std::chrono::duration<double>(period_);
  while (!cv_.wait_for(lk, period, [&] { return done_; })) {
    if (!loop_.snapshots().latest(s)) continue;
    if (truth_ != nullptr && truth_->latest(truth)) have_truth = true;
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    const double rate = dt > 0 ? static_cast<double>(s.tick - last_tick) / dt : 0.0;
    last = now;
    last_tick = s.tick;
    print_status(log_, s, rate, have_truth ? &truth : nullptr);
  }
}

}  // namespace odo::fw
