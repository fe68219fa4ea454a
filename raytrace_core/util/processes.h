#pragma once
// The processes that share one run: one by default, the ranks of `mpirun -np N gilt …` when the
// tool is built with MPI (cli/mpi_processes.cpp installs them). The libraries split their work by
// rank and join the results through this interface, so they need no MPI themselves.
//
// Work is split into items (image tiles, rows, chunks of photons) owned round-robin: item i
// belongs to rank i mod N. Every item is computed by exactly one rank, the same way one process
// would compute it, and joins copy results rather than add them, so a run on N ranks gives the
// bits of a run on one.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "raytrace_core/util/parallel.h"

namespace gilt::raytrace_core::util {

/// The processes of a run and the collective operations the libraries use. Every process must
/// call each operation, in the same order.
class Processes {
 public:
  virtual ~Processes() = default;
  virtual int rank() const { return 0; }
  virtual int count() const { return 1; }
  /// Every process's bytes, concatenated in rank order, on every process.
  virtual std::vector<std::byte> all_gather(std::span<const std::byte> mine) const {
    return {mine.begin(), mine.end()};
  }
  /// Rank 0's bytes in `data` on every process.
  virtual void broadcast(std::span<std::byte>) const {}
  /// The element-wise sum over processes, on every process.
  virtual void sum(std::span<uint64_t>) const {}

  /// Whether this process owns item i.
  bool owns(size_t item) const { return int(item % size_t(count())) == rank(); }
  /// Rank 0's value of `value`, on every process.
  template <class T>
  T broadcast_value(T value) const {
    static_assert(std::is_trivially_copyable_v<T>);
    broadcast(std::as_writable_bytes(std::span(&value, 1)));
    return value;
  }
  /// The largest `value` over processes.
  float max(float value) const;
  /// Whether `value` is true on any process.
  bool any(bool value) const {
    uint64_t n = value ? 1 : 0;
    sum(std::span(&n, 1));
    return n > 0;
  }
  /// The sum of `value` over processes (a count of work each did on its own items).
  uint64_t total(uint64_t value) const {
    sum(std::span(&value, 1));
    return value;
  }
};

/// The processes of this run: one process unless set_processes installed others.
const Processes& processes();
/// Installs the processes of this run (before any work; nullptr restores one process).
void set_processes(std::shared_ptr<const Processes> processes);

/// Joins values[i] computed by their owners (i mod N): afterwards every process holds all of them.
template <class T>
void join_owned(std::vector<T>& values) {
  static_assert(std::is_trivially_copyable_v<T>);
  const Processes& p = processes();
  if (p.count() == 1) return;
  std::vector<T> mine;
  for (size_t i = size_t(p.rank()); i < values.size(); i += size_t(p.count())) mine.push_back(values[i]);
  const std::vector<std::byte> all = p.all_gather(std::as_bytes(std::span(mine)));
  const std::byte* at = all.data();
  for (int r = 0; r < p.count(); ++r)
    for (size_t i = size_t(r); i < values.size(); i += size_t(p.count()), at += sizeof(T)) std::memcpy(&values[i], at, sizeof(T));
}

/// Joins chunks[c] made by their owners (c mod N): afterwards every process holds every chunk,
/// whatever its size.
template <class T>
void join_chunks(std::vector<std::vector<T>>& chunks) {
  static_assert(std::is_trivially_copyable_v<T>);
  const Processes& p = processes();
  const size_t n = size_t(p.count());
  if (n == 1) return;
  // Each owned chunk as its size, then its items; read back in rank order.
  std::vector<std::byte> mine;
  for (size_t c = size_t(p.rank()); c < chunks.size(); c += n) {
    const uint64_t size = chunks[c].size();
    const auto* bytes = reinterpret_cast<const std::byte*>(&size);
    mine.insert(mine.end(), bytes, bytes + sizeof size);
    const auto items = std::as_bytes(std::span(chunks[c]));
    mine.insert(mine.end(), items.begin(), items.end());
  }
  const std::vector<std::byte> all = p.all_gather(mine);
  const std::byte* at = all.data();
  for (size_t r = 0; r < n; ++r)
    for (size_t c = r; c < chunks.size(); c += n) {
      uint64_t size = 0;
      std::memcpy(&size, at, sizeof size);
      at += sizeof size;
      chunks[c].resize(size);
      if (size) std::memcpy(chunks[c].data(), at, size * sizeof(T));
      at += size * sizeof(T);
    }
}

/// Calls body(i) for the items i of [0, count) this process owns, in parallel; join their
/// results with join_ranges or join_owned.
inline void parallel_for_owned(size_t count, const std::function<void(size_t)>& body) {
  const Processes& p = processes();
  const size_t n = size_t(p.count()), first = size_t(p.rank());
  if (n == 1) return parallel_for(count, body);
  const size_t owned = count > first ? (count - first + n - 1) / n : 0;
  parallel_for(owned, [&](size_t k) { body(first + k * n); });
}

/// Joins values[first + c·size, first + (c + 1)·size) computed by the owner of chunk c (c mod N),
/// the last chunk cut at the end: afterwards every process holds all of them.
template <class T>
void join_ranges(std::span<T> values, size_t size, size_t first = 0) {
  static_assert(std::is_trivially_copyable_v<T>);
  const Processes& p = processes();
  const size_t n = size_t(p.count());
  if (n == 1 || values.size() <= first) return;
  const size_t count = values.size() - first, chunks = (count + size - 1) / size;
  auto range = [&](size_t c) {
    return values.subspan(first + c * size, std::min(size, count - c * size));
  };
  std::vector<std::byte> mine;
  for (size_t c = size_t(p.rank()); c < chunks; c += n) {
    const auto bytes = std::as_bytes(range(c));
    mine.insert(mine.end(), bytes.begin(), bytes.end());
  }
  const std::vector<std::byte> all = p.all_gather(mine);
  const std::byte* at = all.data();
  for (size_t r = 0; r < n; ++r)
    for (size_t c = r; c < chunks; c += n) {
      const auto out = range(c);
      std::memcpy(out.data(), at, out.size_bytes());
      at += out.size_bytes();
    }
}

/// Calls body(c, chunks[c]) for the chunks c of [0, chunks.size()) this process owns, in parallel,
/// then joins them: every process ends with every chunk's output, as one process alone makes it.
template <class T>
void distributed_chunks(std::vector<std::vector<T>>& chunks, const std::function<void(size_t, std::vector<T>&)>& body) {
  const Processes& p = processes();
  const size_t n = size_t(p.count()), first = size_t(p.rank());
  const size_t owned = chunks.size() > first ? (chunks.size() - first + n - 1) / n : 0;
  parallel_for(owned, [&](size_t k) { body(first + k * n, chunks[first + k * n]); });
  join_chunks(chunks);
}

}  // namespace gilt::raytrace_core::util
