// The kinematics options shared by the log commands (replay, calib fit-fixes): written once so
// that both take the same names, defaults and checks.
#include "commands.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/config.hpp"

namespace odo::ctl {

void add_kinematics_options(CLI::App& c, KinematicsOpts& k, const KinematicsHelp& help) {
  CLI::Option* config = c.add_option(
      "--config", k.config,
      "odometryd's config file: its [robot] (with the calibration store it names), "
      "[error_model] and [gyro], as odometryd runs them; instead of the geometry options");
  // Without --config the geometry is required: checked in make_kinematics, since CLI11's
  // required() cannot depend on another option.
  CLI::Option* geometry[] = {
      c.add_option("--wheel-diameter", k.wheel_diameter, "nominal wheel diameter Dn [m]"),
      c.add_option("--counts-per-rev", k.counts_per_rev,
                   "encoder counts per motor revolution after quadrature (Ce)"),
      c.add_option("--gear-ratio", k.gear_ratio, "motor revolutions per wheel revolution (n)"),
      c.add_option("--wheelbase", k.wheelbase, help.wheelbase),
      c.add_option("--cl", k.cl, help.cl),
      c.add_option("--cr", k.cr, help.cr)};
  for (CLI::Option* o : geometry) o->excludes(config);
  c.add_option("--counter-bits", k.bits, "counter width in bits, 16..64 (default 64)");
}

namespace {

// config_run: what odometryd runs with under `path`, from one read of the file: [robot] with the
// stored calibration applied (a missing or blank store: the nominal values, as odometryd), and
// the fusion's [gyro] with [error_model].
Result<LogRun> config_run(const std::string& path) {
  auto cfg = fw::load_config(path);
  if (!cfg) return std::move(cfg).error();
  const fw::AppliedCalibration a =
      fw::read_and_apply(cfg->robot, cfg->calibration.store, cfg->calibration.backend);
  auto k = Kinematics::create(a.params);
  if (!k) return std::move(k).error();
  GyrodometryParams p = fw::gyrodometry_params(*cfg);
  p.odometry_noise = cfg->error_model;
  return LogRun{*k, p};
}

// options_kinematics: the kinematics of the geometry options.
Result<Kinematics> options_kinematics(const KinematicsOpts& k) {
  for (auto [name, v] : {std::pair{"--wheel-diameter", k.wheel_diameter},
                         {"--counts-per-rev", k.counts_per_rev},
                         {"--wheelbase", k.wheelbase}})
    if (v == 0.0)
      return make_error(Errc::kInvalidArgument,
                        std::string(name) + " is required (or --config FILE: odometryd's config)");
  KinematicParams p;
  p.wheel_diameter = k.wheel_diameter;
  p.counts_per_rev = k.counts_per_rev;
  p.gear_ratio = k.gear_ratio;
  // The log was recorded with this wheelbase: nominal and effective are the same number here.
  p.wheelbase_nominal = p.wheelbase = k.wheelbase;
  p.c_l = k.cl;
  p.c_r = k.cr;
  return Kinematics::create(p);
}

}  // namespace

Result<LogRun> log_run(const KinematicsOpts& k) {
  if (!k.config.empty()) return config_run(k.config);
  auto kin = options_kinematics(k);
  if (!kin) return std::move(kin).error();
  return LogRun{*kin, GyrodometryParams{}};
}

Result<Kinematics> make_kinematics(const KinematicsOpts& k) {
  auto r = log_run(k);
  if (!r) return std::move(r).error();
  return r->kinematics;
}

}  // namespace odo::ctl
