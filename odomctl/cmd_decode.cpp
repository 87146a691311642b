// odomctl decode FILE [--csv] [--base-id N]: a candump -L log of the CAN pose protocol as a
// readable table (one frame per line) or as CSV (one signal per row).
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "odo/protocol/candump_log.hpp"

namespace odo::ctl {

namespace {

struct DecodeOpts {
  std::string file;
  bool csv = false;
  int base_id = static_cast<int>(protocol::kDefaultBaseId);
};

// DecodeTally: what a log held, for the summary line.
struct DecodeTally {
  std::size_t frames = 0, ours = 0, groups = 0, lost = 0;
  std::map<int, int> last_seq;  // per node
};

// count_pose_group: a PoseX frame opens a pose group; a gap in its 8-bit sequence counts lost
// groups.
void count_pose_group(const protocol::DecodedFrame& d, DecodeTally& tally) {
  const int seq = static_cast<int>(d.fields[1].value);
  auto it = tally.last_seq.find(d.node);
  if (it != tally.last_seq.end())
    tally.lost += static_cast<std::size_t>((seq - it->second - 1 + 256) % 256);
  tally.last_seq[d.node] = seq;
  ++tally.groups;
}

// format_frame: one parsed line as table row(s) or CSV rows, appended to `out`.
void format_frame(const DecodeOpts& o, const protocol::CandumpLine& p, DecodeTally& tally,
                  std::string& out) {
  char buf[160];
  char t[32];
  std::snprintf(t, sizeof t, "%lld.%06d", static_cast<long long>(p.sec), p.usec);
  char id[16];
  std::snprintf(id, sizeof id, p.frame.extended ? "%08X" : "%03X", p.frame.id);
  protocol::DecodedFrame d;
  if (!protocol::decode_protocol_frame(static_cast<std::uint32_t>(o.base_id), p.frame, d)) {
    if (!o.csv) {
      std::snprintf(buf, sizeof buf,
                    "%s %-6s %s  %-2s %-12s len=%u (not a frame of this "
                    "protocol)\n",
                    t, p.iface.c_str(), id, "-", "-", p.frame.len);
      out += buf;
    }
    return;
  }
  ++tally.ours;
  if (d.msg == protocol::Msg::kPoseX) count_pose_group(d, tally);
  if (o.csv) {
    for (std::size_t i = 0; i < d.n_fields; ++i) {
      std::snprintf(buf, sizeof buf, "%s,%s,%s,%d,%s,%s,%.9g\n", t, p.iface.c_str(), id, d.node,
                    d.message, d.fields[i].name, d.fields[i].value);
      out += buf;
    }
    return;
  }
  std::snprintf(buf, sizeof buf, "%s %-6s %s  %-2d %-12s", t, p.iface.c_str(), id, d.node,
                d.message);
  out += buf;
  for (std::size_t i = 0; i < d.n_fields; ++i) {
    std::snprintf(buf, sizeof buf, " %s=%.9g", d.fields[i].name, d.fields[i].value);
    out += buf;
  }
  out += '\n';
}

// run_decode: `odomctl ... decode` once its options are parsed; sets exit_code.
void run_decode(const DecodeOpts& o, int& exit_code) {
  std::ifstream in(o.file, std::ios::binary);
  if (!in) {
    std::cerr << "odomctl decode: " << o.file << ": cannot open\n";
    exit_code = kExitBadInput;
    return;
  }
  std::string line;
  std::size_t n = 0;
  DecodeTally tally;
  std::string out;
  if (o.csv) out += "time,iface,id,node,message,signal,value\n";
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line == "\r") continue;
    // A last line without its newline is a line still being written (a log tailed while
    // candump or odometryd --can-log writes it): not a frame yet, and not an error.
    if (in.eof()) {
      std::cerr << "odomctl decode: " << o.file << ":" << n
                << ": the last line has no newline yet (still being written?): left out\n";
      break;
    }
    auto p = protocol::parse_candump_line(line);
    if (!p) {
      std::cerr << "odomctl decode: " << o.file << ":" << n << ": " << p.error().message << "\n";
      exit_code = kExitBadInput;
      return;
    }
    ++tally.frames;
    format_frame(o, *p, tally, out);
  }
  std::cout << out;
  if (!o.csv) {
    std::cout << "# " << tally.frames << " frames, " << tally.ours << " of this protocol, "
              << tally.groups << " pose groups, " << tally.lost
              << " pose groups lost (sequence gaps)\n";
  }
}

}  // namespace

void add_decode(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<DecodeOpts>();
  CLI::App* c = app.add_subcommand(
      "decode", "decode a candump -L log of the CAN pose protocol (README \"CAN protocol\")");
  c->add_option("file", o->file, "candump -L log (odometryd --can-log, candump -L)")->required();
  c->add_flag("--csv", o->csv, "CSV, one row per signal: time,iface,id,node,message,signal,value");
  fw::with_range(c->add_option("--base-id", o->base_id, "protocol base id"), 0, 1024)
      ->capture_default_str();
  c->callback([o, &exit_code] { run_decode(*o, exit_code); });
}

}  // namespace odo::ctl
