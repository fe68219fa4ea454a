#include "radiosity/ordered_heap.h"

#include <sys/mman.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

// The global operator new and delete are replaced here (the standard allows a program to do so):
// outside an OrderedHeap they are malloc and free, as the library's own; inside one they take
// memory from the scope's region. A delete tells the two apart by the region bitmap.

namespace gilt::radiosity::detail {
namespace {

constexpr int kRegionBits = 32;                        // 4 GiB of addresses per region, aligned to 4 GiB
constexpr std::uintptr_t kRegionSize = std::uintptr_t{1} << kRegionBits;
constexpr int kChunkBits = 20;                         // returned to the system a MiB at a time
constexpr std::size_t kChunks = std::size_t{1} << (kRegionBits - kChunkBits);
constexpr std::size_t kSlots = std::size_t{1} << (47 - kRegionBits);  // 4-GiB slots of user space
constexpr std::size_t kPrefix = 16;                    // each allocation's [begin, end) sits before it

struct Region {
  /// Allocations not yet deleted, plus one while the scope is open.
  std::atomic<std::int64_t> live{1};
  std::atomic<bool> open{true};
  std::uintptr_t cursor = 0;  // next free byte; the owning thread's alone
  std::atomic<std::uint32_t> chunk_live[kChunks];  // allocations touching each chunk
};

/// One bit per 4-GiB slot of the address space: set while a region lives there.
std::atomic<std::uint64_t> g_slots[kSlots / 64];

thread_local Region* t_region = nullptr;

std::uintptr_t round_up(std::uintptr_t x, std::uintptr_t to) { return (x + to - 1) & ~(to - 1); }

Region* region_of(const void* p) {
  const std::uintptr_t slot = reinterpret_cast<std::uintptr_t>(p) >> kRegionBits;
  if (slot >= kSlots) return nullptr;
  if (!(g_slots[slot / 64].load(std::memory_order_acquire) & (std::uint64_t{1} << (slot % 64)))) return nullptr;
  return reinterpret_cast<Region*>(slot << kRegionBits);
}

void set_slot(Region* r, bool on) {
  const std::uintptr_t slot = reinterpret_cast<std::uintptr_t>(r) >> kRegionBits;
  const std::uint64_t bit = std::uint64_t{1} << (slot % 64);
  if (on)
    g_slots[slot / 64].fetch_or(bit, std::memory_order_acq_rel);
  else
    g_slots[slot / 64].fetch_and(~bit, std::memory_order_acq_rel);
}

Region* reserve_region() {
  // Twice the size, then trimmed to the aligned half, so the region's base is its slot's base.
  void* raw = mmap(nullptr, 2 * kRegionSize, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE,
                   -1, 0);
  if (raw == MAP_FAILED) return nullptr;
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(raw), base = round_up(begin, kRegionSize);
  if (base > begin) munmap(raw, base - begin);
  if (base + kRegionSize < begin + 2 * kRegionSize)
    munmap(reinterpret_cast<void*>(base + kRegionSize), begin + 2 * kRegionSize - (base + kRegionSize));
  if ((base >> kRegionBits) >= kSlots) {
    munmap(reinterpret_cast<void*>(base), kRegionSize);
    return nullptr;
  }
  auto* r = new (reinterpret_cast<void*>(base)) Region;
  r->cursor = round_up(base + sizeof(Region), 64);
  r->chunk_live[0].store(1, std::memory_order_relaxed);  // the header's own chunk stays
  set_slot(r, true);
  return r;
}

/// Hands back the region's pages in chunk `c`, which no allocation touches.
void release_chunk(Region* r, std::size_t c) {
  madvise(reinterpret_cast<char*>(r) + (c << kChunkBits), std::size_t{1} << kChunkBits, MADV_DONTNEED);
}

/// Drops one reference; the last one unmaps the region (its slot bit cleared first, so a
/// region mapped there next is never taken for this one).
void unreference(Region* r) {
  if (r->live.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  set_slot(r, false);
  r->~Region();
  munmap(r, kRegionSize);
}

void* allocate_in(Region* r, std::size_t size, std::size_t alignment) {
  if (alignment < kPrefix) alignment = kPrefix;
  const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(r);
  const std::uintptr_t begin = r->cursor, user = round_up(begin + kPrefix, alignment);
  if (size > kRegionSize || user + size + 1 > base + kRegionSize) return nullptr;
  const std::uintptr_t end = user + (size == 0 ? 1 : size);
  auto* prefix = reinterpret_cast<std::uintptr_t*>(user - kPrefix);
  prefix[0] = begin;
  prefix[1] = end;
  for (std::size_t c = (begin - base) >> kChunkBits; c <= ((end - 1 - base) >> kChunkBits); ++c)
    r->chunk_live[c].fetch_add(1, std::memory_order_relaxed);
  r->live.fetch_add(1, std::memory_order_relaxed);
  r->cursor = round_up(end, kPrefix);
  return reinterpret_cast<void*>(user);
}

/// Deletes `p` if a region holds it; false if it is the ordinary heap's.
bool release(void* p) {
  Region* r = region_of(p);
  if (!r) return false;
  const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(r);
  const auto* prefix = reinterpret_cast<const std::uintptr_t*>(reinterpret_cast<std::uintptr_t>(p) - kPrefix);
  const std::uintptr_t begin = prefix[0], end = prefix[1];
  // While the scope is open, only chunks wholly below the cursor may go (the owner allocates
  // on above it); from another thread, none may, since that thread cannot read the cursor.
  const bool open = r->open.load(std::memory_order_acquire);
  const std::size_t limit = !open ? kChunks : t_region == r ? ((r->cursor - base) >> kChunkBits) : 0;
  for (std::size_t c = (begin - base) >> kChunkBits; c <= ((end - 1 - base) >> kChunkBits); ++c)
    if (r->chunk_live[c].fetch_sub(1, std::memory_order_acq_rel) == 1 && c < limit) release_chunk(r, c);
  unreference(r);
  return true;
}

void* ordinary_allocate(std::size_t size) {
  if (size == 0) size = 1;
  for (;;) {
    if (void* p = std::malloc(size)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

void* ordinary_allocate_aligned(std::size_t size, std::size_t alignment) {
  if (size == 0) size = 1;
  if (alignment < sizeof(void*)) alignment = sizeof(void*);
  for (;;) {
    void* p = nullptr;
    if (posix_memalign(&p, alignment, size) == 0) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

/// The allocation functions below call these.
void* ordered_allocate(std::size_t size, std::size_t alignment) {
  Region* r = t_region;
  if (r)
    if (void* p = allocate_in(r, size, alignment)) return p;
  return alignment > __STDCPP_DEFAULT_NEW_ALIGNMENT__ ? ordinary_allocate_aligned(size, alignment)
                                                      : ordinary_allocate(size);
}

void ordered_free(void* p) {
  if (p && !release(p)) std::free(p);
}

}  // namespace

OrderedHeap::OrderedHeap() {
  if (t_region) return;  // nested: the outer scope orders
  Region* r = reserve_region();
  region_ = r;
  t_region = r;
}

OrderedHeap::~OrderedHeap() {
  auto* r = static_cast<Region*>(region_);
  if (!r) return;
  t_region = nullptr;
  r->open.store(false, std::memory_order_release);
  const std::size_t used = ((r->cursor - reinterpret_cast<std::uintptr_t>(r)) >> kChunkBits) + 1;
  for (std::size_t c = 0; c < used && c < kChunks; ++c)
    if (r->chunk_live[c].load(std::memory_order_acquire) == 0) release_chunk(r, c);
  unreference(r);
}

OrderedHeap::Outside::Outside(const OrderedHeap&) : saved_(t_region) { t_region = nullptr; }

OrderedHeap::Outside::~Outside() { t_region = static_cast<Region*>(saved_); }

}  // namespace gilt::radiosity::detail

using gilt::radiosity::detail::ordered_allocate;
using gilt::radiosity::detail::ordered_free;

void* operator new(std::size_t size) { return ordered_allocate(size, __STDCPP_DEFAULT_NEW_ALIGNMENT__); }
void* operator new[](std::size_t size) { return ordered_allocate(size, __STDCPP_DEFAULT_NEW_ALIGNMENT__); }
void* operator new(std::size_t size, std::align_val_t a) { return ordered_allocate(size, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return ordered_allocate(size, static_cast<std::size_t>(a)); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ordered_allocate(size, __STDCPP_DEFAULT_NEW_ALIGNMENT__);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ordered_allocate(size, __STDCPP_DEFAULT_NEW_ALIGNMENT__);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return ordered_allocate(size, static_cast<std::size_t>(a));
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return ordered_allocate(size, static_cast<std::size_t>(a));
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { ordered_free(p); }
void operator delete[](void* p) noexcept { ordered_free(p); }
void operator delete(void* p, std::size_t) noexcept { ordered_free(p); }
void operator delete[](void* p, std::size_t) noexcept { ordered_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { ordered_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { ordered_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { ordered_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { ordered_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { ordered_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { ordered_free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { ordered_free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { ordered_free(p); }
