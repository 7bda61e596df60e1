// The sweep across machines (issue #7): a thin MPI layer, compiled with MPI when CMake found it
// (KNIT_HAVE_MPI), serial otherwise. MPI is initialized only when the process was started by a
// launcher (mpirun / srun set OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK), so a plain
// `knit-meso sweep` never touches MPI.
//
// Distribution: dynamic. Rank 0 holds the queue of pending jobs and runs some of them on its
// own threads; every other rank asks for one job per thread (kRequest), gets a job index or -1
// (kJob), returns each result (kResult, which also asks for the next job) and says kDone when
// it got -1 for every request. Rank 0 writes the checkpoints, fits and writes the database.
// Jobs are deterministic and independent, so the database equals the serial one whichever rank
// ran what. Only the main thread of a rank calls MPI (MPI_THREAD_FUNNELED).
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
  enum Tag { kRequest = 7, kResult = 8, kJob = 9, kDone = 10 };
  /// Sends one message (blocking send).
  void send(int dest, Tag tag, const std::string& msg) const;
  /// Receives one pending message with this tag from any rank, if there is one (non-blocking);
  /// `source` gets the sender.
  bool try_receive(Tag tag, int& source, std::string& msg) const;
  /// Terminates all ranks (after a failure on one of them, so that none waits forever).
  void abort(int code) const;

  /// True if this build has MPI support.
  static bool compiled();

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool active_ = false;
};

}  // namespace knit::meso::sweep
