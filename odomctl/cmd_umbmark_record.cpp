// odomctl umbmark record: the guided UMBmark session on a real robot. The odometry's poses come
// from the daemon's CAN broadcast (read from the bus, or from a candump -L log being written),
// the person types only what the tape gives; the return errors are computed here and saved
// after every run.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/umbmark_tape.hpp"
#include "odo/firmware/can_listen.hpp"
#include "odo/firmware/config.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/protocol/candump_log.hpp"
#include "umbmark_shared.hpp"

namespace odo::ctl {
namespace {

using calib::Direction;
using calib::UmbmarkRun;

constexpr const char* kCmd = "umbmark record";

struct RecordOpts {
  std::string csv, can, can_log, answers, out, store, config;
  int runs = 5, node = 1;
  std::uint32_t base_id = 0x400;
  double side = 4.0, wheelbase = 0.0, cl = 1.0, cr = 1.0;
  calib::SideWall wall = calib::SideWall::kLeft;
  bool bumps = false;
  bool node_given = false, base_id_given = false;  // on the command line: not from --config
};

// PosePairer: joins a node's PoseX and PoseYTheta frames of the same sequence number into a
// pose [m, m, rad]; every other frame is ignored.
class PosePairer {
 public:
  PosePairer(std::uint32_t base_id, int node) : base_id_(base_id), node_(node) {}

  // take: the pose completed by `f`, if it completes one.
  std::optional<Pose2> take(const CanFrame& f) {
    int n = 0;
    protocol::Msg m{};
    if (!protocol::split_id(base_id_, f, n, m) || n != node_) return std::nullopt;
    std::uint8_t seq = 0;
    double y = 0.0, th = 0.0;
    if (m == protocol::Msg::kPoseX && protocol::decode_pose_x(f, x_, seq)) {
      x_seq_ = seq;
    } else if (m == protocol::Msg::kPoseYTheta && protocol::decode_pose_y_theta(f, y, th, seq) &&
               seq == x_seq_) {
      return Pose2{x_, y, th};
    }
    return std::nullopt;
  }

 private:
  std::uint32_t base_id_;
  int node_;
  double x_ = 0.0;
  int x_seq_ = -1;
};

// PoseFeed: where the daemon's current pose is read from.
class PoseFeed {
 public:
  virtual ~PoseFeed() = default;
  // latest: the daemon's newest pose [m, m, rad], or why there is none.
  virtual Result<Pose2> latest() = 0;
};

// LogPoseFeed: the newest complete pose in a candump -L log that is being written.
class LogPoseFeed final : public PoseFeed {
 public:
  LogPoseFeed(std::string path, std::uint32_t base_id, int node)
      : path_(std::move(path)), base_id_(base_id), node_(node) {}

  Result<Pose2> latest() override {
    std::ifstream in(path_, std::ios::binary);
    if (!in) return make_error(Errc::kIo, path_ + ": cannot open (is candump -L running?)");
    PosePairer pairer(base_id_, node_);
    std::optional<Pose2> pose;
    for (std::string line; std::getline(in, line);) {
      auto l = protocol::parse_candump_line(line);
      if (!l) continue;
      if (auto p = pairer.take(l->frame)) pose = p;
    }
    if (!pose)
      return make_error(Errc::kIo,
                        path_ + ": no pose frames of node " + std::to_string(node_) + " yet");
    return *pose;
  }

 private:
  std::string path_;
  std::uint32_t base_id_;
  int node_;
};

// BusPoseFeed: the next complete pose the daemon broadcasts on a SocketCAN interface.
class BusPoseFeed final : public PoseFeed {
 public:
  static constexpr double kWait = 3.0;  // [s] for a pose pair: pose_hz >= 0.5 is enough

  // open: the listener on `iface` for the node's two pose frames; errors name the interface.
  static Result<std::unique_ptr<PoseFeed>> open(const std::string& iface, std::uint32_t base_id,
                                                int node) {
    const auto id = [&](protocol::Msg m) { return protocol::frame_id(base_id, node, m); };
    auto bus =
        fw::open_can_listener(iface, {id(protocol::Msg::kPoseX), id(protocol::Msg::kPoseYTheta)});
    if (!bus) return std::move(bus).error();
    return std::unique_ptr<PoseFeed>(new BusPoseFeed(iface, std::move(bus).value(), base_id, node));
  }

  Result<Pose2> latest() override {
    // What waits in the socket was queued while the person measured: old, and once the queue
    // is full the kernel drops the newest frames. Empty it, then take the next complete pair.
    CanFrame f{};
    while (bus_->receive(f)) {
    }
    // A fresh pairer: the half pair it held is from before the drain, and the sequence number
    // repeats (8 bits), so an old PoseX could complete a new PoseYTheta into a pose that never was.
    PosePairer pairer(base_id_, node_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(kWait);
    while (std::chrono::steady_clock::now() < deadline) {
      if (!bus_->receive(f)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        continue;
      }
      if (auto p = pairer.take(f)) return *p;
    }
    std::ostringstream m;
    m << iface_ << ": no pose frames of node " << node_ << " within " << kWait
      << " s (is odometryd broadcasting on " << iface_ << "?)";
    return make_error(Errc::kIo, m.str());
  }

 private:
  BusPoseFeed(std::string iface, std::unique_ptr<CanBus> bus, std::uint32_t base_id, int node)
      : iface_(std::move(iface)), bus_(std::move(bus)), base_id_(base_id), node_(node) {}

  std::string iface_;
  std::unique_ptr<CanBus> bus_;
  std::uint32_t base_id_;
  int node_;
};

// Prompter: asks on stdout and reads one line from the terminal or from --answers (then echoed,
// so that a transcript reads like a session). A bad answer is asked again on a terminal and
// is an error naming file:line in an answers file.
class Prompter {
 public:
  Prompter(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}

  // line: the answer to `prompt`, nullopt when the input has ended.
  std::optional<std::string> line(const std::string& prompt) {
    std::cout << prompt << std::flush;
    std::string a;
    if (!std::getline(in_, a)) {
      std::cout << "\n";
      return std::nullopt;
    }
    ++line_;
    if (!source_.empty()) std::cout << a << "\n";
    return a;
  }

  // number: a value in [lo, hi] (unit as typed) times `scale`; empty is nullopt when `optional`.
  // false when the input ended or a scripted answer was bad.
  bool number(const std::string& prompt, double lo, double hi, double scale, bool optional,
              std::optional<double>& out) {
    for (;;) {
      auto a = line(prompt);
      if (!a) return false;
      if (a->empty() && optional) {
        out.reset();
        return true;
      }
      char* end = nullptr;
      const double v = std::strtod(a->c_str(), &end);
      if (!a->empty() && end && *end == '\0' && std::isfinite(v) && v >= lo && v <= hi) {
        out = v * scale;
        return true;
      }
      std::ostringstream m;
      m << "'" << *a << "' is not a number in [" << lo << ", " << hi << "]";
      if (!source_.empty()) {
        std::cerr << "odomctl " << kCmd << ": " << source_ << ":" << line_ << ": " << m.str()
                  << "\n";
        return false;
      }
      std::cout << "  " << m.str() << "; again.\n";
    }
  }

  // scripted: the answers come from --answers, not from a person.
  bool scripted() const { return !source_.empty(); }

 private:
  std::istream& in_;
  std::string source_;  // the answers file, empty on a terminal
  int line_ = 0;
};

// print_diagram: the signs of Eq. 3.1 as the tape gives them, for the chosen side wall.
void print_diagram(calib::SideWall wall) {
  const bool left = wall == calib::SideWall::kLeft;
  std::cout << "Signs (seen from above; start frame: x along the first leg, y to the left):\n"
            << (left ? "      left wall\n  ++=================\n  ||    ^ y\n  ||    |\n" : "")
            << "  ||    o---> x     o: the robot's reference point on the start mark\n"
            << (left ? "" : "  ||    |\n  ||    v -y\n  ++=================\n      right wall\n")
            << "  back wall\n"
            << "  x_abs = back(end) - back(start)      ex = x_abs - x_odometry\n"
            << (left ? "  y_abs = left(start) - left(end)" : "  y_abs = right(end) - right(start)")
            << "      ey = y_abs - y_odometry\n"
            << "  heading: counter-clockwise positive; cw squares turn right, ccw squares left.\n";
}

std::string mm(double v) {
  std::ostringstream s;
  s << std::showpos << std::fixed << std::setprecision(1) << v * 1e3 << " mm";
  return s.str();
}

void print_pose(const char* when, const Pose2& p) {
  std::cout << "  odometry at " << when << ": x " << std::fixed << std::setprecision(4) << p.x
            << " m, y " << p.y << " m, theta " << std::setprecision(3) << p.theta * kDegPerRad
            << " deg\n";
}

// read_pose: asks for Enter, then reads the daemon's pose; on a terminal a missing pose is
// asked for again, in a script it ends the session (the runs so far stay saved).
bool read_pose(Prompter& in, PoseFeed& feed, const std::string& prompt, Pose2& out) {
  for (;;) {
    if (!in.line(prompt)) return false;
    auto p = feed.latest();
    if (p) {
      out = *p;
      return true;
    }
    // A script cannot wait for the daemon: the next answer is not an Enter for this pose.
    if (in.scripted()) {
      std::cerr << "odomctl " << kCmd << ": " << p.error().message << "\n";
      return false;
    }
    std::cout << "  " << p.error().message << "; press Enter to try again.\n";
  }
}

// tape: the two distances [mm on the prompt, m returned] at `when` (start or end).
bool tape(Prompter& in, const RecordOpts& o, const char* when, calib::TapeReading& t) {
  const std::string side = o.wall == calib::SideWall::kLeft ? "left" : "right";
  std::optional<double> back, s;
  if (!in.number(std::string("  tape at ") + when + ": reference point to the back wall [mm]: ",
                 0.0, 1e5, 1e-3, false, back) ||
      !in.number(
          std::string("  tape at ") + when + ": reference point to the " + side + " wall [mm]: ",
          0.0, 1e5, 1e-3, false, s))
    return false;
  t = {*back, *s};
  return true;
}

// record_run: one run of the plan, from the start mark to the computed return error.
bool record_run(Prompter& in, PoseFeed& feed, const RecordOpts& o, Direction d, bool bumps,
                UmbmarkRun& run) {
  const char* dir = d == Direction::kCw ? "cw" : "ccw";
  std::cout << "  Put the robot on the start mark, heading along the first leg"
            << (bumps ? (d == Direction::kCw ? "; ten ~10 mm cables under the right wheel's "
                                               "track on the first leg"
                                             : "; ten ~10 mm cables under the left wheel's "
                                               "track on the first leg")
                      : "")
            << ".\n";
  calib::TapeReading t0, t1;
  Pose2 p0, p1;
  std::optional<double> heading;
  if (!tape(in, o, "start", t0) ||
      !read_pose(in, feed, "  press Enter to read the odometry's start pose: ", p0))
    return false;
  print_pose("start", p0);
  if (!read_pose(
          in, feed,
          std::string("  drive the ") + dir + " square now; press Enter when it has " + "stopped: ",
          p1))
    return false;
  print_pose("end", p1);
  if (!tape(in, o, "end", t1) ||
      !in.number(bumps || o.bumps ? "  heading change [deg, counter-clockwise +]: "
                                  : "  heading change [deg, counter-clockwise +; empty: not "
                                    "measured]: ",
                 -180.0, 180.0, kRadPerDeg, !(bumps || o.bumps), heading))
    return false;
  run = calib::tape_return_error(d, bumps, o.wall, t0, t1, heading, p0, p1);
  std::cout << "  return error (absolute - odometry): ex " << mm(run.ex) << ", ey " << mm(run.ey);
  if (run.etheta) std::cout << ", etheta " << std::showpos << *run.etheta * kDegPerRad << " deg";
  std::cout << std::noshowpos << "\n";
  return true;
}

// print_running: the centres of gravity and the spread of the runs so far.
void print_running(const std::vector<UmbmarkRun>& runs) {
  const calib::CentreOfGravity cw = calib::centre_of_gravity(runs, Direction::kCw);
  const calib::CentreOfGravity ccw = calib::centre_of_gravity(runs, Direction::kCcw);
  for (const auto& [name, g] : {std::pair{"cw ", cw}, std::pair{"ccw", ccw}}) {
    std::cout << "  " << name << " n " << g.n;
    if (g.n > 0)
      std::cout << ", centre of gravity x " << mm(g.x) << ", y " << mm(g.y) << ", r_cg "
                << std::noshowpos << std::fixed << std::setprecision(1) << g.r * 1e3 << " mm";
    std::cout << "\n";
  }
  if (auto s = calib::return_spread(runs, cw, ccw))
    std::cout << "  spread sigma " << std::fixed << std::setprecision(1) << *s * 1e3 << " mm\n";
}

// plan: the runs of the session in order: N cw, N ccw, then with --bumps N cw and N ccw bumpy.
std::vector<std::pair<Direction, bool>> plan(const RecordOpts& o) {
  std::vector<std::pair<Direction, bool>> p;
  for (bool bumps : {false, true}) {
    if (bumps && !o.bumps) break;
    for (Direction d : {Direction::kCw, Direction::kCcw})
      for (int i = 0; i < o.runs; ++i) p.emplace_back(d, bumps);
  }
  return p;
}

// load_runs: the runs saved by an earlier session (resume); an absent file is no run. The
// saved runs must be the plan's first ones.
bool load_runs(const RecordOpts& o, std::vector<UmbmarkRun>& runs) {
  std::ifstream f(o.csv, std::ios::binary);
  if (!f) return true;
  auto r = analysis::read_umbmark_runs(f, o.csv);
  if (!r) {
    std::cerr << "odomctl " << kCmd << ": " << r.error().message << "\n";
    return false;
  }
  runs = std::move(r).value();
  const auto p = plan(o);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (i >= p.size() || runs[i].direction != p[i].first || runs[i].bumps != p[i].second) {
      std::cerr << "odomctl " << kCmd << ": " << o.csv << ": run " << i + 1
                << " does not belong to this session's plan (--runs " << o.runs
                << (o.bumps ? ", --bumps" : "") << ")\n";
      return false;
    }
  }
  return true;
}

// finish: the computation over all runs, --out, and the offer to import into --store.
bool finish(Prompter& in, const RecordOpts& o, const std::vector<UmbmarkRun>& runs) {
  calib::UmbmarkInput ui;
  ui.runs = runs;
  ui.side = o.side;
  ui.current = {o.cl, o.cr, o.wheelbase};
  auto r = calib::umbmark_compute(ui);
  if (!r) {
    std::cerr << "odomctl " << kCmd << ": " << o.csv << ": " << r.error().message << "\n";
    return false;
  }
  for (const std::string& w : r->warnings)
    std::cerr << "odomctl " << kCmd << ": warning: " << w << "\n";
  std::cout << "\n";
  print_compute(std::cout, *r, o.wheelbase);
  const std::string text = compute_json(*r).dump() + "\n";
  if (!o.out.empty() && !write_output_file(o.out, text, kCmd)) return false;
  if (o.store.empty()) {
    std::cout << "to use it: sudo odomctl calib import " << (o.out.empty() ? "FILE" : o.out)
              << " --store /var/lib/odometryd/calibration.bin\n";
    return true;
  }
  auto yes = in.line("import into " + o.store + " now? [y/N] ");
  if (!yes || (*yes != "y" && *yes != "Y")) {
    std::cout << "not imported.\n";
    return true;
  }
  auto rec = analysis::parse_calibration_json(text, o.csv, std::time(nullptr));
  if (!rec) {
    std::cerr << "odomctl " << kCmd << ": " << rec.error().message << "; store left unchanged\n";
    return false;
  }
  return save_factors(o.store, *rec, kCmd);
}

// apply_daemon_config: the daemon's [can] interface, node and base id from --config, where the
// command line does not name them. False (said on stderr) for a config that broadcasts no pose.
bool apply_daemon_config(RecordOpts& o) {
  if (o.config.empty()) return true;
  auto c = fw::load_config(o.config);
  std::string m;
  if (!c) {
    m = c.error().message;
  } else if (c->can.bus != fw::CanBusKind::kSocketCan) {
    m = o.config + ": [can] bus is not \"socketcan\": the daemon broadcasts on no CAN interface";
  } else if (!(c->can.pose_hz > 0.0)) {
    m = o.config + ": [can] pose_hz = 0: the daemon broadcasts no pose";
  }
  if (!m.empty()) {
    std::cerr << "odomctl " << kCmd << ": " << m << "\n";
    return false;
  }
  if (o.can.empty() && o.can_log.empty()) o.can = c->can.interface;
  if (!o.node_given) o.node = c->can.node_id;
  if (!o.base_id_given) o.base_id = static_cast<std::uint32_t>(c->can.base_id);
  return true;
}

// record_options_ok: values and output paths before the first question.
bool record_options_ok(const RecordOpts& o) {
  std::string m;
  if (!(o.wheelbase > 0.0 && o.wheelbase <= 20.0)) {
    m = range_message({"--wheelbase", o.wheelbase, 0.0, 20.0, "m"});
  } else if (o.runs < 1 || o.runs > 1000) {
    m = range_message(integer_range("--runs", o.runs, 1, 1000));
  } else if (!protocol::valid_addressing(o.base_id, o.node)) {
    m = "--base-id / --node: not a valid node block (base id a multiple of 16, node 0..63)";
  } else if (o.can.empty() == o.can_log.empty()) {
    m = "the poses: one of --can IFACE (the bus), --can-log FILE (a candump -L log) or --config "
        "FILE (the daemon's interface) is needed";
  }
  if (!m.empty()) {
    std::cerr << "odomctl " << kCmd << ": " << m << "\n";
    return false;
  }
  return output_paths_ok({o.csv, o.out, o.store}, kCmd);
}

// open_feed: the pose source the options name; an interface that cannot be opened is said
// before the first question.
std::unique_ptr<PoseFeed> open_feed(const RecordOpts& o) {
  if (o.can.empty()) return std::make_unique<LogPoseFeed>(o.can_log, o.base_id, o.node);
  auto f = BusPoseFeed::open(o.can, o.base_id, o.node);
  if (!f) {
    std::cerr << "odomctl " << kCmd << ": --can " << o.can << ": " << f.error().message << "\n";
    return nullptr;
  }
  return std::move(f).value();
}

// run_record: `odomctl umbmark record` once its options are parsed; sets exit_code.
void run_record(RecordOpts o, int& exit_code) {
  exit_code = kExitBadInput;
  std::vector<UmbmarkRun> runs;
  if (!apply_daemon_config(o) || !record_options_ok(o) || !load_runs(o, runs)) return;
  const std::unique_ptr<PoseFeed> feed = open_feed(o);
  if (!feed) return;
  std::ifstream answers;
  if (!o.answers.empty()) {
    answers.open(o.answers, std::ios::binary);
    if (!answers) {
      std::cerr << "odomctl " << kCmd << ": " << o.answers << ": cannot open\n";
      return;
    }
  }
  Prompter in(o.answers.empty() ? std::cin : answers, o.answers);
  const auto p = plan(o);
  std::cout << "UMBmark record: " << p.size() << " runs of a " << o.side << " m square, "
            << runs.size() << " already in " << o.csv << "\n";
  print_diagram(o.wall);
  exit_code = kExitFailed;
  for (std::size_t i = runs.size(); i < p.size(); ++i) {
    std::cout << "\nRun " << i + 1 << " of " << p.size() << ": "
              << (p[i].first == Direction::kCw ? "cw (clockwise, turning right)"
                                               : "ccw (counter-clockwise, turning left)")
              << (p[i].second ? ", with bumps" : "") << "\n";
    UmbmarkRun run;
    if (!record_run(in, *feed, o, p[i].first, p[i].second, run)) {
      std::cerr << "odomctl " << kCmd << ": stopped; " << runs.size() << " runs saved in " << o.csv
                << ": the same command resumes\n";
      return;
    }
    runs.push_back(run);
    if (!write_output_file(o.csv, analysis::format_umbmark_runs(runs), kCmd)) return;
    std::cout << "  saved in " << o.csv << " (" << runs.size() << " of " << p.size() << ")\n";
    print_running(runs);
  }
  if (finish(in, o, runs)) exit_code = kExitOk;
}

}  // namespace

void add_record(CLI::App& umbmark, int& exit_code) {
  auto o = std::make_shared<RecordOpts>();
  CLI::App* c = umbmark.add_subcommand(
      "record", "guided UMBmark runs on a real robot: poses from the daemon, tape from you");
  c->add_option("--csv", o->csv, "the runs CSV, saved after every run (a session resumes)")
      ->required();
  c->add_option("--can", o->can,
                "read the daemon's pose from its broadcast on this SocketCAN interface (can0)");
  c->add_option("--can-log", o->can_log,
                "or from a candump -L log of that broadcast being written "
                "(candump -L can0 >FILE, or odometryd --can-log FILE)");
  c->add_option("--wheelbase", o->wheelbase, "wheelbase the robot uses during the runs [m]")
      ->required();
  c->add_option("--current-cl", o->cl, "c_l the robot uses during the runs (default 1)");
  c->add_option("--current-cr", o->cr, "c_r the robot uses during the runs (default 1)");
  c->add_option("--side", o->side, "side L of the square [m] (default 4)");
  c->add_option("--runs", o->runs, "squares a direction (default 5)");
  c->add_flag("--bumps", o->bumps, "then as many extended-UMBmark runs (heading required)");
  c->add_option("--side-wall", o->wall,
                "the side wall at the start mark: left | right (default left)")
      ->transform(fw::choice_check(calib::kSideWalls, true));
  c->add_option("--config", o->config,
                "the daemon's config: --can, --node and --base-id are taken from its [can] "
                "interface, node_id and base_id unless given");
  CLI::Option* node =
      c->add_option("--node", o->node, "node id of the daemon on the bus (default 1)");
  CLI::Option* base =
      c->add_option("--base-id", o->base_id, "base id of the protocol (default 0x400)");
  c->add_option("--answers", o->answers, "read the answers from FILE (scripts, tests)");
  c->add_option("--out", o->out, "write the result as JSON (what `calib import` reads)");
  c->add_option("--store", o->store, "offer to import the result into this calibration store");
  c->callback([o, node, base, &exit_code] {
    o->node_given = node->count() > 0;
    o->base_id_given = base->count() > 0;
    run_record(*o, exit_code);
  });
}

}  // namespace odo::ctl
