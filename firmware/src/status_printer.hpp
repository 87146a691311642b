// StatusPrinter: odometryd's status thread (its only thread): one status line every period from
// the loop's newest snapshot, so the loop never blocks on a terminal or pipe. Private to
// firmware/.
#pragma once

#include <condition_variable>
#include <iosfwd>
#include <mutex>
#include <thread>

#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {

// StatusPrinter: a thread that prints one status line every `period` [s] from the loop's newest
// snapshot (and the simulation's truth, when there is one); the loop never waits for it.
class StatusPrinter {
 public:
  StatusPrinter(std::ostream& log, double period, loop::OdometryLoop& loop,
                sim::TruthRecorder* truth);
  ~StatusPrinter();
  StatusPrinter(const StatusPrinter&) = delete;
  StatusPrinter& operator=(const StatusPrinter&) = delete;
  // stop: ends and joins the thread (idempotent).
  void stop();

 private:
  void run();
  std::ostream& log_;
  double period_;
  loop::OdometryLoop& loop_;
  sim::TruthRecorder* truth_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace odo::fw
