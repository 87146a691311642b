// The kinematics options shared by the log commands (replay, calib fit-fixes): written once so
// that both take the same names, defaults and checks.
#include "commands.hpp"

namespace odo::ctl {

void add_kinematics_options(CLI::App& c, KinematicsOpts& k, const KinematicsHelp& help) {
  c.add_option("--wheel-diameter", k.wheel_diameter, "nominal wheel diameter Dn [m]")->required();
  c.add_option("--counts-per-rev", k.counts_per_rev,
               "encoder counts per motor revolution after quadrature (Ce)")
      ->required();
  c.add_option("--gear-ratio", k.gear_ratio, "motor revolutions per wheel revolution (n)");
  c.add_option("--wheelbase", k.wheelbase, help.wheelbase)->required();
  c.add_option("--cl", k.cl, help.cl);
  c.add_option("--cr", k.cr, help.cr);
  c.add_option("--counter-bits", k.bits, "counter width in bits, 16..64 (default 64)");
}

Result<Kinematics> make_kinematics(const KinematicsOpts& k) {
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

}  // namespace odo::ctl
