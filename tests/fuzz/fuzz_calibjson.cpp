// Fuzz target: the JSON that `odomctl calib import` accepts (odo::analysis::parse_calibration_json:
// the exchange format, `calib show --json` output or `umbmark compute --json` output).
// Properties: never crashes, hangs or overflows (ASan, UBSan); no exception escapes; a rejected
// text has a message that starts with the source name; an accepted record passes
// validate_record and survives the store's encoding unchanged.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_check.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/calibration/record.hpp"
#include "odo/firmware/calibration_store.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto r = odo::analysis::parse_calibration_json(text, "fuzz.json", 1700000000);
  if (!r) {
    require(r.error().message.rfind("fuzz.json", 0) == 0,
            "error message does not name the source:", r.error().message);
    return 0;
  }
  require(odo::calib::validate_record(*r).ok(), "accepted record fails validate_record");
  auto bytes = odo::calib::encode_record(*r);
  require(bytes.ok(), "accepted record does not encode");
  auto back = odo::calib::decode_record(*bytes);
  require(back.ok() && *back == *r, "accepted record changes through the store encoding");
  return 0;
}
