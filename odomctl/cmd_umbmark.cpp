// odomctl umbmark: compute (measured return errors), scale (E_s), simulate (self-calibration).
#include <cmath>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/scaling.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "umbmark_shared.hpp"

namespace odo::ctl {
namespace {

using nlohmann::json;

json opt(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

// print_spread: sigma, SEM and the 3 x SEM verdict of the input runs, beside their E_max,syst
// (Borenstein & Feng Sec. 6.3: the rule compares a set's E_max,syst with that set's SEM).
void print_spread(std::ostream& out, double e_max, const calib::SetSpread& sp) {
  out << std::setprecision(2);
  if (!sp.sigma) {
    out << "spread sigma         unknown (fewer than 3 runs)\n"
        << "pass on these runs   worthwhile (no spread to judge by)\n";
    return;
  }
  out << "spread sigma         " << *sp.sigma * 1e3 << " mm, SEM " << sp.sem * 1e3
      << " mm, 3 x SEM " << 3 * sp.sem * 1e3 << " mm\n"
      << "pass on these runs   "
      << (sp.worthwhile ? "worthwhile (E_max,syst " : "not worthwhile (E_max,syst ") << e_max * 1e3
      << (sp.worthwhile ? " mm > 3 x SEM " : " mm <= 3 x SEM ") << 3 * sp.sem * 1e3
      << (sp.worthwhile ? " mm)\n" : " mm: within the noise)\n");
}

}  // namespace

nlohmann::json compute_json(const calib::UmbmarkResult& r) {
  json j{{"method", "umbmark"},
         {"n_cw", r.cw.n},
         {"n_ccw", r.ccw.n},
         {"x_cg_cw", r.cw.x},
         {"y_cg_cw", r.cw.y},
         {"x_cg_ccw", r.ccw.x},
         {"y_cg_ccw", r.ccw.y},
         {"r_cg_cw", r.cw.r},
         {"r_cg_ccw", r.ccw.r},
         {"e_max_syst", r.e_max_syst},
         {"alpha", r.ab.alpha},
         {"alpha_x", r.ab.alpha_x},
         {"alpha_y", r.ab.alpha_y},
         {"beta", r.ab.beta},
         {"beta_x", r.ab.beta_x},
         {"beta_y", r.ab.beta_y},
         {"radius", opt(r.radius)},
         {"e_d", r.e_d},
         {"e_b", r.e_b},
         {"b_new", r.composed.wheelbase},
         {"c_l_pass", r.pass.c_l},
         {"c_r_pass", r.pass.c_r},
         {"c_l", r.composed.c_l},
         {"c_r", r.composed.c_r},
         {"sigma", opt(r.spread.sigma)},
         {"sem", r.spread.sem},
         {"pass_worthwhile", r.spread.worthwhile}};
  if (r.eps_theta_nonsys) j["eps_theta_nonsys"] = *r.eps_theta_nonsys;
  return j;
}

void print_compute(std::ostream& out, const calib::UmbmarkResult& r, double wheelbase) {
  out << std::fixed << std::setprecision(2) << "UMBmark (Borenstein & Feng 1994)\n"
      << "runs                 cw " << r.cw.n << ", ccw " << r.ccw.n << "\n"
      << "centre of gravity cw  x " << r.cw.x * 1e3 << " mm, y " << r.cw.y * 1e3 << " mm, r_cg "
      << r.cw.r * 1e3 << " mm\n"
      << "centre of gravity ccw x " << r.ccw.x * 1e3 << " mm, y " << r.ccw.y * 1e3 << " mm, r_cg "
      << r.ccw.r * 1e3 << " mm\n"
      << "E_max,syst           " << r.e_max_syst * 1e3 << " mm\n";
  print_spread(out, r.e_max_syst, r.spread);
  out << std::setprecision(4) << "alpha (Type A)       " << r.ab.alpha * kDegPerRad
      << " deg per corner (x: " << r.ab.alpha_x * kDegPerRad << ", y: " << r.ab.alpha_y * kDegPerRad
      << ")\n"
      << "beta (Type B)        " << r.ab.beta * kDegPerRad
      << " deg per leg (x: " << r.ab.beta_x * kDegPerRad << ", y: " << r.ab.beta_y * kDegPerRad
      << ")\n";
  if (r.radius) {
    out << std::setprecision(1) << "R                    " << *r.radius << " m\n";
  } else {
    out << "R                    infinite (beta = 0)\n";
  }
  out << std::setprecision(6) << "E_d = D_R/D_L        " << r.e_d << "\n"
      << "E_b                  " << r.e_b << "\n"
      << "this pass            c_l " << r.pass.c_l << ", c_r " << r.pass.c_r << "\n"
      << std::setprecision(2) << "wheelbase            " << wheelbase * 1e3 << " mm -> b_new "
      << r.composed.wheelbase * 1e3 << " mm\n"
      << std::setprecision(6) << "use from now on      c_l " << r.composed.c_l << ", c_r "
      << r.composed.c_r << ", wheelbase " << r.composed.wheelbase << " m\n";
  out << "next                 drive the squares again with these factors and compute on those\n"
      << "                     runs: their E_max,syst against their 3 x SEM decides another pass\n";
  if (r.eps_theta_nonsys) {
    out << std::setprecision(3) << "eps_theta,nonsys     " << *r.eps_theta_nonsys * kDegPerRad
        << " deg (extended UMBmark)\n";
  }
}

namespace {

namespace {

struct ComputeOpts {
  std::string file;
  double side = 0.0, wheelbase = 0.0, cl = 1.0, cr = 1.0;
  bool json = false;
};

// run_compute: `odomctl ... compute` once its options are parsed; sets exit_code.
void run_compute(const ComputeOpts& o, int& exit_code) {
  auto bad = [&](const std::string& m) {
    std::cerr << "odomctl umbmark compute: " << m << "\n";
    exit_code = kExitBadInput;
  };
  std::ifstream in(o.file, std::ios::binary);
  if (!in) return bad(o.file + ": cannot open");
  auto runs = analysis::read_umbmark_runs(in, o.file);
  if (!runs) return bad(runs.error().message);
  calib::UmbmarkInput ui;
  ui.runs = std::move(runs).value();
  ui.side = o.side;
  ui.current = {o.cl, o.cr, o.wheelbase};
  auto r = calib::umbmark_compute(ui);
  if (!r) {
    // Option values are named as options; run values by the file.
    std::string m = r.error().message;
    for (auto [from, to] : {std::pair{"side", "--side"},
                            {"wheelbase", "--wheelbase"},
                            {"current c_l", "--current-cl"},
                            {"current c_r", "--current-cr"}}) {
      if (m.rfind(std::string(from) + " = ", 0) == 0) m = to + m.substr(std::string(from).size());
    }
    if (m.rfind("--", 0) != 0) m = o.file + ": " + m;
    return bad(m);
  }
  for (const std::string& w : r->warnings)
    std::cerr << "odomctl umbmark compute: warning: " << w << "\n";
  if (o.json) {
    std::cout << compute_json(*r).dump() << "\n";
  } else {
    print_compute(std::cout, *r, o.wheelbase);
  }
  exit_code = kExitOk;
}

}  // namespace

void add_compute(CLI::App& parent, int& exit_code) {
  auto o = std::make_shared<ComputeOpts>();
  CLI::App* c = parent.add_subcommand(
      "compute", "correction factors from measured return errors of cw and ccw squares");
  c->add_option("--runs", o->file, "CSV: direction,ex,ey[,etheta][,bumps] (m, rad)")->required();
  c->add_option("--side", o->side, "side L of the square [m]")->required();
  c->add_option("--wheelbase", o->wheelbase, "wheelbase the robot used during the runs [m]")
      ->required();
  c->add_option("--current-cl", o->cl, "c_l the robot used during the runs")->capture_default_str();
  c->add_option("--current-cr", o->cr, "c_r the robot used during the runs")->capture_default_str();
  c->add_flag("--json", o->json, "print one JSON object on stdout");
  c->callback([o, &exit_code] { run_compute(*o, exit_code); });
}

namespace {

struct ScaleOpts {
  double calculated = 0.0, measured = 0.0, diameter = 0.0;
  bool json = false;
};

// run_scale: `odomctl ... scale` once its options are parsed; sets exit_code.
void run_scale(const ScaleOpts& o, int& exit_code) {
  auto r = calib::scaling_error(o.calculated, o.measured, o.diameter);
  if (!r) {
    std::cerr << "odomctl umbmark scale: " << r.error().message << "\n";
    exit_code = kExitBadInput;
    return;
  }
  if (o.json) {
    std::cout << json{{"l_calc", o.calculated},
                      {"l_actual", o.measured},
                      {"e_s", r->e_s},
                      {"wheel_diameter_nominal", o.diameter},
                      {"wheel_diameter", r->wheel_diameter_new}}
                     .dump()
              << "\n";
  } else {
    std::cout << std::setprecision(6) << "E_s = L_calc / L_actual   " << r->e_s << "\n"
              << std::fixed << std::setprecision(3) << "Dn                        "
              << o.diameter * 1e3 << " mm\nDn* (corrected)           "
              << r->wheel_diameter_new * 1e3 << " mm\n"
              << "apply: odomctl calib set --wheel-diameter " << std::setprecision(6)
              << r->wheel_diameter_new << " (metres)\n";
  }
  exit_code = kExitOk;
}

}  // namespace

void add_scale(CLI::App& parent, int& exit_code) {
  auto o = std::make_shared<ScaleOpts>();
  CLI::App* c = parent.add_subcommand(
      "scale", "scaling error E_s and corrected wheel diameter Dn* from a straight run (App. B)");
  c->add_option("--calculated", o->calculated, "length the odometry computed [m]")->required();
  c->add_option("--measured", o->measured, "length measured with a tape [m]")->required();
  c->add_option("--diameter", o->diameter, "nominal wheel diameter Dn used in the run [m]")
      ->required();
  c->add_flag("--json", o->json, "print one JSON object on stdout");
  c->callback([o, &exit_code] { run_scale(*o, exit_code); });
}

}  // namespace

bool save_factors(const std::string& path, calib::CalibrationRecord rec, const char* cmd) {
  auto s = fw::open_calibration_store(path, NvBackend::kAuto);
  if (!s) {
    std::cerr << "odomctl " << cmd << ": " << s.error().message << "\n";
    return false;
  }
  rec.time = static_cast<std::int64_t>(std::time(nullptr));
  auto seq = s->store->save(rec);
  if (!seq) {
    // The store's messages already start with the path.
    std::cerr << "odomctl " << cmd << ": " << seq.error().message << "\n";
    return false;
  }
  std::cerr << cmd << ": stored sequence " << *seq << " in " << path << " (" << s->backend << ")\n";
  return true;
}

namespace {

namespace {

// sim_record: the final factors of a simulation as a record (method umbmark-sim).
calib::CalibrationRecord sim_record(const analysis::UmbmarkSimResult& r) {
  const analysis::UmbmarkSimPass& last = r.passes.back();
  calib::CalibrationRecord rec;
  rec.c_l = last.result.composed.c_l;
  rec.c_r = last.result.composed.c_r;
  rec.wheelbase = last.result.composed.wheelbase;
  rec.method = "umbmark-sim";
  rec.e_max_before = r.passes.front().before.e_max_syst;
  rec.e_max_after = last.after.e_max_syst;
  rec.runs = static_cast<std::uint32_t>(last.before.runs.size());
  return rec;
}

struct SimulateOpts {
  analysis::UmbmarkSimOptions sim;
  std::string robot = "labmate", noise = "none";  // as typed; parsed into sim before run_simulate
  std::string store, plot, csv, eb_form = "umbmark", gyro = "none";  // choices as typed
  bool json = false;
};

// skid_json / print_skid: the --robot skid4 effective tracks (README "Skid-steer bases").
json skid_json(const analysis::SkidTrackReport& k) {
  json arcs = json::array();
  for (const analysis::SkidArcTrack& a : k.arcs)
    arcs.push_back(json{{"com_x", a.com_x},
                        {"radius", a.radius},
                        {"true_radius", a.true_radius},
                        {"track", a.track}});
  return json{{"geometric_track", k.geometric},
              {"guessed_track", k.guessed},
              {"found_track", k.found},
              {"spot_turn_track", k.spot_turn},
              {"arcs", arcs},
              {"unconverged", k.unconverged}};
}

void print_skid(const analysis::SkidTrackReport& k) {
  const double dev = 100.0 * (k.found - k.spot_turn) / k.spot_turn;
  std::cout << std::setprecision(1) << "effective track [mm]: geometric " << k.geometric * 1e3
            << ", guess x" << analysis::kSkidTrackMultiplier << " " << k.guessed * 1e3
            << ", UMBmark found " << k.found * 1e3 << ", friction model in the spot turns "
            << k.spot_turn * 1e3 << std::setprecision(2) << " (found " << std::showpos << dev
            << std::noshowpos << " %)\n"
            << "friction model on steady arcs at 0.2 m/s (radius 0: spot turn) [mm]:\n"
            << std::setw(10) << "com_x" << std::setw(10) << "radius" << std::setw(13)
            << "true radius" << std::setw(9) << "track\n";
  for (const analysis::SkidArcTrack& a : k.arcs) {
    std::cout << std::setprecision(1) << std::setw(10) << a.com_x * 1e3 << std::setw(10)
              << a.radius * 1e3 << std::setw(13) << a.true_radius * 1e3 << std::setw(8)
              << a.track * 1e3 << "\n";
  }
  if (k.unconverged > 0) std::cout << "unconverged friction solves: " << k.unconverged << "\n";
}

// gyro_comparison_json / print_gyro_comparison: the --gyro figures (README "Gyro").
json gyro_comparison_json(const analysis::UmbmarkGyroComparison& g) {
  return json{{"eps_theta_nonsys_plain", opt(g.eps_plain)},
              {"eps_theta_nonsys_fused", opt(g.eps_fused)},
              {"uncal_plain_bumps", g.uncal_plain_bumps},
              {"cal_fused_bumps", g.cal_fused_bumps},
              {"cal_plain_smooth", g.cal_plain_smooth},
              {"cal_fused_smooth", g.cal_fused_smooth},
              {"events", g.events}};
}

void print_gyro_comparison(const analysis::UmbmarkGyroComparison& g, const std::string& cls) {
  std::cout << std::setprecision(3) << "gyro (" << cls
            << ", exact reference): eps_theta,nonsys plain "
            << g.eps_plain.value_or(0.0) * kDegPerRad << " deg, fused "
            << g.eps_fused.value_or(0.0) * kDegPerRad << " deg\n"
            << "  mean return error, bumps: uncalibrated plain " << g.uncal_plain_bumps * 1e3
            << " mm, calibrated fused " << g.cal_fused_bumps * 1e3 << " mm\n"
            << "  mean return error, smooth, calibrated: plain " << g.cal_plain_smooth * 1e3
            << " mm, fused " << g.cal_fused_smooth * 1e3 << " mm\n";
}

// simulate_options_ok: the options, the formula and every output path, before any square.
bool simulate_options_ok(SimulateOpts& o) {
  auto formula =
      parse_choice_of<calib::WheelbaseFormula>(calib::kWheelbaseFormulas, "--eb-form", o.eb_form);
  if (!formula) {
    std::cerr << "odomctl umbmark simulate: " << formula.error().message << "\n";
    return false;
  }
  o.sim.formula = *formula;
  if (auto s = analysis::check_umbmark_sim_options(o.sim); !s) {
    std::cerr << "odomctl umbmark simulate: " << s.error().message << "\n";
    return false;
  }
  return output_paths_ok({o.store, o.plot, o.csv}, "umbmark simulate");
}

// simulate_outputs: --store, --plot and --csv once the simulation is done.
bool simulate_outputs(const SimulateOpts& o, const analysis::UmbmarkSimResult& r) {
  if (!o.store.empty() && !save_factors(o.store, sim_record(r), "umbmark simulate")) return false;
  if (!o.plot.empty()) {
    std::ostringstream title;
    title << "UMBmark on the simulated " << o.sim.robot << ": " << o.sim.runs
          << " cw + ccw squares of " << o.sim.side << " m, noise " << o.sim.noise << ", seed "
          << o.sim.seed;
    if (!write_output_file(o.plot, analysis::umbmark_svg(r, title.str()), "umbmark simulate"))
      return false;
  }
  if (!o.csv.empty()) {
    // The runs the first pass computed from, as `umbmark record` writes them.
    std::vector<calib::UmbmarkRun> runs = r.passes.front().before.runs;
    runs.insert(runs.end(), r.bump_runs.begin(), r.bump_runs.end());
    if (!write_output_file(o.csv, analysis::format_umbmark_runs(runs), "umbmark simulate"))
      return false;
  }
  return true;
}

void print_simulate_json(const analysis::UmbmarkSimResult& r) {
  json passes = json::array();
  for (const analysis::UmbmarkSimPass& p : r.passes) {
    // Each set's figures carry its name; the verdict is the after set's (another pass?).
    json jp{{"e_max_syst_before", p.before.e_max_syst},
            {"sigma_before", opt(p.before.spread.sigma)},
            {"sem_before", p.before.spread.sem},
            {"c_l", p.result.composed.c_l},
            {"c_r", p.result.composed.c_r},
            {"b", p.result.composed.wheelbase},
            {"alpha", p.result.ab.alpha},
            {"beta", p.result.ab.beta},
            {"e_max_syst_after", p.after.e_max_syst},
            {"sigma_after", opt(p.after.spread.sigma)},
            {"sem_after", p.after.spread.sem},
            {"another_pass_recommended", p.after.spread.worthwhile}};
    if (p.result.eps_theta_nonsys) jp["eps_theta_nonsys"] = *p.result.eps_theta_nonsys;
    passes.push_back(jp);
  }
  json out{{"passes", passes}, {"improvement", r.improvement}};
  if (r.gyro) out["gyro"] = gyro_comparison_json(*r.gyro);
  if (r.skid) out["skid"] = skid_json(*r.skid);
  std::cout << out.dump() << "\n";
}

// spread_cells: a set's E_max,syst, sigma and 3 x SEM [mm] as three table cells ("-": no sigma).
void spread_cells(std::ostream& out, const analysis::UmbmarkRunSet& set) {
  out << std::setprecision(2) << std::setw(12) << set.e_max_syst * 1e3;
  if (set.spread.sigma) {
    out << std::setw(8) << *set.spread.sigma * 1e3 << std::setw(8) << 3 * set.spread.sem * 1e3;
  } else {
    out << std::setw(8) << "-" << std::setw(8) << "-";
  }
}

void print_simulate_text(const analysis::UmbmarkSimResult& r, const std::string& gyro_class) {
  // Each set's statistics sit beside its own E_max,syst; "another pass?" is the after set's
  // 3 x SEM verdict (Borenstein & Feng Sec. 6.3), which is also the next pass's input.
  std::cout << std::right << std::setw(32) << "before (input set) [mm]" << std::setw(32)
            << "factors found from it" << std::setw(30) << "after (verification) [mm]"
            << "\n"
            << "pass" << std::setw(12) << "E_max,syst" << std::setw(8) << "sigma" << std::setw(8)
            << "3xSEM" << std::setw(11) << "c_l" << std::setw(11) << "c_r" << std::setw(10)
            << "b [mm]" << std::setw(14) << "E_max,syst" << std::setw(8) << "sigma" << std::setw(8)
            << "3xSEM"
            << "  another pass?\n";
  int i = 1;
  for (const analysis::UmbmarkSimPass& p : r.passes) {
    const calib::UmbmarkResult& u = p.result;
    std::cout << std::fixed << std::setw(4) << i++;
    spread_cells(std::cout, p.before);
    std::cout << "  " << std::setprecision(6) << std::setw(9) << u.composed.c_l << std::setw(11)
              << u.composed.c_r << std::setprecision(3) << std::setw(10)
              << u.composed.wheelbase * 1e3 << "  ";
    spread_cells(std::cout, p.after);
    std::cout << "  " << (p.after.spread.worthwhile ? "yes" : "no") << "\n";
  }
  std::cout << std::setprecision(1) << "improvement (first before / last after): " << r.improvement
            << "-fold\nanother pass?: the after set's E_max,syst > its own 3 x SEM "
               "(Borenstein & Feng, Sec. 6.3)\n";
  if (const auto& e = r.passes.front().result.eps_theta_nonsys) {
    std::cout << std::setprecision(3) << "eps_theta,nonsys (extended UMBmark): " << *e * kDegPerRad
              << " deg\n";
  }
  if (r.gyro) print_gyro_comparison(*r.gyro, gyro_class);
  if (r.skid) print_skid(*r.skid);
}

// run_simulate: `odomctl ... simulate` once its options are parsed; sets exit_code.
void run_simulate(SimulateOpts o, int& exit_code) {  // a copy: sets o.sim.formula
  if (!simulate_options_ok(o)) {
    exit_code = kExitBadInput;
    return;
  }
  std::cerr << "umbmark simulate: " << o.sim.robot << ", " << o.sim.runs << " cw + ccw squares of "
            << o.sim.side << " m per set, " << o.sim.passes << " pass(es), noise " << o.sim.noise
            << (o.sim.bumps ? ", bumps" : "") << ", seed " << o.sim.seed << "\n";
  ProgressLine progress("squares");
  int driven = 0;
  auto r = analysis::run_umbmark_simulation(o.sim, [&](int done, int total) {
    driven = done;
    progress.update(done, total);
  });
  progress.finish();
  if (!r) {
    std::cerr << "odomctl umbmark simulate: " << r.error().message << "\n";
    exit_code = kExitFailed;
    return;
  }
  std::cerr << "umbmark simulate: " << driven << " squares driven\n";
  for (const std::string& w : r->passes.front().result.warnings)
    std::cerr << "odomctl umbmark simulate: warning: " << w << "\n";
  if (!simulate_outputs(o, *r)) {
    exit_code = kExitFailed;
    return;
  }
  if (o.json) {
    print_simulate_json(*r);
  } else {
    print_simulate_text(*r, o.gyro);
  }
  exit_code = kExitOk;
}

}  // namespace

void add_simulate(CLI::App& parent, int& exit_code) {
  auto o = std::make_shared<SimulateOpts>();
  CLI::App* c = parent.add_subcommand(
      "simulate", "automated UMBmark self-calibration of the simulated robot (virtual time)");
  c->add_option("--robot", o->robot,
                "simulated robot: labmate (the UMBmark report's LabMate) or skid4 (a "
                "Jackal-sized 4WD skid-steer base)")
      ->capture_default_str();
  c->add_option("--runs", o->sim.runs, "squares a direction per set")->capture_default_str();
  c->add_option("--passes", o->sim.passes, "calibration passes")->capture_default_str();
  c->add_option("--side", o->sim.side, "side of the square [m]")->capture_default_str();
  c->add_option("--noise", o->noise, "none | paper (floor roughness, reference error)")
      ->capture_default_str();
  c->add_flag("--bumps", o->sim.bumps, "add extended-UMBmark runs (ten 10 mm bumps)");
  c->add_option("--seed", o->sim.seed, "random seed")->capture_default_str();
  c->add_option("--gyro", o->gyro,
                "none | consumer | industrial: also compare odometry with the gyro fused")
      ->capture_default_str();
  c->add_option("--store", o->store, "write the final factors to this calibration store");
  c->add_option("--plot", o->plot, "write an SVG of the return errors before and after");
  c->add_option("--csv", o->csv, "write the first pass's runs (the CSV `record` writes)");
  c->add_option("--eb-form", o->eb_form,
                "wheelbase formula: umbmark (Eq. 6.29) or chong (C&K Eq. 9)")
      ->capture_default_str();
  c->add_flag("--json", o->json, "print one JSON object on stdout");
  c->callback([o, &exit_code] {
    const char* cmd = "umbmark simulate";
    if (take_choice(analysis::parse_umbmark_robot(o->robot), o->sim.robot, cmd, exit_code) &&
        take_choice(analysis::parse_umbmark_noise(o->noise), o->sim.noise, cmd, exit_code) &&
        take_choice(
            parse_choice_of<analysis::UmbmarkGyro>(analysis::kUmbmarkGyros, "--gyro", o->gyro),
            o->sim.gyro, cmd, exit_code))
      run_simulate(*o, exit_code);
  });
}

}  // namespace

void add_umbmark(CLI::App& app, int& exit_code) {
  CLI::App* c = app.add_subcommand("umbmark", "UMBmark calibration (Borenstein & Feng)");
  c->require_subcommand(1);
  add_compute(*c, exit_code);
  add_scale(*c, exit_code);
  add_simulate(*c, exit_code);
  add_record(*c, exit_code);
}

}  // namespace odo::ctl
