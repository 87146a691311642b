#include "odo/drivers/iio_gyro.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>

namespace odo::drivers {
namespace {

bool exists(const std::string& path) {
  return ::access(path.c_str(), F_OK) == 0;
}

// read_attr: the first line of a sysfs attribute, without its newline.
Result<std::string> read_attr(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  if (!f || !std::getline(f, line))
    return make_error(exists(path) ? Errc::kIo : Errc::kNotFound, path + ": cannot be read");
  return line;
}

// write_attr: writes `value` to a sysfs attribute (one write, as `echo` does).
Status write_attr(const std::string& path, const std::string& value) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) return make_error(Errc::kIo, path + ": open for writing: " + std::strerror(errno));
  const ssize_t n = ::write(fd, value.data(), value.size());
  const int err = errno;
  ::close(fd);
  if (n != static_cast<ssize_t>(value.size()))
    return make_error(Errc::kIo, path + ": writing '" + value +
                                     "': " + (n < 0 ? std::strerror(err) : "short write"));
  return Ok{};
}

// parse_real: the whole text as a finite number (surrounding blanks allowed).
bool parse_real(const std::string& text, double& out) {
  const char* b = text.c_str();
  char* end = nullptr;
  errno = 0;
  out = std::strtod(b, &end);
  if (end == b || errno == ERANGE || !std::isfinite(out)) return false;
  while (*end == ' ' || *end == '\n' || *end == '\t') ++end;
  return *end == '\0';
}

// list_dir: the entries of a directory (no . and ..), sorted.
std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool starts_with(const std::string& s, const std::string& p) {
  return s.compare(0, p.size(), p) == 0;
}

bool ends_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(s.size() - p.size(), p.size(), p) == 0;
}

// find_device: the sysfs directory of the configured device (by path or by name).
Result<std::string> find_device(const IioGyroConfig& c) {
  if (c.device.empty())
    return make_error(Errc::kInvalidArgument,
                      "gyro device is empty: give the IIO device's name "
                      "(" +
                          c.sysfs_root + "/*/name) or its path");
  if (c.device.front() == '/') {
    const std::string base = c.device.substr(c.device.find_last_of('/') + 1);
    const std::string dir = starts_with(c.device, c.dev_root + "/") && starts_with(base, "iio:")
                                ? c.sysfs_root + "/" + base
                                : c.device;
    if (!exists(dir + "/name"))
      return make_error(Errc::kNotFound, "gyro device " + c.device + ": no IIO device there (" +
                                             dir + "/name does not exist)");
    return dir;
  }
  std::vector<std::string> matches;
  std::string present;
  for (const std::string& e : list_dir(c.sysfs_root)) {
    if (!starts_with(e, "iio:device")) continue;
    const auto name = read_attr(c.sysfs_root + "/" + e + "/name");
    if (!name) continue;
    present += (present.empty() ? "" : ", ") + *name + " (" + e + ")";
    if (*name == c.device) matches.push_back(c.sysfs_root + "/" + e);
  }
  if (matches.empty())
    return make_error(Errc::kNotFound, "gyro device '" + c.device +
                                           "': no IIO device of that "
                                           "name under " +
                                           c.sysfs_root + " (present: " +
                                           (present.empty() ? "none" : present) + ")");
  if (matches.size() > 1)
    return make_error(Errc::kInvalidArgument,
                      "gyro device '" + c.device + "': " + std::to_string(matches.size()) +
                          " IIO devices have that name (" + present + "); give the path of one");
  return matches.front();
}

}  // namespace

char axis_letter(IioAxis a) noexcept {
  return a == IioAxis::kX ? 'x' : (a == IioAxis::kY ? 'y' : 'z');
}

Result<std::unique_ptr<IioGyro>> IioGyro::open(const IioGyroConfig& c) {
  if (c.sign != 1 && c.sign != -1)
    return make_error(Errc::kInvalidArgument,
                      "gyro sign = " + std::to_string(c.sign) +
                          " must be +1 (chip axis along the robot's z, up) or -1 (upside down)");
  if (c.buffer_length < 2 || c.buffer_length > 65536 || c.max_scans_per_read < 1 ||
      c.max_scans_per_read > 4096 || c.stale_timeout <= 0)
    return make_error(Errc::kInvalidArgument,
                      "gyro buffer_length must be 2..65536, "
                      "max_scans_per_read 1..4096, stale_timeout > 0");
  auto dir = find_device(c);
  if (!dir) return std::move(dir).error();
  std::unique_ptr<IioGyro> g(new IioGyro());
  g->dir_ = *dir;
  g->name_ = read_attr(g->dir_ + "/name").value();
  g->chan_ = std::string("in_anglvel_") + axis_letter(c.axis);
  g->mode_ = c.mode;
  g->sign_ = c.sign;
  g->book_.stale_timeout = c.stale_timeout;
  if (auto s = g->read_scale(c); !s) return std::move(s).error();
  const Status s = c.mode == IioMode::kBuffered ? g->setup_buffer(c) : g->setup_polled(c);
  if (!s) return std::move(s).error();
  return g;
}

Status IioGyro::read_scale(const IioGyroConfig& c) {
  const std::string who = "IIO device '" + name_ + "' (" + dir_ + ")";
  // The channel must exist in some form: raw attribute or scan element.
  if (!exists(dir_ + "/" + chan_ + "_raw") && !exists(dir_ + "/scan_elements/" + chan_ + "_en")) {
    std::string have;
    for (const std::string& e : list_dir(dir_))
      if (starts_with(e, "in_anglvel_") && ends_with(e, "_raw")) have += " " + e;
    return make_error(Errc::kNotFound,
                      who + ": channel " + chan_ + " missing (no " + chan_ +
                          "_raw, no scan_elements/" + chan_ +
                          "_en; has:" + (have.empty() ? " no angular-rate channel" : have) + ")");
  }
  std::string path = dir_ + "/" + chan_ + "_scale";
  if (!exists(path)) path = dir_ + "/in_anglvel_scale";
  const auto text = read_attr(path);
  if (!text)
    return make_error(Errc::kNotFound, who + ": channel " + chan_ + " has no scale (neither " +
                                           chan_ + "_scale nor in_anglvel_scale)");
  if (!parse_real(*text, scale_) || !(scale_ > 0.0))
    return make_error(Errc::kParse, who + ": " + path + " = '" + *text +
                                        "' is not a positive number [rad/s per LSB]");
  for (const std::string& p : {dir_ + "/" + chan_ + "_offset", dir_ + "/in_anglvel_offset"}) {
    if (!exists(p)) continue;
    const auto o = read_attr(p);
    if (!o || !parse_real(*o, offset_))
      return make_error(Errc::kParse, who + ": " + p + " is not a number [LSB]");
    break;
  }
  // The word's width, for saturation and full_scale, from the scan element when there is one.
  full_scale_ = std::numeric_limits<double>::infinity();
  if (const auto t = read_attr(dir_ + "/scan_elements/" + chan_ + "_type")) {
    auto parsed = parse_iio_scan_type(*t);
    if (!parsed)
      return make_error(Errc::kParse,
                        who + ": scan_elements/" + chan_ + "_type: " + parsed.error().message);
    type_ = *parsed;
    have_type_ = true;
    iio_raw_limits(type_, raw_lo_, raw_hi_);
    full_scale_ = (static_cast<double>(raw_hi_) + offset_) * scale_;
  }
  (void)c;
  return Ok{};
}

Status IioGyro::setup_polled(const IioGyroConfig& c) {
  const std::string path = dir_ + "/" + chan_ + "_raw";
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0)
    return make_error(Errc::kNotFound, "IIO device '" + name_ + "' (" + dir_ + "): channel " +
                                           chan_ + ": " + path + ": " + std::strerror(errno));
  (void)c;
  return Ok{};
}

IioGyro::~IioGyro() {
  if (fd_ >= 0) ::close(fd_);
  if (mode_ == IioMode::kBuffered && fd_ >= 0) (void)write_attr(dir_ + "/buffer/enable", "0");
}

void IioGyro::finish(GyroSample& s, TimeNs now, double sum) noexcept {
  const double mean = s.samples > 0 ? sign_ * (sum / s.samples + offset_) * scale_ : 0.0;
  book_.close(s, now, mean);
}

GyroSample IioGyro::read(TimeNs now) noexcept {
  GyroSample s;
  const double sum = mode_ == IioMode::kBuffered ? read_buffered(s) : read_polled(s, now);
  finish(s, now, sum);
  return s;
}

double IioGyro::read_buffered(GyroSample& s) noexcept {
  const ssize_t n = ::read(fd_, buf_.data() + pending_, buf_.size() - pending_);
  if (n < 0) {
    if (errno != EAGAIN && errno != EINTR) {
      s.flags |= kGyroReadError;
      ++book_.counters.read_errors;
    }
    return 0.0;
  }
  const std::size_t total = pending_ + static_cast<std::size_t>(n);
  const std::size_t scans = total / scan_bytes_;
  double sum = 0.0;
  for (std::size_t i = 0; i < scans; ++i) {
    const std::uint8_t* scan = buf_.data() + i * scan_bytes_;
    const std::int64_t raw = iio_extract(scan + rate_off_, type_);
    if (raw <= raw_lo_ || raw >= raw_hi_) {
      s.flags |= kGyroSaturated;
      ++book_.counters.saturated;
    }
    sum += static_cast<double>(raw);
    book_.last_stamp = iio_extract(scan + ts_off_, ts_type_);
  }
  s.samples = static_cast<std::uint32_t>(scans);
  // The kernel hands out whole scans; a pipe or file standing in for it need not.
  pending_ = total - scans * scan_bytes_;
  if (pending_ > 0) std::memmove(buf_.data(), buf_.data() + scans * scan_bytes_, pending_);
  return sum;
}

double IioGyro::read_polled(GyroSample& s, TimeNs now) noexcept {
  char text[32];
  const ssize_t n = ::pread(fd_, text, sizeof text - 1, 0);
  if (n <= 0) {
    s.flags |= kGyroReadError;  // e.g. EBUSY while someone else runs the buffer
    ++book_.counters.read_errors;
    return 0.0;
  }
  text[n] = '\0';
  char* end = nullptr;
  errno = 0;
  const long long raw = std::strtoll(text, &end, 10);
  if (end == text || errno == ERANGE || (*end != '\n' && *end != '\0')) {
    s.flags |= kGyroInvalid;
    ++book_.counters.invalid;
    return 0.0;
  }
  if (have_type_ && (raw <= raw_lo_ || raw >= raw_hi_)) {
    s.flags |= kGyroSaturated;
    ++book_.counters.saturated;
  }
  s.samples = 1;
  book_.last_stamp = now;
  return static_cast<double>(raw);
}

Status IioGyro::setup_buffer(const IioGyroConfig& c) {
  const std::string who = "IIO device '" + name_ + "' (" + dir_ + ")";
  const std::string se = dir_ + "/scan_elements/";
  if (!exists(se + chan_ + "_en"))
    return make_error(Errc::kNotFound, who + ": channel " + chan_ + " has no scan element (" + se +
                                           chan_ +
                                           "_en): the driver has no buffer; "
                                           "use mode = polled");
  if (!exists(se + "in_timestamp_en"))
    return make_error(Errc::kNotFound, who + ": no timestamp channel (" + se +
                                           "in_timestamp_en); use mode = polled");
  if (auto st = write_attr(dir_ + "/buffer/enable", "0"); !st) return st;
  // Only our channel and the timestamp: the smallest scan, the cheapest read.
  for (const std::string& e : list_dir(se)) {
    if (!ends_with(e, "_en")) continue;
    const std::string ch = e.substr(0, e.size() - 3);
    if (auto st = write_attr(se + e, ch == chan_ || ch == "in_timestamp" ? "1" : "0"); !st)
      return st;
  }
  if (auto st = layout(who, se); !st) return st;
  // Time stamps on the loop's clock (the default is CLOCK_REALTIME).
  if (exists(dir_ + "/current_timestamp_clock")) {
    if (auto st = write_attr(dir_ + "/current_timestamp_clock", "monotonic"); !st) return st;
  }
  if (auto st = configure_rate_and_trigger(c, who); !st) return st;
  if (auto st = write_attr(dir_ + "/buffer/length", std::to_string(c.buffer_length)); !st)
    return st;
  if (auto st = write_attr(dir_ + "/buffer/enable", "1"); !st)
    return make_error(Errc::kIo, who + ": " + st.error().message +
                                     " (is a trigger attached? set the gyro trigger)");
  const std::string dev = c.dev_root + "/" + dir_.substr(dir_.find_last_of('/') + 1);
  fd_ = ::open(dev.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    (void)write_attr(dir_ + "/buffer/enable", "0");
    return make_error(Errc::kIo, who + ": " + dev + ": " + std::strerror(err));
  }
  buf_.assign(scan_bytes_ * static_cast<std::size_t>(c.max_scans_per_read), 0);
  return Ok{};
}

Status IioGyro::layout(const std::string& who, const std::string& se) {
  // Every enabled element in index order (others may stay enabled if a driver insists).
  std::vector<std::pair<IioScanElement, std::string>> els;
  for (const std::string& e : list_dir(se)) {
    if (!ends_with(e, "_en")) continue;
    const std::string ch = e.substr(0, e.size() - 3);
    const auto en = read_attr(se + e);
    if (!en || *en != "1") continue;
    const auto idx = read_attr(se + ch + "_index");
    const auto ty = read_attr(se + ch + "_type");
    double index = 0.0;
    if (!idx || !parse_real(*idx, index) || index < 0)
      return make_error(Errc::kParse, who + ": " + se + ch + "_index is missing or not an index");
    if (!ty) return make_error(Errc::kNotFound, who + ": " + se + ch + "_type is missing");
    auto t = parse_iio_scan_type(*ty);
    if (!t) return make_error(Errc::kParse, who + ": " + se + ch + "_type: " + t.error().message);
    els.push_back({IioScanElement{static_cast<int>(index), *t}, ch});
  }
  std::sort(els.begin(), els.end(),
            [](const auto& a, const auto& b) { return a.first.index < b.first.index; });
  std::vector<IioScanElement> v;
  for (const auto& e : els) v.push_back(e.first);
  std::vector<std::size_t> off(v.size());
  scan_bytes_ = iio_scan_layout(v, off);
  bool have_rate = false, have_ts = false;
  for (std::size_t i = 0; i < els.size(); ++i) {
    if (els[i].second == chan_) {
      rate_off_ = off[i];
      have_rate = true;
    } else if (els[i].second == "in_timestamp") {
      ts_off_ = off[i];
      ts_type_ = els[i].first.type;
      have_ts = true;
    }
  }
  if (!have_rate || !have_ts || scan_bytes_ == 0)
    return make_error(Errc::kIo, who + ": " + chan_ + " or in_timestamp did not stay enabled");
  return Ok{};
}

Status IioGyro::configure_rate_and_trigger(const IioGyroConfig& c, const std::string& who) {
  if (c.expected_rate > 0.0) {
    std::string attr = dir_ + "/in_anglvel_sampling_frequency";
    if (!exists(attr)) attr = dir_ + "/sampling_frequency";
    if (!exists(attr))
      return make_error(Errc::kNotFound, who +
                                             ": no sampling_frequency attribute to set the "
                                             "expected rate");
    char v[32];
    std::snprintf(v, sizeof v, "%g", c.expected_rate);
    if (auto st = write_attr(attr, v); !st) return st;
    double got = 0.0;
    const auto back = read_attr(attr);
    if (!back || !parse_real(*back, got) ||
        std::fabs(got - c.expected_rate) > 0.01 * c.expected_rate)
      return make_error(Errc::kInvalidArgument,
                        who + ": " + attr + " reads '" + (back ? *back : std::string("?")) +
                            "' after writing the expected rate " + v + " Hz");
  }
  if (!c.trigger.empty()) {
    const std::string attr = dir_ + "/trigger/current_trigger";
    if (auto st = write_attr(attr, c.trigger); !st) return st;
    const auto back = read_attr(attr);
    if (!back || *back != c.trigger)
      return make_error(Errc::kInvalidArgument, who + ": trigger '" + c.trigger +
                                                    "' not accepted (" + attr + " reads '" +
                                                    (back ? *back : std::string("?")) + "')");
  }
  return Ok{};
}

}  // namespace odo::drivers
