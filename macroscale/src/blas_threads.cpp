#include "blas_threads.hpp"

#include <dlfcn.h>

namespace knit::macro {

void serial_blas() {
  using SetThreads = void (*)(int);
  static const bool once = [] {
    const auto set_threads =
        reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (set_threads) set_threads(1);
    return true;
  }();
  (void)once;
}

}  // namespace knit::macro
