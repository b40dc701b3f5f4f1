/* A fake Force Dimension DHD library for the tests: the functions spinesim's backend loads,
 * with the signatures of dhdc.h, a scripted motion (one step per dhdGetPosition call, 1 ms) and
 * recorded forces. Environment variables as for fake_hd.c (FAKE_HAPTIC_LOG,
 * FAKE_HAPTIC_FAIL_INIT: dhdOpen fails with "fake DHD: no device found", FAKE_HAPTIC_FAIL_AT:
 * from call N on, dhdGetPosition fails with "fake DHD: communication error").
 * Motion (m, the DHD frame: x towards the user, y right, z up): x = 0.05 - 0.02 t,
 * y = 0.03 sin(2 pi t), z = 0.01. */
#include <cmath>
#include <cstdio>
#include <cstdlib>

extern "C" {

static long g_calls;
static const char* g_error = "no error";
static FILE* g_log;

static long env_long(const char* name, long fallback) {
  const char* v = getenv(name);
  return v && *v ? atol(v) : fallback;
}

int dhdGetDeviceCount(void) { return env_long("FAKE_HAPTIC_FAIL_INIT", 0) ? 0 : 1; }
int dhdOpen(void) {
  if (env_long("FAKE_HAPTIC_FAIL_INIT", 0)) {
    g_error = "fake DHD: no device found";
    return -1;
  }
  const char* log = getenv("FAKE_HAPTIC_LOG");
  g_log = log && *log ? fopen(log, "w") : NULL;
  g_calls = 0;
  return 0;
}
int dhdClose(char id) {
  (void)id;
  if (g_log) fclose(g_log);
  g_log = NULL;
  return 0;
}
int dhdEnableForce(unsigned char on, char id) {
  (void)on, (void)id;
  return 0;
}
int dhdGetPosition(double* x, double* y, double* z, char id) {
  (void)id;
  long fail_at = env_long("FAKE_HAPTIC_FAIL_AT", -1);
  if (fail_at >= 0 && g_calls >= fail_at) {
    g_error = "fake DHD: communication error";
    return -1;
  }
  const double t = g_calls / 1000.0;
  *x = 0.05 - 0.02 * t, *y = 0.03 * sin(2 * M_PI * t), *z = 0.01;
  ++g_calls;
  return 0;
}
int dhdGetLinearVelocity(double* vx, double* vy, double* vz, char id) {
  (void)id;
  const double t = (g_calls - 1) / 1000.0;
  *vx = -0.02, *vy = 0.06 * M_PI * cos(2 * M_PI * t), *vz = 0;
  return 0;
}
int dhdGetButtonMask(char id) {
  (void)id;
  return (int)((g_calls / 500) % 2);
}
int dhdSetForce(double fx, double fy, double fz, char id) {
  (void)id;
  if (g_log) fprintf(g_log, "%ld %.9g %.9g %.9g\n", g_calls, fx, fy, fz);
  return 0;
}
const char* dhdErrorGetLastStr(void) { return g_error; }

}  // extern "C"
