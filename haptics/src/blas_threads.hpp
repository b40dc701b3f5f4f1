// One BLAS thread for the process, if the BLAS is OpenBLAS (found at run time: nothing to link).
// The real-time threads' solves (the multirate spine's equilibrium, the palpated disc's CHOLMOD
// solves) reach OpenBLAS, whose own threads busy-wait: beside the servo thread on a 2-core machine
// they took the servo period's p99.9 from 1.09 to 3.8 ms, and they tripled the disc's step.
#pragma once

#include <dlfcn.h>

namespace spinesim::haptics::detail {

inline void use_one_blas_thread() {
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
    set(1);
}

}  // namespace spinesim::haptics::detail
