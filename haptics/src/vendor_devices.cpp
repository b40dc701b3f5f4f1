// The OpenHaptics HD and Force Dimension DHD backends, loaded at run time with dlopen (as
// CHAI3D loads its device libraries), so that they build everywhere and are tested against fake
// vendor libraries. Every signature and constant below is taken from the vendors' published
// headers (OpenHaptics hd.h / hdDefines.h; Force Dimension dhdc.h); nothing of theirs is
// included or linked at build time.
#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/triple_buffer.hpp"

#include <dlfcn.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

namespace spinesim::haptics {
namespace {

// A dlopen'ed library and its symbols; a missing symbol is collected, not fatal, so the error
// can list them all.
class SharedLibrary {
 public:
  explicit SharedLibrary(const std::string& path)
      : handle_(::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
    if (!handle_) {
      const char* e = ::dlerror();
      error_ = e ? e : "unknown dlopen error";
    }
  }
  ~SharedLibrary() {
    if (handle_) ::dlclose(handle_);
  }
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;
  bool loaded() const { return handle_ != nullptr; }
  const std::string& error() const { return error_; }
  template <class F>
  void bind(F& f, const char* name) {
    f = handle_ ? reinterpret_cast<F>(::dlsym(handle_, name)) : nullptr;
    if (!f) missing_ += (missing_.empty() ? "" : ", ") + std::string(name);
  }
  const std::string& missing() const { return missing_; }

 private:
  void* handle_;
  std::string error_, missing_;
};

// --- OpenHaptics HD (hdDefines.h, hd.h) ------------------------------------------------------
using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDCallbackCode = unsigned int;
using HDSchedulerHandle = unsigned long;
struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};
constexpr HDerror HD_SUCCESS = 0x0000;
constexpr HDenum HD_CURRENT_BUTTONS = 0x2000, HD_CURRENT_POSITION = 0x2050,
                 HD_CURRENT_VELOCITY = 0x2051, HD_CURRENT_FORCE = 0x2700, HD_FORCE_OUTPUT = 0x4000;
constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFF;
constexpr HDCallbackCode HD_CALLBACK_DONE = 0, HD_CALLBACK_CONTINUE = 1;
constexpr unsigned short HD_MAX_SCHEDULER_PRIORITY = 0xFFFF;  // USHRT_MAX

struct HdApi {
  HHD (*hdInitDevice)(const char*) = nullptr;
  void (*hdDisableDevice)(HHD) = nullptr;
  void (*hdBeginFrame)(HHD) = nullptr;
  void (*hdEndFrame)(HHD) = nullptr;
  void (*hdGetDoublev)(HDenum, double*) = nullptr;
  void (*hdGetIntegerv)(HDenum, int*) = nullptr;
  void (*hdSetDoublev)(HDenum, const double*) = nullptr;
  void (*hdEnable)(HDenum) = nullptr;
  HDErrorInfo (*hdGetError)() = nullptr;
  const char* (*hdGetErrorString)(HDerror) = nullptr;
  void (*hdStartScheduler)() = nullptr;
  void (*hdStopScheduler)() = nullptr;
  HDSchedulerHandle (*hdScheduleAsynchronous)(HDCallbackCode (*)(void*), void*,
                                              unsigned short) = nullptr;
  void (*hdUnschedule)(HDSchedulerHandle) = nullptr;
  void bind(SharedLibrary& lib) {
    lib.bind(hdInitDevice, "hdInitDevice");
    lib.bind(hdDisableDevice, "hdDisableDevice");
    lib.bind(hdBeginFrame, "hdBeginFrame");
    lib.bind(hdEndFrame, "hdEndFrame");
    lib.bind(hdGetDoublev, "hdGetDoublev");
    lib.bind(hdGetIntegerv, "hdGetIntegerv");
    lib.bind(hdSetDoublev, "hdSetDoublev");
    lib.bind(hdEnable, "hdEnable");
    lib.bind(hdGetError, "hdGetError");
    lib.bind(hdGetErrorString, "hdGetErrorString");
    lib.bind(hdStartScheduler, "hdStartScheduler");
    lib.bind(hdStopScheduler, "hdStopScheduler");
    lib.bind(hdScheduleAsynchronous, "hdScheduleAsynchronous");
    lib.bind(hdUnschedule, "hdUnschedule");
  }
};

std::string load_error(const std::string& backend, const std::string& path,
                       const SharedLibrary& lib) {
  if (!lib.loaded())
    return backend + ": cannot load " + path + " (" + lib.error() +
           "): install the vendor's SDK or give its library with --sdk-lib";
  return backend + ": " + path + " lacks " + lib.missing() + ": not the vendor's library?";
}

class OpenHapticsDevice final : public Device {
 public:
  OpenHapticsDevice(const DeviceCapabilities& caps, std::string path)
      : caps_(caps), path_(path.empty() ? "libHD.so" : std::move(path)), lib_(path_) {
    api_.bind(lib_);
  }
  ~OpenHapticsDevice() override { close(); }
  std::string name() const override { return "openhaptics"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }

  void open() override {
    if (!lib_.loaded() || !lib_.missing().empty())
      throw std::runtime_error(load_error("openhaptics", path_, lib_));
    hhd_ = api_.hdInitDevice(nullptr);  // HD_DEFAULT_DEVICE
    const HDErrorInfo e = api_.hdGetError();
    if (hhd_ == HD_INVALID_HANDLE || e.errorCode != HD_SUCCESS) {
      hhd_ = HD_INVALID_HANDLE;
      throw std::runtime_error("openhaptics: cannot open the device: " + error_text(e));
    }
    api_.hdEnable(HD_FORCE_OUTPUT);
    force_.write(Eigen::Vector3d::Zero());
    scheduled_ =
        api_.hdScheduleAsynchronous(&OpenHapticsDevice::servo, this, HD_MAX_SCHEDULER_PRIORITY);
    api_.hdStartScheduler();
    const HDErrorInfo s = api_.hdGetError();
    if (s.errorCode != HD_SUCCESS) {
      close();
      throw std::runtime_error("openhaptics: cannot start the scheduler: " + error_text(s));
    }
    running_ = true;
  }

  void close() override {
    if (hhd_ == HD_INVALID_HANDLE) return;
    force_.write(Eigen::Vector3d::Zero());
    if (running_) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // zero applied
    api_.hdStopScheduler();
    api_.hdUnschedule(scheduled_);
    api_.hdDisableDevice(hhd_);
    hhd_ = HD_INVALID_HANDLE;
    running_ = false;
  }

  bool read(DeviceState& s) override {
    if (failed_.load(std::memory_order_acquire)) return false;
    s = state_.read();
    return true;
  }
  bool write_force(const Eigen::Vector3d& f) override {
    force_.write(f);
    return !failed_.load(std::memory_order_acquire);
  }
  std::string last_error() const override {
    const HDerror code = error_code_.load();
    return code == HD_SUCCESS ? std::string() : "openhaptics: " + error_text({code, 0, hhd_});
  }

 private:
  std::string error_text(const HDErrorInfo& e) const {
    const char* text = api_.hdGetErrorString ? api_.hdGetErrorString(e.errorCode) : nullptr;
    return std::string(text ? text : "unknown error") + " (HD error 0x" +
           [](unsigned v) {
             char b[16];
             std::snprintf(b, sizeof b, "%04X", v);
             return std::string(b);
           }(e.errorCode) +
           ")";
  }
  // The HD scheduler's servo callback: the state out, the latest force in. On an error the
  // force is zeroed and the callback ends; read() then reports the failure to the loop.
  static HDCallbackCode servo(void* user) {
    auto* d = static_cast<OpenHapticsDevice*>(user);
    const HdApi& hd = d->api_;
    hd.hdBeginFrame(d->hhd_);
    DeviceState s;
    hd.hdGetDoublev(HD_CURRENT_POSITION, s.position_mm.data());
    hd.hdGetDoublev(HD_CURRENT_VELOCITY, s.velocity_mm_s.data());
    int buttons = 0;
    hd.hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
    s.buttons = unsigned(buttons);
    const Eigen::Vector3d& demanded = d->force_.read();
    const Eigen::Vector3d f = demanded.allFinite() ? demanded : Eigen::Vector3d::Zero();
    hd.hdSetDoublev(HD_CURRENT_FORCE, f.data());
    hd.hdEndFrame(d->hhd_);
    const HDErrorInfo e = hd.hdGetError();
    if (e.errorCode != HD_SUCCESS) {
      const double zero[3] = {0, 0, 0};
      hd.hdBeginFrame(d->hhd_);
      hd.hdSetDoublev(HD_CURRENT_FORCE, zero);
      hd.hdEndFrame(d->hhd_);
      d->error_code_.store(e.errorCode);
      d->failed_.store(true, std::memory_order_release);
      return HD_CALLBACK_DONE;
    }
    d->state_.write(s);
    return HD_CALLBACK_CONTINUE;
  }

  DeviceCapabilities caps_;
  std::string path_;
  SharedLibrary lib_;
  HdApi api_;
  HHD hhd_ = HD_INVALID_HANDLE;
  HDSchedulerHandle scheduled_ = 0;
  bool running_ = false;
  TripleBuffer<DeviceState> state_;
  TripleBuffer<Eigen::Vector3d> force_{Eigen::Vector3d::Zero()};
  std::atomic<bool> failed_{false};
  std::atomic<HDerror> error_code_{HD_SUCCESS};
};

// --- Force Dimension DHD (dhdc.h) -------------------------------------------------------------
struct DhdApi {
  int (*dhdOpen)() = nullptr;
  int (*dhdClose)(char) = nullptr;
  int (*dhdEnableForce)(unsigned char, char) = nullptr;
  int (*dhdGetPosition)(double*, double*, double*, char) = nullptr;
  int (*dhdGetLinearVelocity)(double*, double*, double*, char) = nullptr;
  int (*dhdGetButtonMask)(char) = nullptr;
  int (*dhdSetForce)(double, double, double, char) = nullptr;
  const char* (*dhdErrorGetLastStr)() = nullptr;
  int (*dhdGetDeviceCount)() = nullptr;
  void bind(SharedLibrary& lib) {
    lib.bind(dhdOpen, "dhdOpen");
    lib.bind(dhdClose, "dhdClose");
    lib.bind(dhdEnableForce, "dhdEnableForce");
    lib.bind(dhdGetPosition, "dhdGetPosition");
    lib.bind(dhdGetLinearVelocity, "dhdGetLinearVelocity");
    lib.bind(dhdGetButtonMask, "dhdGetButtonMask");
    lib.bind(dhdSetForce, "dhdSetForce");
    lib.bind(dhdErrorGetLastStr, "dhdErrorGetLastStr");
    lib.bind(dhdGetDeviceCount, "dhdGetDeviceCount");
  }
};
constexpr unsigned char DHD_ON = 1;
constexpr char kDefaultId = -1;

// DHD's frame is x towards the user, y right, z up, in metres; ours x right, y up, z towards
// the user, in mm.
Eigen::Vector3d from_dhd(double x, double y, double z) { return 1000.0 * Eigen::Vector3d(y, z, x); }

class DhdDevice final : public Device {
 public:
  DhdDevice(const DeviceCapabilities& caps, std::string path)
      : caps_(caps), path_(path.empty() ? "libdhd.so" : std::move(path)), lib_(path_) {
    api_.bind(lib_);
  }
  ~DhdDevice() override { close(); }
  std::string name() const override { return "dhd"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }
  void open() override {
    if (!lib_.loaded() || !lib_.missing().empty())
      throw std::runtime_error(load_error("dhd", path_, lib_));
    if (api_.dhdOpen() < 0)
      throw std::runtime_error("dhd: cannot open the device: " + vendor_text());
    open_ = true;
    if (api_.dhdEnableForce(DHD_ON, kDefaultId) < 0) {
      const std::string why = vendor_text();
      close();
      throw std::runtime_error("dhd: cannot enable forces: " + why);
    }
  }
  void close() override {
    if (!open_) return;
    api_.dhdSetForce(0, 0, 0, kDefaultId);
    api_.dhdClose(kDefaultId);
    open_ = false;
  }
  bool read(DeviceState& s) override {
    double x = 0, y = 0, z = 0, vx = 0, vy = 0, vz = 0;
    if (api_.dhdGetPosition(&x, &y, &z, kDefaultId) < 0 ||
        api_.dhdGetLinearVelocity(&vx, &vy, &vz, kDefaultId) < 0)
      return fail();
    const int mask = api_.dhdGetButtonMask(kDefaultId);
    if (mask < 0) return fail();
    s.position_mm = from_dhd(x, y, z);
    s.velocity_mm_s = from_dhd(vx, vy, vz);
    s.buttons = unsigned(mask);
    return true;
  }
  bool write_force(const Eigen::Vector3d& f) override {
    const Eigen::Vector3d g = f.allFinite() ? f : Eigen::Vector3d::Zero();
    if (api_.dhdSetForce(g.z(), g.x(), g.y(), kDefaultId) < 0) return fail();  // (x, y, z)_dhd
    return true;
  }
  std::string last_error() const override { return failed_ ? "dhd: " + error_ : std::string(); }

 private:
  std::string vendor_text() const {
    const char* t = api_.dhdErrorGetLastStr ? api_.dhdErrorGetLastStr() : nullptr;
    return t ? t : "unknown error";
  }
  bool fail() {
    if (!failed_) {
      failed_ = true;
      error_ = vendor_text();  // once, on the first error (the loop stops right after)
      api_.dhdSetForce(0, 0, 0, kDefaultId);
    }
    return false;
  }
  DeviceCapabilities caps_;
  std::string path_;
  SharedLibrary lib_;
  DhdApi api_;
  bool open_ = false, failed_ = false;
  std::string error_;
};

class MappedDevice final : public Device {
 public:
  MappedDevice(std::unique_ptr<Device> d, const Eigen::Matrix3d& R, const Eigen::Vector3d& c)
      : d_(std::move(d)), R_(R), c_(c) {}
  std::string name() const override { return d_->name(); }
  const DeviceCapabilities& capabilities() const override { return d_->capabilities(); }
  void open() override { d_->open(); }
  void close() override { d_->close(); }
  bool read(DeviceState& s) override {
    if (!d_->read(s)) return false;
    s.position_mm = c_ + R_ * s.position_mm;
    s.velocity_mm_s = R_ * s.velocity_mm_s;
    s.orientation = R_ * s.orientation;
    s.angular_velocity_rad_s = R_ * s.angular_velocity_rad_s;
    return true;
  }
  bool write_force(const Eigen::Vector3d& f) override {
    return d_->write_force(R_.transpose() * f);
  }
  bool write_wrench(const Eigen::Vector3d& f, const Eigen::Vector3d& torque) override {
    return d_->write_wrench(R_.transpose() * f, R_.transpose() * torque);
  }
  bool finished() const override { return d_->finished(); }
  std::string last_error() const override { return d_->last_error(); }

 private:
  std::unique_ptr<Device> d_;
  Eigen::Matrix3d R_;
  Eigen::Vector3d c_;
};

}  // namespace

std::unique_ptr<Device> make_openhaptics_device(const DeviceCapabilities& caps,
                                                const std::string& library) {
  return std::make_unique<OpenHapticsDevice>(caps, library);
}

std::unique_ptr<Device> make_dhd_device(const DeviceCapabilities& caps,
                                        const std::string& library) {
  return std::make_unique<DhdDevice>(caps, library);
}

BackendProbe probe_openhaptics(const std::string& library) {
  BackendProbe p;
  p.name = "openhaptics";
  p.library = library.empty() ? "libHD.so" : library;
  SharedLibrary lib(p.library);
  HdApi api;
  api.bind(lib);
  p.loaded = lib.loaded() && lib.missing().empty();
  p.detail = p.loaded ? "library found (HD cannot count devices without opening one)"
                      : load_error("openhaptics", p.library, lib);
  return p;
}

BackendProbe probe_dhd(const std::string& library) {
  BackendProbe p;
  p.name = "dhd";
  p.library = library.empty() ? "libdhd.so" : library;
  SharedLibrary lib(p.library);
  DhdApi api;
  api.bind(lib);
  p.loaded = lib.loaded() && lib.missing().empty();
  if (p.loaded) {
    p.devices = api.dhdGetDeviceCount();
    p.detail = p.devices < 0 ? std::string("device count failed: ") +
                                   (api.dhdErrorGetLastStr() ? api.dhdErrorGetLastStr() : "")
                             : "library found";
  } else {
    p.detail = load_error("dhd", p.library, lib);
  }
  return p;
}

std::unique_ptr<Device> map_device(std::unique_ptr<Device> device, const Eigen::Matrix3d& R,
                                   const Eigen::Vector3d& center_mm) {
  return std::make_unique<MappedDevice>(std::move(device), R, center_mm);
}

}  // namespace spinesim::haptics
