#include "cli/mpi_processes.h"

#include <cstdlib>

#ifdef GILT_MPI

#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "raytrace_core/util/processes.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace {

void check(int status, const char* what) {
  if (status != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

int as_count(size_t bytes) {
  if (bytes > size_t(std::numeric_limits<int>::max())) throw std::runtime_error("MPI: a message over 2 GiB");
  return int(bytes);
}

/// The ranks of MPI_COMM_WORLD.
class MpiProcesses final : public rc::util::Processes {
 public:
  MpiProcesses(int rank, int count) : rank_(rank), count_(count) {}
  int rank() const override { return rank_; }
  int count() const override { return count_; }

  std::vector<std::byte> all_gather(std::span<const std::byte> mine) const override {
    const int size = as_count(mine.size());
    std::vector<int> sizes(static_cast<size_t>(count_)), offsets(static_cast<size_t>(count_));
    check(MPI_Allgather(&size, 1, MPI_INT, sizes.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
    size_t total = 0;
    for (int r = 0; r < count_; ++r) offsets[r] = as_count(total), total += size_t(sizes[r]);
    std::vector<std::byte> all(total);
    check(MPI_Allgatherv(mine.data(), size, MPI_BYTE, all.data(), sizes.data(), offsets.data(), MPI_BYTE,
                         MPI_COMM_WORLD),
          "MPI_Allgatherv");
    return all;
  }

  void broadcast(std::span<std::byte> data) const override {
    check(MPI_Bcast(data.data(), as_count(data.size()), MPI_BYTE, 0, MPI_COMM_WORLD), "MPI_Bcast");
  }

  void sum(std::span<uint64_t> values) const override {
    check(MPI_Allreduce(MPI_IN_PLACE, values.data(), as_count(values.size()), MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD),
          "MPI_Allreduce");
  }

 private:
  int rank_, count_;
};

/// Whether mpirun (Open MPI's, or any PMIx launcher) started this process.
bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpirun()) return;
  check(MPI_Init(&argc, &argv), "MPI_Init");
  started_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  if (ranks_ > 1) rc::util::set_processes(std::make_shared<const MpiProcesses>(rank_, ranks_));
  if (rank_ > 0) {
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr))
      std::fputs("gilt: rank output not silenced\n", stderr);
  }
}

MpiSession::~MpiSession() {
  if (!started_) return;
  rc::util::set_processes(nullptr);
  MPI_Finalize();
}

void MpiSession::abort(int code) const {
  if (started_ && ranks_ > 1) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace gilt::cli

#else  // without MPI: one process

namespace gilt::cli {

MpiSession::MpiSession(int&, char**&) {}
MpiSession::~MpiSession() = default;
void MpiSession::abort(int code) const { std::exit(code); }

}  // namespace gilt::cli

#endif
