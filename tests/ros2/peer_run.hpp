// Test side of the DDS peers: running a peer (or odometryd) and collecting its stdout lines,
// splitting a line into words, and the environment the Fast DDS peer runs with.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace odo::ros2::test {

struct PeerRun {
  std::vector<std::string> lines;
  int status = -1;  // pclose() status: 0 when the command exited 0
};

// run_peer: runs cmd (through the shell), collects its stdout lines, returns them with the exit
// status.
inline PeerRun run_peer(const std::string& cmd) {
  PeerRun r;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return r;
  char buf[8192];
  while (std::fgets(buf, sizeof buf, f)) {
    std::string l(buf);
    if (!l.empty() && l.back() == '\n') l.pop_back();
    r.lines.push_back(l);
  }
  r.status = pclose(f);
  return r;
}

inline std::vector<std::string> split(const std::string& l) {
  std::istringstream in(l);
  std::vector<std::string> t;
  for (std::string w; in >> w;) t.push_back(w);
  return t;
}

// fastdds_peer_env: shell assignments to put before the Fast DDS peer's command. Sanitizer
// builds: Debian's libfastrtps 2.9 deletes its StatisticsReaderImpl (64 bytes) as an RTPSReader
// (56) when the participant is torn down (ASan new-delete-type-mismatch inside the library),
// and ThreadSanitizer, blind to the uninstrumented library's locking, reports an unlock by a
// wrong thread inside it. Those checks are off for the peer process only (a test tool; the
// process under test keeps them all).
inline std::string fastdds_peer_env() {
  auto with = [](const char* var, const char* extra) {
    const char* v = std::getenv(var);
    return std::string(var) + "='" + (v ? v : "") + (v && *v ? " " : "") + extra + "' ";
  };
  return with("ASAN_OPTIONS", "new_delete_type_mismatch=0") + with("TSAN_OPTIONS", "report_bugs=0");
}

// kCycloneLoopbackXml: the Cyclone peer's network set-up (CYCLONEDDS_URI): loopback only,
// unicast discovery.
inline constexpr const char* kCycloneLoopbackXml =
    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>"
    "</Discovery></Domain></CycloneDDS>";

// test_domain: a DDS domain for this process (100..219), so that parallel test runs do not
// meet; offset separates the tests of one process.
inline int test_domain(int offset, int pid) {
  return 100 + (pid * 2 + offset) % 120;
}

}  // namespace odo::ros2::test
