// The sweep across machines (issue #7): a thin MPI layer, compiled with MPI when CMake found it
// (KNIT_HAVE_MPI), serial otherwise. MPI is initialized only when the process was started by a
// launcher (mpirun / srun set OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK), so a plain
// `knit-meso sweep` never touches MPI.
//
// Distribution (choice): static round robin -- pending job i runs on rank i mod size, each rank
// runs its share on its own thread pool. Rank 0 receives every result, writes the checkpoints,
// fits and writes the database. Jobs are deterministic and independent, so the database equals
// the serial one. Only the main thread of a rank calls MPI (MPI_THREAD_FUNNELED).
#pragma once

#include <string>

namespace knit::meso::sweep {

class MpiSession {
 public:
  /// Initializes MPI if launched by mpirun (and built with MPI); otherwise rank 0 of 1.
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool active() const { return active_; }
  /// Ranks on this machine (to divide the cores among them); 1 without MPI.
  int local_size() const { return local_size_; }

  /// Broadcasts s from rank 0 to all ranks.
  void broadcast(std::string& s) const;
  /// Sends one message to rank 0 (blocking).
  void send_to_root(const std::string& msg) const;
  /// Rank 0: receives one pending message if there is one (non-blocking).
  bool try_receive(std::string& msg) const;
  /// Terminates all ranks (after a failure on one of them, so that none waits forever).
  void abort(int code) const;

  /// True if this build has MPI support.
  static bool compiled();

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool active_ = false;
};

}  // namespace knit::meso::sweep
