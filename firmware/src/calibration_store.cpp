#include "odo/firmware/calibration_store.hpp"

#include <sstream>

#include "odo/drivers/nv_storage.hpp"

namespace odo::fw {

using calib::CalibrationRecord;
using calib::LoadResult;
using calib::StoreStatus;

Result<OpenStore> open_calibration_store(const std::string& path, NvBackend backend) {
  const NvBackend k = backend == NvBackend::kAuto ? drivers::detect_nv_backend(path) : backend;
  OpenStore o;
  o.backend = drivers::nv_backend_name(k);
  auto m = drivers::open_nv_storage(path, k);
  if (!m) return std::move(m).error();
  o.medium = std::move(m).value();
  auto s = calib::CalibrationStore::create(*o.medium);
  if (!s) return make_error(s.error().code, path + ": " + s.error().message);
  o.store.emplace(std::move(s).value());
  return o;
}

AppliedCalibration apply_calibration(const KinematicParams& nominal,
                                     const Result<calib::LoadResult>& loaded,
                                     std::string_view where) {
  AppliedCalibration a;
  a.params = nominal;
  std::ostringstream m;
  m << "calibration " << where << ": ";
  if (!loaded) {
    a.state = StoreStatus::kCorrupt;
    m << "ERROR: cannot read the store (" << loaded.error().message
      << "); running on NOMINAL values";
    a.report = m.str();
    return a;
  }
  const LoadResult& l = *loaded;
  if (l.status == StoreStatus::kCorrupt) {
    a.state = StoreStatus::kCorrupt;
    m << "ERROR: store corrupt (" << l.describe() << "); running on NOMINAL values";
    a.report = m.str();
    return a;
  }
  if (l.status == StoreStatus::kUncalibrated) {
    m << "uncalibrated (" << l.describe() << "); running on nominal values";
    a.sequence = l.record ? l.record->sequence : 0;
    a.report = m.str();
    return a;
  }
  const CalibrationRecord& r = *l.record;
  auto applied = calib::apply_record(nominal, r);
  if (!applied) {
    a.state = StoreStatus::kCorrupt;
    m << "ERROR: stored values rejected (" << applied.error().message
      << "); running on NOMINAL values";
    a.report = m.str();
    return a;
  }
  const KinematicParams p = *applied;
  a.params = p;
  a.state = StoreStatus::kOk;
  a.sequence = r.sequence;
  m << "ok, sequence " << r.sequence << ": c_l=" << r.c_l << " c_r=" << r.c_r
    << " b=" << p.wheelbase << " m" << (r.wheelbase ? "" : " (nominal)")
    << " Dn=" << p.wheel_diameter << " m" << (r.wheel_diameter ? "" : " (nominal)") << " ("
    << (r.method.empty() ? "?" : r.method) << ", " << calib::utc_text(r.time) << ")";
  a.report = m.str();
  return a;
}

AppliedCalibration read_and_apply(const KinematicParams& nominal, const std::string& path,
                                  NvBackend backend) {
  if (path.empty()) {
    AppliedCalibration a;
    a.params = nominal;
    a.report = "calibration: no store configured; running on nominal values";
    return a;
  }
  auto o = open_calibration_store(path, backend);
  if (!o) return apply_calibration(nominal, Result<LoadResult>(std::move(o).error()), path);
  const std::string where = path + " (" + o->backend + ")";
  return apply_calibration(nominal, o->store->load(), where);
}

}  // namespace odo::fw
