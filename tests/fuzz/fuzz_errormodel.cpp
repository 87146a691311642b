// Fuzz target: the run-error CSV of `odomctl errormodel fit` (odo::analysis::read_run_errors) and
// the fit that follows it (odo::analysis::fit_error_model, 10 m out and back, 0.34 m wheelbase).
// Properties: never crashes, hangs or overflows (ASan, UBSan); a rejected file has a message
// that starts with "fuzz.csv:"; an accepted file has finite errors within the documented
// +-1000 m/rad, and a fit that succeeds gives finite, non-negative k_L and k_R.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "fuzz_check.hpp"
#include "odo/analysis/error_model_tools.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  auto runs = odo::analysis::read_run_errors(in, "fuzz.csv");
  if (!runs) {
    require(runs.error().message.rfind("fuzz.csv:", 0) == 0,
            "error message does not name the file:", runs.error().message);
    return 0;
  }
  for (const auto& e : *runs) {
    for (double v : e) require(std::isfinite(v) && std::fabs(v) <= 1000.0, "error out of range");
  }
  auto fit = odo::analysis::fit_error_model(*runs, 10.0, 0.34);
  if (fit) {
    require(std::isfinite(fit->k.k_left) && fit->k.k_left >= 0.0, "k_left not finite/negative");
    require(std::isfinite(fit->k.k_right) && fit->k.k_right >= 0.0, "k_right not finite/negative");
  }
  return 0;
}
