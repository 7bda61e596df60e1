// The BLAS behind the shell's sparse factorizations (CHOLMOD's supernodal Cholesky and MUMPS's
// multifrontal LDL^T) runs on the calling thread.
#pragma once

namespace knit::macro {

/// OpenBLAS (Debian's libopenblas0-pthread behind libblas.so.3, scripts/setup.sh) starts one
/// thread per core for every BLAS call; beside the assembly threads and other processes on a
/// 2-core machine its spinning threads cost more than they gave (a 1,440-unknown run: 27 % of
/// the samples in the kernel's scheduler and sched_yield). One BLAS thread: the factorization
/// runs on the calling thread, and its round-off does not depend on the number of cores.
/// Looked up at run time (absent with another BLAS); the first call sets it.
void serial_blas();

}  // namespace knit::macro
