/* A fake OpenHaptics HD library for the tests: the functions spinesim's backend loads, with
 * the signatures of OpenHaptics's hd.h, a scheduler thread at 1 kHz, a scripted device motion
 * and recorded forces. Controlled by environment variables:
 *   FAKE_HAPTIC_LOG       file to append "frame fx fy fz" to, one line per frame;
 *   FAKE_HAPTIC_FAIL_INIT 1: hdInitDevice fails ("fake HD: no device found", HD_COMM_ERROR);
 *   FAKE_HAPTIC_FAIL_AT   N: from frame N on, hdGetError reports HD_DEVICE_FAULT.
 * Device motion (mm, the HD frame): x = 30 sin(2 pi t), y = 0, z = 50 - 20 t, t = frame / 1000. */
#include <pthread.h>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

extern "C" {

typedef unsigned int HHD;
typedef unsigned int HDenum;
typedef unsigned int HDerror;
typedef unsigned int HDCallbackCode;
typedef unsigned long HDSchedulerHandle;
typedef struct {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
} HDErrorInfo;
typedef HDCallbackCode (*HDSchedulerCallback)(void*);

static HDSchedulerCallback g_callback;
static void* g_user;
static pthread_t g_thread;
static std::atomic<int> g_running{0};
static long g_frame;
static HDerror g_error;
static double g_force[3];
static FILE* g_log;

static long env_long(const char* name, long fallback) {
  const char* v = getenv(name);
  return v && *v ? atol(v) : fallback;
}

HHD hdInitDevice(const char* name) {
  (void)name;
  if (env_long("FAKE_HAPTIC_FAIL_INIT", 0)) {
    g_error = 0x0302; /* HD_COMM_ERROR */
    return 0xFFFFFFFF;
  }
  const char* log = getenv("FAKE_HAPTIC_LOG");
  g_log = log && *log ? fopen(log, "w") : NULL;
  g_error = 0;
  g_frame = 0;
  return 1;
}
void hdDisableDevice(HHD h) {
  (void)h;
  if (g_log) fclose(g_log);
  g_log = NULL;
}
void hdEnable(HDenum cap) { (void)cap; }
void hdBeginFrame(HHD h) { (void)h; }
void hdEndFrame(HHD h) {
  (void)h;
  if (g_log) fprintf(g_log, "%ld %.9g %.9g %.9g\n", g_frame, g_force[0], g_force[1], g_force[2]);
  ++g_frame;
  long fail_at = env_long("FAKE_HAPTIC_FAIL_AT", -1);
  if (fail_at >= 0 && g_frame >= fail_at) g_error = 0x0300; /* HD_DEVICE_FAULT */
}
void hdGetDoublev(HDenum what, double* v) {
  const double t = g_frame / 1000.0;
  if (what == 0x2050) { /* HD_CURRENT_POSITION */
    v[0] = 30 * sin(2 * M_PI * t), v[1] = 0, v[2] = 50 - 20 * t;
  } else if (what == 0x2051) { /* HD_CURRENT_VELOCITY */
    v[0] = 60 * M_PI * cos(2 * M_PI * t), v[1] = 0, v[2] = -20;
  }
}
void hdGetIntegerv(HDenum what, int* v) {
  if (what == 0x2000) *v = (g_frame / 500) % 2; /* HD_CURRENT_BUTTONS: toggles every 0.5 s */
}
void hdSetDoublev(HDenum what, const double* v) {
  if (what == 0x2700) memcpy(g_force, v, sizeof g_force); /* HD_CURRENT_FORCE */
}
HDErrorInfo hdGetError(void) {
  HDErrorInfo e = {g_error, 0, 1};
  return e;
}
const char* hdGetErrorString(HDerror e) {
  switch (e) {
    case 0:
      return "no error";
    case 0x0302:
      return "fake HD: no device found";
    case 0x0300:
      return "fake HD: device fault";
    default:
      return "fake HD: unknown error";
  }
}
static void* scheduler(void* arg) {
  (void)arg;
  while (g_running) {
    if (g_callback && g_callback(g_user) == 0) g_callback = NULL; /* HD_CALLBACK_DONE */
    struct timespec ts = {0, 1000000};
    nanosleep(&ts, NULL);
  }
  return NULL;
}
HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback cb, void* user, unsigned short p) {
  (void)p;
  g_callback = cb;
  g_user = user;
  return 1;
}
void hdUnschedule(HDSchedulerHandle h) {
  (void)h;
  g_callback = NULL;
}
void hdStartScheduler(void) {
  g_running = 1;
  pthread_create(&g_thread, NULL, scheduler, NULL);
}
void hdStopScheduler(void) {
  if (!g_running) return;
  g_running = 0;
  pthread_join(g_thread, NULL);
}

}  // extern "C"
