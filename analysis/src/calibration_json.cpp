#include "odo/analysis/calibration_json.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

namespace odo::analysis {
namespace {

using calib::CalibrationRecord;
using calib::LoadResult;
using calib::StoreStatus;
using nlohmann::json;

json opt(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

json provenance_json(const CalibrationRecord& r) {
  return json{{"time", r.time},
              {"time_utc", calib::utc_text(r.time)},
              {"method", r.method},
              {"e_max_syst_before", opt(r.e_max_before)},
              {"e_max_syst_after", opt(r.e_max_after)},
              {"runs", r.runs}};
}

// Reads optional numeric fields with type checks; the first problem is kept in `error`.
struct FieldReader {
  const json& j;
  std::string_view source;
  std::string error;

  std::optional<double> number(const char* key) {
    auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::nullopt;
    if (!it->is_number()) {
      fail(key, "expected a number");
      return std::nullopt;
    }
    return it->get<double>();
  }
  std::optional<std::int64_t> integer(const char* key) {
    auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::nullopt;
    if (!it->is_number_integer()) {
      fail(key, "expected an integer");
      return std::nullopt;
    }
    return it->get<std::int64_t>();
  }
  std::optional<std::string> text(const char* key) {
    auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::nullopt;
    if (!it->is_string()) {
      fail(key, "expected a string");
      return std::nullopt;
    }
    return it->get<std::string>();
  }
  void fail(const char* key, const std::string& what) {
    if (error.empty()) error = std::string(source) + ": field " + key + ": " + what;
  }
};

Error bad(std::string_view source, const std::string& what) {
  return make_error(Errc::kInvalidArgument, std::string(source) + ": " + what);
}

}  // namespace

std::string show_json(const LoadResult& l) {
  json j;
  j["status"] = calib::status_name(l.status);
  j["sequence"] = l.record ? l.record->sequence : 0;
  j["slot"] = l.slot < 0 ? json(nullptr) : json(l.slot == 0 ? "A" : "B");
  const bool ok = l.status == StoreStatus::kOk;
  // Uncalibrated: the firmware runs on factors of 1 and the nominal geometry (null here).
  const bool known = l.status != StoreStatus::kCorrupt;
  j["c_l"] = ok ? json(l.record->c_l) : known ? json(1.0) : json(nullptr);
  j["c_r"] = ok ? json(l.record->c_r) : known ? json(1.0) : json(nullptr);
  j["wheelbase"] = ok ? opt(l.record->wheelbase) : json(nullptr);
  j["wheel_diameter"] = ok ? opt(l.record->wheel_diameter) : json(nullptr);
  j["e_s"] = ok ? opt(l.record->e_s) : json(nullptr);
  // Skid steer (record version 3): only when stored, so that two-wheel output is unchanged.
  if (ok && l.record->x_icr) {
    j["x_icr"] = *l.record->x_icr;
    j["sigma_x_icr"] = l.record->sigma_x_icr;
  }
  j["provenance"] = ok ? provenance_json(*l.record) : json(nullptr);
  json slots = json::array();
  for (const auto& s : l.slots)
    slots.push_back({{"valid", s.valid},
                     {"blank", s.blank},
                     {"sequence", s.valid ? json(s.sequence) : json(nullptr)},
                     {"problem", s.problem.empty() ? json(nullptr) : json(s.problem)}});
  j["slots"] = slots;
  j["detail"] = l.describe();
  return j.dump();
}

std::string show_text(const LoadResult& l) {
  std::ostringstream o;
  o << "status: " << calib::status_name(l.status) << "\n";
  if (l.status == StoreStatus::kOk) {
    const CalibrationRecord& r = *l.record;
    char line[160];
    o << "sequence: " << r.sequence << " (slot " << (l.slot == 0 ? 'A' : 'B') << ")\n";
    std::snprintf(line, sizeof line, "c_l: %.6f\nc_r: %.6f\n", r.c_l, r.c_r);
    o << line;
    if (r.wheelbase) {
      std::snprintf(line, sizeof line, "wheelbase: %.6f m (%.2f mm)\n", *r.wheelbase,
                    *r.wheelbase * 1e3);
      o << line;
    } else {
      o << "wheelbase: not stored (nominal from the config)\n";
    }
    if (r.wheel_diameter) {
      std::snprintf(line, sizeof line, "wheel_diameter: %.6f m (%.3f mm)\n", *r.wheel_diameter,
                    *r.wheel_diameter * 1e3);
      o << line;
    } else {
      o << "wheel_diameter: not stored (nominal from the config)\n";
    }
    if (r.e_s) o << "e_s: " << *r.e_s << "\n";
    if (r.x_icr) {
      std::snprintf(line, sizeof line, "x_icr: %.6f m (%.2f mm, sigma %.2f mm)\n", *r.x_icr,
                    *r.x_icr * 1e3, r.sigma_x_icr * 1e3);
      o << line;
    }
    o << "obtained: " << calib::utc_text(r.time) << " by " << (r.method.empty() ? "?" : r.method);
    if (r.runs > 0) o << " from " << r.runs << " runs";
    o << "\n";
    if (r.e_max_before || r.e_max_after) {
      o << "E_max,syst:";
      if (r.e_max_before) o << " before " << *r.e_max_before * 1e3 << " mm";
      if (r.e_max_after) o << " after " << *r.e_max_after * 1e3 << " mm";
      o << "\n";
    }
  } else if (l.status == StoreStatus::kUncalibrated) {
    o << "the firmware runs on nominal values (c_l = c_r = 1, config geometry)\n";
    if (l.record) o << "sequence: " << l.record->sequence << " (reset marker)\n";
  } else {
    o << "no slot holds a valid record; the firmware will NOT use these values\n";
  }
  o << "detail: " << l.describe() << "\n";
  return o.str();
}

std::string export_json(const CalibrationRecord& r) {
  json j{{"format", "diffodom-calibration"},
         {"format_version", calib::kRecordVersion},
         {"sequence", r.sequence},
         {"c_l", r.c_l},
         {"c_r", r.c_r},
         {"wheelbase", opt(r.wheelbase)},
         {"wheel_diameter", opt(r.wheel_diameter)},
         {"e_s", opt(r.e_s)},
         {"provenance", provenance_json(r)}};
  if (r.x_icr) {  // only when stored: two-wheel exports are unchanged
    j["x_icr"] = *r.x_icr;
    j["sigma_x_icr"] = r.sigma_x_icr;
  }
  return j.dump(2);
}

Result<CalibrationRecord> parse_calibration_json(std::string_view text, std::string_view source,
                                                 std::time_t now) {
  json j = json::parse(text, nullptr, false);
  if (j.is_discarded()) return bad(source, "not valid JSON");
  if (!j.is_object()) return bad(source, "expected a JSON object");
  if (auto st = j.find("status"); st != j.end() && *st != "ok")
    return bad(source, "the object describes a store with status " + st->dump() +
                           ", not a calibration (need status \"ok\")");
  if (auto f = j.find("format"); f != j.end() && *f != "diffodom-calibration")
    return bad(source, "field format: expected \"diffodom-calibration\", found " + f->dump());

  FieldReader top{j, source, {}};
  CalibrationRecord r;
  const auto c_l = top.number("c_l");
  const auto c_r = top.number("c_r");
  if (top.error.empty() && (!c_l || !c_r)) {
    std::ostringstream m;
    m << "field " << (c_l ? "c_r" : "c_l") << " is missing (expected a number in ["
      << calib::RecordLimits::kFactorMin << ", " << calib::RecordLimits::kFactorMax << "])";
    return bad(source, m.str());
  }
  r.c_l = c_l.value_or(1.0);
  r.c_r = c_r.value_or(1.0);
  // Exchange format: "wheelbase"; UMBmark output: "b_new" (Eq. 6.28).
  r.wheelbase = top.number("wheelbase");
  if (!r.wheelbase) r.wheelbase = top.number("b_new");
  r.wheel_diameter = top.number("wheel_diameter");
  if (!r.wheel_diameter) r.wheel_diameter = top.number("wheel_diameter_new");
  r.e_s = top.number("e_s");
  r.x_icr = top.number("x_icr");  // skid steer (record version 3); absent: none
  if (r.x_icr) r.sigma_x_icr = top.number("sigma_x_icr").value_or(0.0);

  const json* pj = &j;
  if (auto p = j.find("provenance"); p != j.end() && !p->is_null()) {
    if (!p->is_object()) return bad(source, "field provenance: expected an object");
    pj = &*p;
  }
  FieldReader prov{*pj, source, {}};
  r.e_max_before = prov.number("e_max_syst_before");
  if (!r.e_max_before) r.e_max_before = prov.number("e_max_syst");
  r.e_max_after = prov.number("e_max_syst_after");
  auto runs = prov.integer("runs");
  if (!runs) {
    const auto n_cw = prov.integer("n_cw");
    const auto n_ccw = prov.integer("n_ccw");
    if (n_cw || n_ccw) runs = n_cw.value_or(0) + n_ccw.value_or(0);
  }
  if (runs && (*runs < 0 || *runs > calib::RecordLimits::kRunsMax))
    return bad(source, "field runs = " + std::to_string(*runs) + " is outside [0, " +
                           std::to_string(calib::RecordLimits::kRunsMax) + "]");
  r.runs = static_cast<std::uint32_t>(runs.value_or(0));
  r.time = prov.integer("time").value_or(static_cast<std::int64_t>(now));
  r.method = prov.text("method").value_or(j.contains("b_new") ? "umbmark" : "import");
  for (const std::string* e : {&top.error, &prov.error})
    if (!e->empty()) return make_error(Errc::kInvalidArgument, *e);
  if (auto s = calib::validate_record(r); !s) return bad(source, s.error().message);
  return r;
}

}  // namespace odo::analysis
