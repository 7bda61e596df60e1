#include <cstdlib>
#include <stdexcept>

#include "knit/meso/sweep/mpi.hpp"

#if defined(KNIT_HAVE_MPI)
#include <mpi.h>
#endif

namespace knit::meso::sweep {

namespace {
bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
}
}  // namespace

bool MpiSession::compiled() {
#if defined(KNIT_HAVE_MPI)
  return true;
#else
  return false;
#endif
}

MpiSession::MpiSession() {
#if defined(KNIT_HAVE_MPI)
  if (!launched_by_mpirun()) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  active_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (const char* l = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE")) local_size_ = std::atoi(l);
  if (local_size_ < 1) local_size_ = 1;
#endif
}

MpiSession::~MpiSession() {
#if defined(KNIT_HAVE_MPI)
  if (active_) MPI_Finalize();
#endif
}

void MpiSession::broadcast([[maybe_unused]] std::string& s) const {
#if defined(KNIT_HAVE_MPI)
  if (!active_ || size_ == 1) return;
  long n = static_cast<long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  s.resize(static_cast<std::size_t>(n));
  if (n > 0) MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
#endif
}

void MpiSession::send([[maybe_unused]] int dest, [[maybe_unused]] Tag tag,
                      [[maybe_unused]] const std::string& msg) const {
#if defined(KNIT_HAVE_MPI)
  if (!active_) throw std::logic_error("MpiSession::send without MPI");
  MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
#else
  throw std::logic_error("MpiSession::send without MPI");
#endif
}

bool MpiSession::try_receive([[maybe_unused]] Tag tag, [[maybe_unused]] int& source,
                             [[maybe_unused]] std::string& msg) const {
#if defined(KNIT_HAVE_MPI)
  if (!active_ || size_ == 1) return false;
  int flag = 0;
  MPI_Status st;
  MPI_Iprobe(MPI_ANY_SOURCE, tag, MPI_COMM_WORLD, &flag, &st);
  if (!flag) return false;
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  msg.assign(static_cast<std::size_t>(n), '\0');
  source = st.MPI_SOURCE;
  MPI_Recv(msg.data(), n, MPI_CHAR, st.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return true;
#else
  return false;
#endif
}

void MpiSession::abort([[maybe_unused]] int code) const {
#if defined(KNIT_HAVE_MPI)
  if (active_ && size_ > 1) MPI_Abort(MPI_COMM_WORLD, code);
#endif
}

}  // namespace knit::meso::sweep
