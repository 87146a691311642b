// odomctl umbmark record: the guided UMBmark session on a real robot. The odometry's poses come
// from the daemon's CAN broadcast (read from the bus, or from a candump -L log being written),
// the person types only what the tape gives; the return errors are computed here and saved
// after every run.
#include <signal.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/umbmark_tape.hpp"
#include "odo/firmware/calibration_store.hpp"
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
      x_seq_ = -1;  // a second PoseYTheta of this number joins only a PoseX sent after it
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

// interrupted: set by SIGINT (Ctrl-C); the session then ends as at the end of its input.
volatile std::sig_atomic_t interrupted = 0;

extern "C" void on_interrupt(int) {
  interrupted = 1;
}

// catch_interrupt: Ctrl-C interrupts the read of an answer (no SA_RESTART) instead of killing
// the process, so that the session says what Ctrl-D says (runs saved, the same command resumes).
void catch_interrupt() {
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  sigaction(SIGINT, &sa, nullptr);
}

// PoseReading: a pose read at an Enter, and the odometry's path length since the read before
// [m] when the feed saw every pose in between (unknown across a restarted log or a silent bus).
struct PoseReading {
  Pose2 pose;
  std::optional<double> path;
};

// PoseFeed: where the daemon's current pose is read from.
class PoseFeed {
 public:
  virtual ~PoseFeed() = default;
  // latest: the daemon's newest pose [m, m, rad], or why there is none.
  virtual Result<PoseReading> latest() = 0;
};

double wall_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string seconds_text(double s) {
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << s << " s";
  return t.str();
}

// LogPoseFeed: the daemon's pose from a candump -L log that is being written. Each read goes on
// from where the last one ended (a log started again from empty is read from its start); a
// partial last line is left for the next read. A pose counts only when its own time stamp is
// at most kMaxAge before the Enter; the newest Status frame tells a stopped daemon.
class LogPoseFeed final : public PoseFeed {
 public:
  static constexpr double kMaxAge = 0.5;  // [s] a pose older than the Enter by more: stale
  static constexpr double kWait = 3.0;    // [s] for a fresh pose: pose_hz >= 0.5 is enough

  LogPoseFeed(std::string path, std::uint32_t base_id, int node)
      : path_(std::move(path)), base_id_(base_id), node_(node), pairer_(base_id, node) {}

  Result<PoseReading> latest() override {
    const double asked = wall_now();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(kWait);
    for (;;) {
      if (auto st = read_on(); !st) return std::move(st).error();
      if (stopping_) return stopped(asked);
      if (pose_ && pose_stamp_ >= asked - kMaxAge) {
        PoseReading r{*pose_, path_complete_ ? std::optional(path_since_) : std::nullopt};
        path_since_ = 0.0;
        path_complete_ = true;
        return r;
      }
      if (interrupted || std::chrono::steady_clock::now() >= deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return stale(asked);
  }

 private:
  // read_on: the lines added since the last read; a replaced or emptied log is read anew.
  Status read_on() {
    struct stat st {};
    if (::stat(path_.c_str(), &st) != 0)
      return make_error(Errc::kIo, path_ + ": cannot open (is odometryd --can-log " + path_ +
                                       " or candump -L running?)");
    if (st.st_ino != inode_ || static_cast<std::uint64_t>(st.st_size) < offset_) restart(st.st_ino);
    std::ifstream in(path_, std::ios::binary);
    if (!in) return make_error(Errc::kIo, path_ + ": cannot open");
    in.seekg(static_cast<std::streamoff>(offset_));
    for (std::string line; std::getline(in, line);) {
      if (in.eof()) break;  // a partial last line: read again, whole, next time
      offset_ += line.size() + 1;
      take_line(line);
    }
    return Ok{};
  }

  // restart: the log read from its start; a log replaced or emptied after the first read (the
  // daemon started again, a capture rotated) hides the path in between: unknown, not 0.
  void restart(ino_t inode) {
    if (inode_ != 0) path_complete_ = false;
    inode_ = inode;
    offset_ = 0;
    pairer_ = PosePairer(base_id_, node_);
    pose_.reset();
    stopping_ = false;
    status_stamp_ = -1.0;
    path_since_ = 0.0;
  }

  // take_line: one whole line; lines that are not the node's pose or status are skipped.
  void take_line(std::string_view line) {
    auto l = protocol::parse_candump_line(line);
    if (!l) return;
    const double stamp = static_cast<double>(l->sec) + 1e-6 * l->usec;
    int n = 0;
    protocol::Msg m{};
    protocol::StatusMsg status;
    if (protocol::split_id(base_id_, l->frame, n, m) && n == node_ && m == protocol::Msg::kStatus &&
        protocol::decode_status(l->frame, status)) {
      stopping_ = status.stopping;
      status_stamp_ = stamp;
      return;
    }
    if (auto p = pairer_.take(l->frame)) {
      if (pose_) path_since_ += std::hypot(p->x - pose_->x, p->y - pose_->y);
      pose_ = p;
      pose_stamp_ = stamp;
    }
  }

  Error stopped(double asked) const {
    return make_error(Errc::kIo, path_ + ": odometryd has stopped (its last Status frame, " +
                                     seconds_text(asked - status_stamp_) +
                                     " old, says stopping): start it again with --can-log " +
                                     path_);
  }

  Error stale(double asked) const {
    std::string m = path_ + ": ";
    if (!pose_)
      m += "no pose frames of node " + std::to_string(node_) + " within " + seconds_text(kWait);
    else
      m += "the newest pose is " + seconds_text(asked - pose_stamp_) + " old (at most " +
           seconds_text(kMaxAge) + " is taken)";
    if (status_stamp_ >= 0.0)
      m += ", the newest Status frame " + seconds_text(asked - status_stamp_) + " old";
    return make_error(Errc::kIo, m + ": is odometryd running with --can-log " + path_ +
                                     " (or candump -L writing it)? Start it");
  }

  std::string path_;
  std::uint32_t base_id_;
  int node_;
  PosePairer pairer_;
  ino_t inode_ = 0;
  std::uint64_t offset_ = 0;  // bytes of whole lines read
  std::optional<Pose2> pose_;
  double pose_stamp_ = 0.0;     // [s] wall clock of the log
  double status_stamp_ = -1.0;  // [s], < 0: no Status frame yet
  bool stopping_ = false;
  double path_since_ = 0.0;    // [m] odometry path since the last reading
  bool path_complete_ = true;  // every pose since the last reading was read
};

// BusPoseFeed: the daemon's pose broadcast on a SocketCAN interface, read by a thread of its own
// from the start: every pose pair is joined as it arrives, so that a reading has the odometry's
// path since the one before (the no-motion check) and a pose completed after the Enter. The
// socket alone would not do: while a person drives and measures, its queue fills and the kernel
// drops the newest frames.
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

  ~BusPoseFeed() override {
    stop_ = true;
    reader_.join();
  }

  Result<PoseReading> latest() override {
    const auto asked = std::chrono::steady_clock::now();
    const auto deadline = asked + std::chrono::duration<double>(kWait);
    std::unique_lock<std::mutex> l(m_);
    // A pose completed before the Enter may be from before the robot stopped: wait for the next.
    while (!(pose_ && pose_at_ >= asked) && !interrupted) {
      if (std::chrono::steady_clock::now() >= deadline) {
        std::ostringstream m;
        m << iface_ << ": no pose frames of node " << node_ << " within " << kWait
          << " s (is odometryd broadcasting on " << iface_ << "?)";
        return make_error(Errc::kIo, m.str());
      }
      // Bounded wait: Ctrl-C sets `interrupted` without a notify.
      fresh_.wait_for(l, std::chrono::milliseconds(50));
    }
    if (interrupted) return make_error(Errc::kIo, "interrupted");
    PoseReading r{*pose_, path_complete_ ? std::optional(path_since_) : std::nullopt};
    path_since_ = 0.0;
    path_complete_ = true;
    return r;
  }

 private:
  BusPoseFeed(std::string iface, std::unique_ptr<CanBus> bus, std::uint32_t base_id, int node)
      : iface_(std::move(iface)), bus_(std::move(bus)), node_(node), pairer_(base_id, node) {
    reader_ = std::thread([this] { read_bus(); });
  }

  // read_bus: the reader thread: each pose joined as it arrives, until the feed is destroyed.
  void read_bus() {
    CanFrame f{};
    while (!stop_) {
      if (!bus_->receive(f)) {
        // The listener is non-blocking; 2 ms is a tenth of the fastest pose period (50 Hz).
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        continue;
      }
      if (auto p = pairer_.take(f)) take_pose(*p);
    }
  }

  void take_pose(const Pose2& p) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> l(m_);
    if (pose_) {
      // A silence longer than kWait (the daemon stopped, restarted, the link was down) hides
      // the path in between: unknown, not the chord across it.
      if (now - pose_at_ > std::chrono::duration<double>(kWait)) path_complete_ = false;
      path_since_ += std::hypot(p.x - pose_->x, p.y - pose_->y);
    }
    pose_ = p;
    pose_at_ = now;
    fresh_.notify_all();
  }

  std::string iface_;
  std::unique_ptr<CanBus> bus_;  // read by the reader thread only
  int node_;
  PosePairer pairer_;  // the reader thread's
  std::atomic<bool> stop_{false};
  std::mutex m_;  // guards what follows: written by the reader, taken by latest()
  std::condition_variable fresh_;
  std::optional<Pose2> pose_;
  std::chrono::steady_clock::time_point pose_at_{};
  double path_since_ = 0.0;    // [m] odometry path since the last reading
  bool path_complete_ = true;  // no silence since the last reading
  std::thread reader_;         // last: started once everything it uses exists
};

// Prompter: asks on stdout and reads one line from the terminal or from --answers (then echoed,
// so that a transcript reads like a session). A bad answer is asked again on a terminal and
// is an error naming file:line in an answers file (bad() then tells the caller: exit 2).
class Prompter {
 public:
  // Plausibility: why a value [unit as typed] cannot be meant, empty when it can.
  using Plausibility = std::function<std::string(double)>;

  Prompter(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}

  // line: the answer to `prompt`, nullopt when the input has ended (Ctrl-D, Ctrl-C).
  std::optional<std::string> line(const std::string& prompt) {
    std::cout << prompt << std::flush;
    std::string a;
    if (interrupted || !std::getline(in_, a) || interrupted) {
      std::cout << "\n";
      return std::nullopt;
    }
    ++line_;
    if (!source_.empty()) std::cout << a << "\n";
    return a;
  }

  // number: a value in [lo, hi] (unit as typed) that `plausible` accepts, times `scale`; empty
  // is nullopt when `optional`. false when the input ended or a scripted answer was bad.
  bool number(const std::string& prompt, double lo, double hi, double scale, bool optional,
              std::optional<double>& out, const Plausibility& plausible = {}) {
    for (;;) {
      auto a = line(prompt);
      if (!a) return false;
      if (a->empty() && optional) {
        out.reset();
        return true;
      }
      char* end = nullptr;
      const double v = std::strtod(a->c_str(), &end);
      std::string why;
      if (a->empty() || !end || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
        std::ostringstream m;
        m << "'" << *a << "' is not a number in [" << lo << ", " << hi << "]";
        why = m.str();
      } else if (plausible) {
        why = plausible(v);
      }
      if (why.empty()) {
        out = v * scale;
        return true;
      }
      if (!refused(why)) return false;
    }
  }

  // refused: says why the last answer is not taken; true when it is asked again (a terminal),
  // false when the session ends (a script: the error names the answer's file:line).
  bool refused(const std::string& why) {
    if (!source_.empty()) {
      std::cerr << "odomctl " << kCmd << ": " << source_ << ":" << line_ << ": " << why << "\n";
      bad_ = true;
      return false;
    }
    std::cout << "  " << why << "; again.\n";
    return true;
  }

  // scripted: the answers come from --answers, not from a person.
  bool scripted() const { return !source_.empty(); }
  // bad: a scripted answer was refused (bad input, exit 2).
  bool bad() const { return bad_; }

 private:
  std::istream& in_;
  std::string source_;  // the answers file, empty on a terminal
  int line_ = 0;
  bool bad_ = false;
};

// print_diagram: the signs of Eq. 3.1 as the tape gives them, for the chosen side wall.
void print_diagram(calib::SideWall wall) {
  const bool left = wall == calib::SideWall::kLeft;
  std::cout << "Signs (seen from above; start frame: x along the first leg, y to the left):\n"
            // The back wall is the vertical one (||): its label at its open end, away from
            // the side wall's label (below it with a left wall, above it with a right wall).
            << (left ? "      left wall\n  ++=================\n  ||    ^ y\n  ||    |\n"
                     : "  back wall\n")
            << "  ||    o---> x     o: the robot's reference point on the start mark\n"
            << (left ? "  back wall\n"
                     : "  ||    |\n  ||    v -y\n  ++=================\n      right wall\n")
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

// Plausibility bounds of what a person types or the odometry reports (issue 35).
constexpr double kMinTapeMm = 10.0;          // [mm] a reference point closer to a wall: metres?
constexpr double kMaxReturnFraction = 0.25;  // return error over the side: a mistyped reading
constexpr double kMinPathFraction = 0.5;     // odometry path over the square's 4 L: not driven

// read_pose: asks for Enter, then reads the daemon's pose; on a terminal a missing or stale pose
// is asked for again, in a script it ends the session (the runs so far stay saved).
bool read_pose(Prompter& in, PoseFeed& feed, const std::string& prompt, PoseReading& out) {
  for (;;) {
    if (!in.line(prompt)) return false;
    auto p = feed.latest();
    if (p) {
      out = *p;
      return true;
    }
    if (interrupted) return false;
    // A script cannot wait for the daemon: the next answer is not an Enter for this pose.
    if (in.scripted()) {
      std::cerr << "odomctl " << kCmd << ": " << p.error().message << "\n";
      return false;
    }
    std::cout << "  " << p.error().message << "; press Enter to try again.\n";
  }
}

// read_end_pose: the pose after the square; odometry that did not move along the square between
// the two Enters (the log's poses in between: less than half of 4 L) is refused: on a terminal
// the Enter is asked for again, in a script the session ends.
bool read_end_pose(Prompter& in, PoseFeed& feed, const RecordOpts& o, std::string_view dir,
                   PoseReading& out) {
  const std::string prompt =
      "  drive the " + std::string(dir) + " square now; press Enter when it has stopped: ";
  for (;;) {
    if (!read_pose(in, feed, prompt, out)) return false;
    if (!out.path || *out.path >= kMinPathFraction * 4.0 * o.side) return true;
    std::ostringstream m;
    m << "the odometry moved " << std::fixed << std::setprecision(3) << *out.path
      << " m since the start pose, a square of " << std::defaultfloat << o.side << " m is "
      << 4.0 * o.side << " m: drive the square (is --side right?), then press Enter";
    if (in.scripted()) {
      std::cerr << "odomctl " << kCmd << ": " << m.str() << "\n";
      return false;
    }
    std::cout << "  " << m.str() << ".\n";
  }
}

// tape: the two distances [mm on the prompt, m returned] at `when` (start or end).
bool tape(Prompter& in, const RecordOpts& o, const char* when, calib::TapeReading& t) {
  const std::string side = o.wall == calib::SideWall::kLeft ? "left" : "right";
  const Prompter::Plausibility millimetres = [](double v) {
    std::ostringstream m;
    if (v < kMinTapeMm)
      m << v << " mm from a wall (under " << kMinTapeMm << " mm): metres typed? type millimetres ("
        << v << " m = " << v * 1e3 << " mm)";
    return m.str();
  };
  std::optional<double> back, s;
  if (!in.number(std::string("  tape at ") + when + ": reference point to the back wall [mm]: ",
                 0.0, 1e5, 1e-3, false, back, millimetres) ||
      !in.number(
          std::string("  tape at ") + when + ": reference point to the " + side + " wall [mm]: ",
          0.0, 1e5, 1e-3, false, s, millimetres))
    return false;
  t = {*back, *s};
  return true;
}

// end_readings: the end tape and heading, and the return error they give; a return error over
// kMaxReturnFraction of the side is asked again (a terminal) or refused (a script).
bool end_readings(Prompter& in, const RecordOpts& o, Direction d, bool bumps,
                  const calib::TapeReading& t0, const Pose2& p0, const Pose2& p1, UmbmarkRun& run) {
  const bool need_heading = bumps || o.bumps;
  for (;;) {
    calib::TapeReading t1;
    std::optional<double> heading;
    if (!tape(in, o, "end", t1) ||
        !in.number(need_heading ? "  heading change [deg, counter-clockwise +]: "
                                : "  heading change [deg, counter-clockwise +; empty: not "
                                  "measured]: ",
                   -180.0, 180.0, kRadPerDeg, !need_heading, heading))
      return false;
    run = calib::tape_return_error(d, bumps, o.wall, t0, t1, heading, p0, p1);
    const double r = std::hypot(run.ex, run.ey);
    if (r <= kMaxReturnFraction * o.side) return true;
    std::ostringstream m;
    m << "the return error (ex " << mm(run.ex) << ", ey " << mm(run.ey) << ") is " << std::noshowpos
      << std::fixed << std::setprecision(0) << 100.0 * r / o.side << " % of the " << o.side
      << " m side (at most " << 100.0 * kMaxReturnFraction
      << " % is taken): check the end readings (millimetres, which wall), then type them";
    if (!in.refused(m.str())) return false;
  }
}

// record_run: one run of the plan, from the start mark to the computed return error.
bool record_run(Prompter& in, PoseFeed& feed, const RecordOpts& o, Direction d, bool bumps,
                UmbmarkRun& run) {
  const std::string_view dir = choice_name(calib::kDirections, d);
  std::cout << "  Put the robot on the start mark, heading along the first leg"
            << (bumps ? (d == Direction::kCw ? "; ten ~10 mm cables under the right wheel's "
                                               "track on the first leg"
                                             : "; ten ~10 mm cables under the left wheel's "
                                               "track on the first leg")
                      : "")
            << ".\n";
  calib::TapeReading t0;
  PoseReading p0, p1;
  if (!tape(in, o, "start", t0) ||
      !read_pose(in, feed, "  press Enter to read the odometry's start pose: ", p0))
    return false;
  print_pose("start", p0.pose);
  if (!read_end_pose(in, feed, o, dir, p1)) return false;
  print_pose("end", p1.pose);
  if (!end_readings(in, o, d, bumps, t0, p0.pose, p1.pose, run)) return false;
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

// StoreNow: what --store holds before an import: its factors when it holds a calibration, and
// the words for the preview's heading either way.
struct StoreNow {
  std::optional<calib::Factors> factors;
  std::string what;
};

// store_now: reads --store without changing it (a missing file is not created here); a record
// without a wheelbase leaves the daemon's configured one, `wheelbase` [m].
StoreNow store_now(const std::string& path, double wheelbase) {
  // A missing file says why (not written yet, or a directory that does not exist: a typo).
  if (auto absent = fw::store_absence(path, NvBackend::kAuto)) return {std::nullopt, absent->text};
  auto s = fw::open_calibration_store(path, NvBackend::kAuto);
  if (!s) return {std::nullopt, s.error().message};
  auto l = s->store->load();
  if (!l) return {std::nullopt, l.error().message};
  if (l->status != calib::StoreStatus::kOk || !l->record || l->record->cleared)
    return {std::nullopt, path + ": " + l->describe()};
  const calib::CalibrationRecord& r = *l->record;
  return {calib::Factors{r.c_l, r.c_r, r.wheelbase.value_or(wheelbase)},
          "in " + path + " now, sequence " + std::to_string(r.sequence)};
}

// print_import: what an import would change: the factors in the store now (or, for a store
// without a calibration, those the robot used during the runs) against the new ones, with the
// new ones' sigmas; and a note when the store holds other factors than the runs were driven
// with (--current-*, --wheelbase: UMBmark composes the new factors from those).
void print_import(const RecordOpts& o, const calib::UmbmarkInput& ui,
                  const calib::UmbmarkResult& r) {
  const std::optional<calib::Factors> sd = calib::factor_sigmas(ui, r);
  const StoreNow now = store_now(o.store, o.wheelbase);
  const calib::Factors used{o.cl, o.cr, o.wheelbase};
  const calib::Factors old = now.factors.value_or(used);
  auto row = [&](const char* name, double old_v, double new_v, std::optional<double> sigma,
                 double unit, const char* unit_name, int digits) {
    std::cout << "  " << std::left << std::setw(10) << name << std::right << std::fixed
              << std::setprecision(digits) << old_v * unit << unit_name << " -> " << new_v * unit
              << unit_name;
    if (sigma) std::cout << "  (sigma " << *sigma * unit << unit_name << ")";
    std::cout << "\n";
  };
  if (now.factors)
    std::cout << "the import would store (" << now.what << " -> new):\n";
  else
    std::cout << "the import would store (used during the runs -> new):\n  (" << now.what << ")\n";
  row("c_l", old.c_l, r.composed.c_l, sd ? std::optional(sd->c_l) : std::nullopt, 1.0, "", 6);
  row("c_r", old.c_r, r.composed.c_r, sd ? std::optional(sd->c_r) : std::nullopt, 1.0, "", 6);
  row("wheelbase", old.wheelbase, r.composed.wheelbase,
      sd ? std::optional(sd->wheelbase) : std::nullopt, 1e3, " mm", 1);
  if (!sd) std::cout << "  (sigmas unknown: fewer than 3 runs a direction)\n";
  // 1e-6: what `calib show` prints (6 decimals) and a person types back counts as the same.
  const bool differ = now.factors && (std::fabs(old.c_l - used.c_l) > 1e-6 ||
                                      std::fabs(old.c_r - used.c_r) > 1e-6 ||
                                      std::fabs(old.wheelbase - used.wheelbase) > 1e-6);
  if (differ)
    std::cout << std::setprecision(6) << "  note: the new factors are composed from those the runs "
              << "were driven with (--current-cl " << used.c_l << " --current-cr " << used.c_r
              << " --wheelbase " << used.wheelbase << "), not from the store's: if odometryd ran "
              << "with the store's, answer N and record again with --current-cl " << old.c_l
              << " --current-cr " << old.c_r << " --wheelbase " << old.wheelbase << "\n";
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
  print_import(o, ui, *r);
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
  catch_interrupt();
  exit_code = kExitFailed;
  for (std::size_t i = runs.size(); i < p.size(); ++i) {
    std::cout << "\nRun " << i + 1 << " of " << p.size() << ": "
              << (p[i].first == Direction::kCw ? "cw (clockwise, turning right)"
                                               : "ccw (counter-clockwise, turning left)")
              << (p[i].second ? ", with bumps" : "") << "\n";
    UmbmarkRun run;
    if (!record_run(in, *feed, o, p[i].first, p[i].second, run)) {
      // Ctrl-D, Ctrl-C and a session that cannot go on all end here, with the same words.
      std::cerr << "odomctl " << kCmd << ": stopped; " << runs.size() << " runs saved in " << o.csv
                << ": the same command resumes\n";
      if (in.bad()) exit_code = kExitBadInput;
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
