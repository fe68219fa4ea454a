#pragma once
// gilt under `mpirun -np N`: MPI's ranks as raytrace_core::util::Processes. Built with -DGILT_MPI=ON.

namespace gilt::cli {

/// Starts MPI when the process was launched by mpirun (Open MPI's or PMIx's environment says
/// so), installs the ranks as the run's processes when there are several, and sends every rank
/// but 0's standard output and error to /dev/null: rank 0 alone prints and writes files. Ends
/// MPI when destroyed. Without mpirun it does nothing.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  /// Ends every rank with `code`: for a failure one rank may meet alone, when the others would
  /// otherwise wait for it forever.
  [[noreturn]] void abort(int code) const;

 private:
  bool started_ = false;
  int rank_ = 0, ranks_ = 1;
};

}  // namespace gilt::cli
