// odomctl calib show|set|import|export|reset: the calibration store on a file, an EEPROM
// (nvmem file) or a raw flash partition (MTD).
#include <ctime>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/firmware/calibration_store.hpp"

namespace odo::ctl {
namespace {

struct StoreOpts {
  std::string path = fw::kDefaultCalibrationStore;
  std::string backend = "auto";
  bool json = false;
};

void add_store_options(CLI::App* c, StoreOpts& o, bool json) {
  c->add_option("--store", o.path, "store: a file, an nvmem file or /dev/mtdN")
      ->capture_default_str();
  c->add_option("--backend", o.backend, "auto | file | nvmem | mtd (auto: from the path)")
      ->check(fw::choice_check(fw::choices<NvBackend>(), false))
      ->capture_default_str();
  if (json) c->add_flag("--json", o.json, "print one JSON object");
}

// Opens the store and loads it; on failure prints why and sets exit_code.
std::optional<fw::OpenStore> open_loaded(const char* cmd, const StoreOpts& o,
                                         calib::LoadResult& loaded, int& exit_code) {
  // --backend is one of the spellings (fw::choice_check above).
  const auto backend = fw::parse_choice<NvBackend>(o.backend).value_or(NvBackend::kAuto);
  auto s = fw::open_calibration_store(o.path, backend);
  if (!s) {
    std::cerr << "odomctl calib " << cmd << ": " << s.error().message << "\n";
    exit_code = kExitFailed;
    return std::nullopt;
  }
  auto l = s->store->load();
  if (!l) {
    std::cerr << "odomctl calib " << cmd << ": " << o.path << ": " << l.error().message << "\n";
    exit_code = kExitFailed;
    return std::nullopt;
  }
  loaded = std::move(l).value();
  return std::move(s).value();
}

// Writes `r` (or a reset marker) and reports the result the same way `show` does.
void write_and_report(const char* cmd, const StoreOpts& o, fw::OpenStore& s,
                      const std::optional<calib::CalibrationRecord>& r, int& exit_code) {
  auto seq = r ? s.store->save(*r) : s.store->clear();
  if (!seq) {
    std::cerr << "odomctl calib " << cmd << ": " << o.path << ": " << seq.error().message << "\n";
    exit_code = seq.error().code == Errc::kInvalidArgument ? kExitBadInput : kExitFailed;
    return;
  }
  auto l = s.store->load();
  if (!l) {
    std::cerr << "odomctl calib " << cmd << ": " << o.path << ": read-back: " << l.error().message
              << "\n";
    exit_code = kExitFailed;
    return;
  }
  if (o.json) {
    std::cout << analysis::show_json(*l) << "\n";
  } else {
    std::cout << "odomctl calib " << cmd << ": wrote sequence " << *seq << " to " << o.path << " ("
              << s.backend << ")\n"
              << analysis::show_text(*l);
  }
  exit_code = kExitOk;
}

struct SetOpts {
  StoreOpts store;
  std::optional<double> cl, cr, wheelbase, wheel_diameter;
};

struct ImportOpts {
  StoreOpts store;
  std::string file;
};

// store_note: for a file store that does not exist, why (fw::store_absence): it is uncalibrated
// because nothing was ever written there, or because its directory is missing (a typo?).
std::optional<fw::StoreAbsence> store_note(const StoreOpts& o) {
  return fw::store_absence(o.path,
                           fw::parse_choice<NvBackend>(o.backend).value_or(NvBackend::kAuto));
}

// calib_show: `calib show`: the record and the store status (exit 1 when corrupt).
void calib_show(const StoreOpts& o, int& exit_code) {
  const auto absent = store_note(o);
  calib::LoadResult l;
  if (!open_loaded("show", o, l, exit_code)) return;
  if (o.json && absent) {
    auto j = nlohmann::json::parse(analysis::show_json(l));
    j["note"] = absent->text;
    std::cout << j.dump() << "\n";
  } else {
    std::cout << (o.json ? analysis::show_json(l) + "\n" : analysis::show_text(l));
    if (absent) std::cout << "note: " << absent->text << "\n";
  }
  exit_code = l.status == calib::StoreStatus::kCorrupt ? kExitFailed : kExitOk;
  if (absent && absent->directory_missing) {
    std::cerr << "odomctl calib show: " << absent->text << "\n";
    exit_code = kExitFailed;
  }
}

// calib_set: `calib set`: changes the given values, keeps the rest.
void calib_set(const SetOpts& o, int& exit_code) {
  if (!o.cl && !o.cr && !o.wheelbase && !o.wheel_diameter) {
    std::cerr << "odomctl calib set: give at least one of --cl, --cr, --wheelbase, "
                 "--wheel-diameter\n";
    exit_code = kExitBadInput;
    return;
  }
  calib::LoadResult l;
  auto s = open_loaded("set", o.store, l, exit_code);
  if (!s) return;
  if (l.status == calib::StoreStatus::kCorrupt) {
    std::cerr << "odomctl calib set: " << o.store.path << ": store corrupt (" << l.describe()
              << "); there are no stored values to keep: use `odomctl calib import` or "
                 "`odomctl calib reset`\n";
    exit_code = kExitFailed;
    return;
  }
  calib::CalibrationRecord r;
  if (l.status == calib::StoreStatus::kOk) r = *l.record;
  if (o.cl) r.c_l = *o.cl;
  if (o.cr) r.c_r = *o.cr;
  if (o.wheelbase) r.wheelbase = *o.wheelbase;
  if (o.wheel_diameter) r.wheel_diameter = *o.wheel_diameter;
  r.method = "set";
  r.time = static_cast<std::int64_t>(std::time(nullptr));
  if (auto v = calib::validate_record(r); !v) {
    std::cerr << "odomctl calib set: " << v.error().message << "; store left unchanged\n";
    exit_code = kExitBadInput;
    return;
  }
  write_and_report("set", o.store, *s, r, exit_code);
}

// calib_import: `calib import`: a record from JSON (file or stdin).
void calib_import(const ImportOpts& o, int& exit_code) {
  std::string text;
  if (o.file == "-") {
    text.assign(std::istreambuf_iterator<char>(std::cin), {});
  } else {
    std::ifstream in(o.file, std::ios::binary);
    if (!in) {
      std::cerr << "odomctl calib import: " << o.file << ": cannot open\n";
      exit_code = kExitBadInput;
      return;
    }
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto r = analysis::parse_calibration_json(text, o.file == "-" ? "<stdin>" : o.file,
                                            std::time(nullptr));
  if (!r) {
    std::cerr << "odomctl calib import: " << r.error().message << "; store left unchanged\n";
    exit_code = kExitBadInput;
    return;
  }
  calib::LoadResult l;
  auto s = open_loaded("import", o.store, l, exit_code);
  if (!s) return;
  write_and_report("import", o.store, *s, *r, exit_code);
}

// calib_export: `calib export`: the stored record in the exchange format.
void calib_export(const StoreOpts& o, int& exit_code) {
  if (const auto absent = store_note(o)) {
    std::cerr << "odomctl calib export: " << absent->text << "; nothing to export\n";
    exit_code = kExitFailed;
    return;
  }
  calib::LoadResult l;
  if (!open_loaded("export", o, l, exit_code)) return;
  if (l.status != calib::StoreStatus::kOk) {
    std::cerr << "odomctl calib export: " << o.path << ": " << l.describe()
              << "; nothing to export\n";
    exit_code = kExitFailed;
    return;
  }
  std::cout << analysis::export_json(*l.record) << "\n";
  exit_code = kExitOk;
}

// calib_reset: `calib reset`: marks the store uncalibrated.
void calib_reset(const StoreOpts& o, int& exit_code) {
  calib::LoadResult l;
  auto s = open_loaded("reset", o, l, exit_code);
  if (!s) return;
  write_and_report("reset", o, *s, std::nullopt, exit_code);
}
// history_order: the valid records, newest first.
std::vector<const calib::CalibrationRecord*> history_order(const calib::LoadResult& l) {
  std::vector<const calib::CalibrationRecord*> v;
  for (const auto& r : l.records)
    if (r) v.push_back(&*r);
  if (v.size() == 2 && v[1]->sequence > v[0]->sequence) std::swap(v[0], v[1]);
  if (v.size() == 2 && v[1]->sequence == v[0]->sequence) v.pop_back();  // the first save: twice
  return v;
}

nlohmann::json history_json(const calib::CalibrationRecord& r) {
  nlohmann::json j{{"sequence", r.sequence},
                   {"cleared", r.cleared},
                   {"method", r.method},
                   {"time", r.time},
                   {"time_utc", calib::utc_text(r.time)},
                   {"c_l", r.c_l},
                   {"c_r", r.c_r},
                   {"wheelbase", r.wheelbase ? nlohmann::json(*r.wheelbase) : nullptr}};
  if (r.fit)
    j["fit"] = {{"fixes_used", r.fit->fixes_used}, {"fixes_rejected", r.fit->fixes_rejected},
                {"residual", r.fit->residual},     {"sigma_c_l", r.fit->sigma_c_l},
                {"sigma_c_r", r.fit->sigma_c_r},   {"sigma_wheelbase", r.fit->sigma_wheelbase}};
  if (r.x_icr) {
    j["x_icr"] = *r.x_icr;
    j["sigma_x_icr"] = r.sigma_x_icr;
  }
  return j;
}

std::string history_line(const calib::CalibrationRecord& r, bool newest) {
  std::ostringstream o;
  o << (newest ? "in use    " : "previous  ") << "sequence " << r.sequence << "  "
    << calib::utc_text(r.time) << "  " << (r.cleared ? "reset" : r.method);
  if (!r.cleared) {
    o << "  c_l " << r.c_l << "  c_r " << r.c_r;
    if (r.wheelbase) o << "  b " << *r.wheelbase << " m";
  }
  if (r.fit)
    o << "  (" << r.fit->fixes_used << " fixes, " << r.fit->fixes_rejected
      << " rejected, held-out chi2/dof " << r.fit->residual << ")";
  return o.str() + "\n";
}

// calib_history: `calib history`: the records the store holds (A/B: the newest and the one
// before it) with their provenance.
void calib_history(const StoreOpts& o, int& exit_code) {
  calib::LoadResult l;
  if (!open_loaded("history", o, l, exit_code)) return;
  const auto v = history_order(l);
  if (o.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto* r : v) j.push_back(history_json(*r));
    std::cout << j.dump() << "\n";
  } else if (v.empty()) {
    std::cout << o.path << ": " << l.describe() << "; no records\n";
  } else {
    for (std::size_t i = 0; i < v.size(); ++i) std::cout << history_line(*v[i], i == 0);
  }
  exit_code = l.status == calib::StoreStatus::kCorrupt ? kExitFailed : kExitOk;
}

// calib_rollback: `calib rollback`: the previous record becomes the newest again, written
// through the store like any save (a power cut leaves the old newest or the restored one).
void calib_rollback(const StoreOpts& o, int& exit_code) {
  calib::LoadResult l;
  auto s = open_loaded("rollback", o, l, exit_code);
  if (!s) return;
  const auto v = history_order(l);
  if (v.size() < 2) {
    std::cerr << "odomctl calib rollback: " << o.path << ": " << l.describe()
              << "; no previous record to restore\n";
    exit_code = kExitFailed;
    return;
  }
  std::optional<calib::CalibrationRecord> prev;
  if (!v[1]->cleared) prev = *v[1];
  write_and_report("rollback", o, *s, prev, exit_code);
}

}  // namespace

void add_calib(CLI::App& app, int& exit_code) {
  CLI::App* calib = app.add_subcommand("calib", "show or change the stored calibration");
  calib->require_subcommand(1);

  auto show = std::make_shared<StoreOpts>();
  CLI::App* c_show = calib->add_subcommand("show", "print the stored calibration and its status");
  add_store_options(c_show, *show, true);
  c_show->callback([show, &exit_code] { calib_show(*show, exit_code); });

  auto set = std::make_shared<SetOpts>();
  CLI::App* c_set = calib->add_subcommand("set", "change stored values (the rest are kept)");
  add_store_options(c_set, set->store, true);
  // The ranges are the record's (calib::RecordLimits), checked when the record is written.
  using L = calib::RecordLimits;
  fw::say_range(c_set->add_option("--cl", set->cl, "left wheel correction factor c_L"),
                L::kFactorMin, L::kFactorMax);
  fw::say_range(c_set->add_option("--cr", set->cr, "right wheel correction factor c_R"),
                L::kFactorMin, L::kFactorMax);
  fw::say_range(c_set->add_option("--wheelbase", set->wheelbase, "effective wheelbase b [m]"),
                L::kWheelbaseMin, L::kWheelbaseMax);
  fw::say_range(c_set->add_option("--wheel-diameter", set->wheel_diameter,
                                  "corrected wheel diameter Dn* [m]"),
                L::kDiameterMin, L::kDiameterMax);
  c_set->callback([set, &exit_code] { calib_set(*set, exit_code); });

  auto imp = std::make_shared<ImportOpts>();
  CLI::App* c_imp = calib->add_subcommand(
      "import", "store a calibration from JSON (`umbmark compute --json`, `calib export`)");
  add_store_options(c_imp, imp->store, true);
  c_imp->add_option("file", imp->file, "JSON file, - for stdin")->required();
  c_imp->callback([imp, &exit_code] { calib_import(*imp, exit_code); });

  auto exp = std::make_shared<StoreOpts>();
  CLI::App* c_exp =
      calib->add_subcommand("export", "print the stored calibration as JSON (for `import`)");
  add_store_options(c_exp, *exp, false);  // its output is JSON: no --json to accept and ignore
  c_exp->callback([exp, &exit_code] { calib_export(*exp, exit_code); });

  auto reset = std::make_shared<StoreOpts>();
  CLI::App* c_reset = calib->add_subcommand(
      "reset", "mark the store uncalibrated (the firmware then runs on nominal values)");
  add_store_options(c_reset, *reset, true);
  c_reset->callback([reset, &exit_code] { calib_reset(*reset, exit_code); });

  auto hist = std::make_shared<StoreOpts>();
  CLI::App* c_hist = calib->add_subcommand(
      "history", "list the stored records (newest and previous) with their provenance");
  add_store_options(c_hist, *hist, true);
  c_hist->callback([hist, &exit_code] { calib_history(*hist, exit_code); });

  auto rb = std::make_shared<StoreOpts>();
  CLI::App* c_rb = calib->add_subcommand("rollback", "restore the previous record");
  add_store_options(c_rb, *rb, true);
  c_rb->callback([rb, &exit_code] { calib_rollback(*rb, exit_code); });

  add_calib_fit_fixes(*calib, exit_code);
}

}  // namespace odo::ctl
