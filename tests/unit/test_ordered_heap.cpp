// OrderedHeap: the scope in which corefinement runs, so that what it orders by address comes out
// in the order it was made.
//   - inside a scope, every allocation lies above the earlier ones and is aligned as asked, even
//     where malloc would put a small block below a large one made before it;
//   - what outlives its scope stays intact while later scopes allocate, and is deleted later
//     (on another thread too) without harm;
//   - Outside allocates from the ordinary heap, for results that must outlive the scope;
//   - scopes on several threads at once keep to their own regions.

#include "radiosity/ordered_heap.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <thread>
#include <vector>

namespace gilt::radiosity::detail {
namespace {

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

TEST(OrderedHeap, AllocationsRiseInTheOrderTheyAreMade) {
  OrderedHeap heap;
  ASSERT_TRUE(heap.ordered()) << "the system refused the address reservation";
  // A large block then a small one: glibc maps the first and takes the second from its heap,
  // below it, which is how two vectors of corefinement came out in either order.
  std::vector<std::unique_ptr<char[]>> blocks;
  std::uintptr_t last = 0;
  for (size_t size : {size_t(1) << 21, size_t(24), size_t(0), size_t(4096), size_t(1) << 22, size_t(7)}) {
    blocks.emplace_back(new char[size]);
    EXPECT_GT(address(blocks.back().get()), last) << size;
    EXPECT_EQ(address(blocks.back().get()) % __STDCPP_DEFAULT_NEW_ALIGNMENT__, 0u);
    last = address(blocks.back().get());
    if (blocks.size() % 2 == 0) blocks.front().reset();  // deletes in between change nothing
  }
  struct alignas(256) Wide {
    char bytes[256];
  };
  auto wide = std::make_unique<Wide>();
  EXPECT_EQ(address(wide.get()) % 256, 0u);
  EXPECT_GT(address(wide.get()), last);
}

TEST(OrderedHeap, WhatOutlivesItsScopeStaysIntact) {
  std::vector<int>* kept = nullptr;  // as a library's thread-local cache, filled on first use
  std::vector<char>* outside = nullptr;
  {
    OrderedHeap heap;
    ASSERT_TRUE(heap.ordered());
    kept = new std::vector<int>(100000);
    for (size_t i = 0; i < kept->size(); ++i) (*kept)[i] = int(i * 7);
    std::vector<int> scratch(300000, -1);  // freed with the scope
    const OrderedHeap::Outside guard(heap);
    outside = new std::vector<char>(5000, 'x');
  }
  for (int round = 0; round < 3; ++round) {
    OrderedHeap heap;
    std::vector<int> fill(500000, -2);  // would overwrite `kept` if its memory were reused
    EXPECT_EQ(fill.back(), -2);
  }
  for (size_t i = 0; i < kept->size(); ++i) ASSERT_EQ((*kept)[i], int(i * 7)) << i;
  std::thread([&] { delete kept; }).join();  // the last allocation of its region, from elsewhere
  EXPECT_EQ(outside->at(4999), 'x');
  delete outside;
}

TEST(OrderedHeap, NestedScopesAndThreadsKeepToTheirOwnOrder) {
  std::vector<std::thread> threads;
  std::vector<int> rising(4, 0);
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&rising, t] {
      OrderedHeap heap;
      OrderedHeap inner;  // does nothing: the outer scope orders
      EXPECT_FALSE(inner.ordered());
      std::uintptr_t last = 0;
      bool ok = true;
      std::vector<std::unique_ptr<std::vector<double>>> made;
      for (int k = 0; k < 2000; ++k) {
        made.push_back(std::make_unique<std::vector<double>>(size_t(1 + (k * 37) % 500)));
        ok = ok && address(made.back().get()) > last && address(made.back()->data()) > address(made.back().get());
        last = address(made.back()->data());
        if (k % 3 == 0) made[size_t(k / 2)].reset();
      }
      rising[size_t(t)] = ok ? 1 : 0;
    });
  for (auto& t : threads) t.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(rising[size_t(t)], 1) << "thread " << t;
}

}  // namespace
}  // namespace gilt::radiosity::detail
