// odomctl errormodel: validate (Monte Carlo on the simulated robot) and fit (k_L, k_R from runs).
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "odo/analysis/error_model_tools.hpp"
#include "odo/hal/field_range.hpp"

namespace odo::ctl {
namespace {

nlohmann::json nested(const Cov3& c) {
  return nlohmann::json::array({{c[0], c[1], c[2]}, {c[3], c[4], c[5]}, {c[6], c[7], c[8]}});
}

void print_table(std::ostream& out, const Cov3& predicted, const Cov3& sample) {
  static const char* names[3] = {"x", "y", "theta"};
  out << "entry          predicted        sample           predicted/sample\n";
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      const double p = predicted[3 * i + j], s = sample[3 * i + j];
      std::string name = std::string("cov(") + names[i] + "," + names[j] + ")";
      out << std::left << std::setw(15) << name << std::right << std::scientific
          << std::setprecision(6) << std::setw(14) << p << "   " << std::setw(14) << s << "   ";
      out << std::defaultfloat << std::setprecision(4) << (s != 0.0 ? p / s : 0.0) << "\n";
    }
  }
  out << "units: m^2, m^2, m rad; rad^2 (SI)\n";
}

namespace {

struct ValidateOpts {
  analysis::McOptions mc;
  std::string path = "outback";  // --path as typed; parsed into mc.path before run_validate
  std::string plot, csv;
  bool json = false;
  bool twist = false;  // --twist: the ROS 2 twist covariance instead of the pose's
};

// run_validate_twist: `validate --twist`: the twist covariance the ROS 2 output publishes against
// a Monte Carlo of one tick (analysis::run_twist_monte_carlo); sets exit_code.
void run_validate_twist(const ValidateOpts& o, int& exit_code) {
  auto r = analysis::run_twist_monte_carlo(o.mc);
  if (!r) {
    std::cerr << "odomctl errormodel validate: " << r.error().message << "\n";
    exit_code = r.error().code == Errc::kInvalidArgument ? kExitBadInput : kExitFailed;
    return;
  }
  const auto& p = r->predicted;
  const auto& s = r->sample;
  if (o.json) {
    nlohmann::json j{{"runs", r->runs},
                     {"twist", true},
                     {"speed", o.mc.speed},
                     {"wheelbase", o.mc.wheelbase},
                     {"k_left", o.mc.k.k_left},
                     {"k_right", o.mc.k.k_right},
                     {"seed", o.mc.seed},
                     {"predicted", {{p[0], p[1]}, {p[2], p[3]}}},
                     {"sample", {{s[0], s[1]}, {s[2], s[3]}}},
                     {"mean", r->mean},
                     {"rel_error_diag", r->rel_error},
                     {"max_rel_error_diag", r->max_rel_error_diag}};
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "twist over one tick, " << r->runs << " runs, circle of 2 m radius at "
              << o.mc.speed << " m/s\n"
              << "entry          predicted        sample           predicted/sample\n";
    const char* names[3] = {"var(v)", "cov(v,omega)", "var(omega)"};
    for (int i : {0, 1, 3}) {
      std::cout << std::left << std::setw(15) << names[i == 3 ? 2 : i] << std::right
                << std::scientific << std::setprecision(6) << std::setw(14) << p[i] << "   "
                << std::setw(14) << s[i] << "   " << std::defaultfloat << std::setprecision(4)
                << (s[i] != 0.0 ? p[i] / s[i] : 0.0) << "\n";
    }
    std::cout << "units: (m/s)^2, m rad/s^2, (rad/s)^2 (SI)\n"
              << "max |pred - sample| / sample over the variances: " << r->max_rel_error_diag
              << "\n";
  }
  exit_code = kExitOk;
}

// write_validate_files: --plot and --csv of a pose Monte Carlo; false (said) when one failed.
bool write_validate_files(const ValidateOpts& o, const analysis::McResult& r) {
  if (!o.plot.empty()) {
    std::ostringstream title;
    title << "Chong-Kleeman error model, " << r.runs
          << " runs: " << analysis::path_description(o.mc.path) << "; k_L = " << o.mc.k.k_left
          << ", k_R = " << o.mc.k.k_right << " m^(1/2), b = " << o.mc.wheelbase << " m";
    if (!write_output_file(
            o.plot,
            analysis::error_ellipse_svg(r.errors, r.predicted, r.sample, r.mean, title.str()),
            "errormodel validate"))
      return false;
  }
  if (o.csv.empty()) return true;
  std::ostringstream text;
  analysis::write_run_errors(text, r.errors);
  return write_output_file(o.csv, text.str(), "errormodel validate");
}

// print_validate: the predicted and sample covariances on stdout (a table, or --json).
void print_validate(const ValidateOpts& o, const analysis::McResult& r) {
  if (o.json) {
    nlohmann::json j{{"runs", r.runs},
                     {"path", std::string(analysis::name_of(o.mc.path))},
                     {"wheelbase", o.mc.wheelbase},
                     {"k_left", o.mc.k.k_left},
                     {"k_right", o.mc.k.k_right},
                     {"seed", o.mc.seed},
                     {"predicted", nested(r.predicted)},
                     {"sample", nested(r.sample)},
                     {"mean", r.mean},
                     {"rel_error_diag", r.rel_error},
                     {"max_rel_error_diag", r.max_rel_error_diag}};
    std::cout << j.dump() << "\n";
    return;
  }
  print_table(std::cout, r.predicted, r.sample);
  std::cout << "mean error          " << r.mean[0] << " m, " << r.mean[1] << " m, " << r.mean[2]
            << " rad\n"
            << "max |pred - sample| / sample over the variances: " << r.max_rel_error_diag << "\n";
}

// run_validate: `odomctl ... validate` once its options are parsed; sets exit_code.
void run_validate(const ValidateOpts& o, int& exit_code) {
  if (auto s = analysis::check_mc_options(o.mc); !s) {
    std::cerr << "odomctl errormodel validate: " << s.error().message << "\n";
    exit_code = kExitBadInput;
    return;
  }
  // A path that cannot be written is reported before the Monte Carlo, not after it.
  if (!output_paths_ok({o.plot, o.csv}, "errormodel validate")) {
    exit_code = kExitBadInput;
    return;
  }
  if (o.twist) return run_validate_twist(o, exit_code);
  std::cerr << "errormodel validate: " << o.mc.runs << " runs, "
            << analysis::path_description(o.mc.path) << ", k_L " << o.mc.k.k_left << ", k_R "
            << o.mc.k.k_right << " m^(1/2), b " << o.mc.wheelbase << " m, seed " << o.mc.seed
            << "\n";
  ProgressLine progress("runs");
  auto r = analysis::run_error_monte_carlo(
      o.mc, [&progress](int done, int total) { progress.update(done, total); });
  progress.finish();
  if (!r) {
    std::cerr << "odomctl errormodel validate: " << r.error().message << "\n";
    exit_code = kExitFailed;
    return;
  }
  std::cerr << "errormodel validate: " << r->runs << " runs driven\n";
  if (!write_validate_files(o, *r)) {
    exit_code = kExitFailed;
    return;
  }
  print_validate(o, *r);
  exit_code = kExitOk;
}

}  // namespace

void add_validate(CLI::App& parent, int& exit_code) {
  auto o = std::make_shared<ValidateOpts>();
  CLI::App* c = parent.add_subcommand(
      "validate", "Monte Carlo on the simulated robot: predicted against sample covariance");
  c->add_option("--runs", o->mc.runs, "number of runs")->capture_default_str();
  c->add_option("--path", o->path, "outback (10 m forward, 10 m back) or arc (270 deg, 2 m radius)")
      ->capture_default_str();
  c->add_option("--k-left", o->mc.k.k_left, "k_L [m^(1/2)]")->capture_default_str();
  c->add_option("--k-right", o->mc.k.k_right, "k_R [m^(1/2)]")->capture_default_str();
  c->add_option("--wheelbase", o->mc.wheelbase, "wheelbase b [m]")->capture_default_str();
  c->add_option("--seed", o->mc.seed, "random seed")->capture_default_str();
  c->add_option("--plot", o->plot, "write an SVG of the 95% error ellipses");
  c->add_option("--csv", o->csv, "write every run's error in the CSV format of `fit`");
  c->add_flag("--json", o->json, "print one JSON object on stdout");
  c->add_flag("--twist", o->twist,
              "the twist covariance of the ROS 2 output (one tick on a 2 m circle) instead");
  c->callback([o, &exit_code] {
    const auto path = analysis::parse_mc_path(o->path);
    if (take_choice(path, o->mc.path, "errormodel validate", exit_code))
      run_validate(*o, exit_code);
  });
}

namespace {

struct FitOpts {
  std::string file;
  double distance = 10.0, wheelbase = 0.34;
  bool json = false;
};

// run_fit: `odomctl ... fit` once its options are parsed; sets exit_code.
void run_fit(const FitOpts& o, int& exit_code) {
  auto bad = [&](const std::string& m) {
    std::cerr << "odomctl errormodel fit: " << m << "\n";
    exit_code = kExitBadInput;
  };
  if (!(o.distance >= 0.1 && o.distance <= 10000.0)) {
    return bad(range_message({"--distance", o.distance, 0.1, 10000.0, "m"}));
  }
  if (!(o.wheelbase >= 0.05 && o.wheelbase <= 5.0)) {
    return bad(range_message({"--wheelbase", o.wheelbase, 0.05, 5.0, "m"}));
  }
  std::ifstream in(o.file, std::ios::binary);
  if (!in) return bad(o.file + ": cannot open");
  auto errors = analysis::read_run_errors(in, o.file);
  if (!errors) return bad(errors.error().message);
  auto r = analysis::fit_error_model(*errors, o.distance, o.wheelbase);
  if (!r) return bad(o.file + ": " + r.error().message);
  if (o.json) {
    nlohmann::json j{{"runs", r->runs},
                     {"distance", o.distance},
                     {"wheelbase", o.wheelbase},
                     {"k_left", r->k.k_left},
                     {"k_right", r->k.k_right},
                     {"predicted", nested(r->predicted)},
                     {"sample", nested(r->sample)},
                     {"mean", r->mean}};
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "runs      " << r->runs << "\n"
              << "k_left    " << r->k.k_left << " m^(1/2)\n"
              << "k_right   " << r->k.k_right << " m^(1/2)\n"
              << "mean error (systematic, removed before the fit) " << r->mean[0] << " m, "
              << r->mean[1] << " m, " << r->mean[2] << " rad\n";
    print_table(std::cout, r->predicted, r->sample);
    std::cout << "[error_model] for odometryd.toml:\nk_left = " << r->k.k_left
              << "\nk_right = " << r->k.k_right << "\n";
  }
  exit_code = kExitOk;
}

}  // namespace

void add_fit(CLI::App& parent, int& exit_code) {
  auto o = std::make_shared<FitOpts>();
  CLI::App* c = parent.add_subcommand(
      "fit", "estimate k_L and k_R from the return errors of repeated out-and-back runs");
  c->add_option("FILE", o->file, "CSV with header ex,ey,etheta (optional column run)")->required();
  c->add_option("--distance", o->distance, "distance driven each way [m]")->capture_default_str();
  c->add_option("--wheelbase", o->wheelbase, "wheelbase b [m]")->capture_default_str();
  c->add_flag("--json", o->json, "print one JSON object on stdout");
  c->callback([o, &exit_code] { run_fit(*o, exit_code); });
}

}  // namespace

void add_errormodel(CLI::App& app, int& exit_code) {
  CLI::App* c = app.add_subcommand("errormodel", "the Chong-Kleeman odometry error model");
  c->require_subcommand(1);
  add_validate(*c, exit_code);
  add_fit(*c, exit_code);
}

}  // namespace odo::ctl
