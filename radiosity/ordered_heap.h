#pragma once
// A scope in which operator new hands out memory in increasing addresses.

namespace gilt::radiosity::detail {

/// While an OrderedHeap is alive, every operator new on its thread takes memory from one address
/// range of its own, in increasing addresses: each allocation lies above every earlier one of
/// the scope. Code that orders objects by their addresses then sees the order in which they were
/// made, which depends on its input alone. CGAL 5.5's corefinement is such code: its
/// box-intersection ids are box addresses, the meshes' face and edge boxes live in two vectors,
/// and a std::map is keyed by pointers to its nodes. Under the process's own malloc, which of two
/// vectors lies lower depends on what the heap held before (other threads, earlier meshes), so
/// the cuts it makes, and the contact lines gilt imprints, changed from run to run.
///
/// Memory is not reused within a scope. What is still allocated when the scope ends (a
/// thread-local cache a library fills on first use) stays valid: the range is returned to the
/// system a megabyte at a time as its allocations are deleted, from any thread, and entirely
/// once the last one is. Scopes do not nest (an inner one does nothing). When the system refuses
/// the reservation, allocations take the ordinary heap: nothing breaks, only the order is lost
/// (`ordered()` says which).
class OrderedHeap {
 public:
  OrderedHeap();
  ~OrderedHeap();
  OrderedHeap(const OrderedHeap&) = delete;
  OrderedHeap& operator=(const OrderedHeap&) = delete;

  /// Whether this scope's allocations come from its own range.
  bool ordered() const { return region_ != nullptr; }

  /// While an Outside lives, this thread allocates from the ordinary heap again: for results
  /// that must outlive the scope (copy them out under one).
  class Outside {
   public:
    explicit Outside(const OrderedHeap& heap);
    ~Outside();
    Outside(const Outside&) = delete;
    Outside& operator=(const Outside&) = delete;

   private:
    void* saved_;
  };

 private:
  void* region_ = nullptr;
};

}  // namespace gilt::radiosity::detail
