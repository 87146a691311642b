// The CLI11 front shared by odometryd and odomctl: the parse (help and version exit 0, any other
// parse error prints "<prog>: <what>" on stderr and gives exit 2), the help layout in the
// project's words (HelpFormatter) and the checks that say a range or a set of spellings once.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "odo/hal/choice.hpp"

namespace odo::fw {

// HelpFormatter: CLI11's help with the parser kept out of it: a value is named by its type alone
// (FLOAT, INT, UINT, TEXT, FILE; not "FLOAT:FLOAT in [0 - 1e+09]" nor "ENUM:value in {...}"), a
// range or a set of spellings is said by the description (with_range, choice_check), and a
// default is shown once, as "(default X)" at the end of the description: the value captured
// from the variable when the description does not already say it.
class HelpFormatter : public CLI::Formatter {
 public:
  // make_option_opts: " TYPE[ REQUIRED][ Needs: ...][ Excludes: ...]" after the option's name.
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (!opt->get_option_text().empty()) return " " + opt->get_option_text();
    std::string out;
    if (opt->get_type_size() != 0) {
      const std::string full = opt->get_type_name();
      std::string type = full.substr(0, full.find(':'));
      // CLI::ExistingFile's own word is the better type name of a path that must exist.
      if (full.find(":FILE") != std::string::npos) type = "FILE";
      if (type == "ENUM") type = "TEXT";  // a choice is typed as its spelling
      if (!type.empty()) out += " " + type;
      if (opt->get_expected_max() == CLI::detail::expected_max_vector_size) out += " ...";
      if (opt->get_required()) out += " REQUIRED";
    }
    if (!opt->get_needs().empty()) {
      out += " Needs:";
      for (const CLI::Option* n : opt->get_needs()) out += " " + n->get_name();
    }
    if (!opt->get_excludes().empty()) {
      out += " Excludes:";
      for (const CLI::Option* e : opt->get_excludes()) out += " " + e->get_name();
    }
    return out;
  }
  // make_option_desc: the description, then "(default X)" when a default was captured and the
  // description does not give it already.
  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string d = opt->get_description();
    const std::string def = opt->get_default_str();
    if (!def.empty() && d.find("(default ") == std::string::npos) d += " (default " + def + ")";
    return d;
  }
};

// use_help_formatter: `app` and every subcommand below it print their help with HelpFormatter.
inline void use_help_formatter(CLI::App& app) {
  static const auto fmt = std::make_shared<HelpFormatter>();
  app.formatter(fmt);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    use_help_formatter(*sub);
}

// number_text: v as %g prints it, with the digits needed to give it back (1e-4, 0.01, 1e+09).
inline std::string number_text(double v) {
  char b[32];
  for (int p = 6; p <= 17; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, v);
    if (std::strtod(b, nullptr) == v) break;
  }
  return b;
}

// range_text: "[lo, hi]" as the help and the refusals write a range.
inline std::string range_text(double lo, double hi) {
  return "[" + number_text(lo) + ", " + number_text(hi) + "]";
}

// say_range: `opt`'s description ends with ", range [lo, hi]" (the unit, if any, is the
// description's): for a range another layer checks (the calibration record's limits).
inline CLI::Option* say_range(CLI::Option* opt, double lo, double hi) {
  return opt->description(opt->get_description() + ", range " + range_text(lo, hi));
}

// with_range: say_range, and the option itself refuses a value outside, with the same range:
// "--duration: -1 is outside [0, 1e+09]".
inline CLI::Option* with_range(CLI::Option* opt, double lo, double hi) {
  const std::string range = range_text(lo, hi);
  say_range(opt, lo, hi);
  return opt->check(CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return "'" + text + "' is not a number";
        if (!(v >= lo && v <= hi)) return text + " is outside " + range;
        return {};
      },
      ""));
}

// choice_check: a check that the value is one of `table`'s spellings (a hal Choice table), which
// it turns into the enum's number when `to_number` (an enum-typed option); refused with the
// spellings: "--side-wall: 'middle' must be left or right". The description lists them itself.
template <class Table>
CLI::Validator choice_check(const Table& table, bool to_number) {
  return CLI::Validator(
      [table, to_number](std::string& text) -> std::string {
        for (const auto& c : table) {
          if (c.name != text) continue;
          if (to_number) text = std::to_string(static_cast<long long>(c.value));
          return {};
        }
        return "'" + text + "' must be " + choice_join(table, " or ");
      },
      "");
}

// subcommand_error: when the deepest command given needs a subcommand and got none, says so on
// stderr with the word that is not one ("odomctl: 'bogus' is not a subcommand") and the valid
// ones (CLI11 itself says only "A subcommand is required"); false for any other error.
inline bool subcommand_error(CLI::App& app, const char* prog) {
  CLI::App* at = &app;
  std::string path = prog;
  for (auto given = at->get_subcommands(); !given.empty(); given = at->get_subcommands()) {
    at = given.front();
    path += " " + at->get_name();
  }
  if (at->get_require_subcommand_min() == 0 || !at->get_subcommands().empty()) return false;
  std::string names;
  for (const CLI::App* s : at->get_subcommands([](CLI::App*) { return true; }))
    names += (names.empty() ? "" : ", ") + s->get_name();
  const std::vector<std::string> rest = at->remaining();
  if (rest.empty())
    std::cerr << path << ": a subcommand is needed: " << names << "\n";
  else
    std::cerr << path << ": '" << rest.front() << "' is not "
              << (rest.front().starts_with('-') ? "an option here" : "a subcommand")
              << "; the subcommands are: " << names << "\n";
  return true;
}

// parse_command_line: nullopt to go on, else the process exit code.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv,
                                             const char* prog) {
  use_help_formatter(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (subcommand_error(app, prog)) return 2;
    std::cerr << prog << ": " << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

}  // namespace odo::fw
