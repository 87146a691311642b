// Fuzz target: the UMBmark CSV reader (odo::analysis::read_umbmark_runs on top of
// odo::analysis::CsvReader) and the computation it feeds (odo::calib::umbmark_compute, 4 m square,
// 0.34 m wheelbase). Properties: never crashes, hangs or overflows (ASan, UBSan); a rejected file
// has a message "fuzz.csv:<line>: ..."; an accepted file either computes finite results or is
// refused with a message naming the field.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "fuzz_check.hpp"
#include "odo/analysis/umbmark_tools.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  auto runs = odo::analysis::read_umbmark_runs(in, "fuzz.csv");
  if (!runs) {
    require(odo::fuzz::starts_with_location(runs.error().message, "fuzz.csv"),
            "error message does not name file and line:", runs.error().message);
    return 0;
  }
  odo::calib::UmbmarkInput ui;
  ui.runs = std::move(runs).value();
  ui.side = 4.0;
  ui.current = {1.0, 1.0, 0.34};
  auto r = odo::calib::umbmark_compute(ui);
  if (!r) {
    const std::string& m = r.error().message;
    bool named = false;
    for (const char* f : {"alpha", "beta", "direction", "c_l", "c_r", "etheta", "finite"})
      named = named || m.find(f) != std::string::npos;
    require(named, "compute error does not name the field:", m);
    return 0;
  }
  for (double v : {r->cw.x, r->cw.y, r->ccw.x, r->ccw.y, r->e_max_syst, r->ab.alpha, r->ab.beta,
                   r->e_d, r->e_b, r->composed.c_l, r->composed.c_r, r->composed.wheelbase,
                   r->spread.sem, r->spread.sigma.value_or(0.0), r->eps_theta_nonsys.value_or(0.0),
                   r->radius.value_or(0.0)}) {
    require(std::isfinite(v), "accepted input gave a non-finite result");
  }
  require(r->e_d > 0.0 && r->e_b > 0.0 && r->composed.wheelbase > 0.0, "non-positive factor");
  return 0;
}
